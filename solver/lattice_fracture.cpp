#include "solver/lattice_fracture.h"

#include <Eigen/LU>
#include <cmath>

#include "solver/lattice_packing.h"
#include "common/format.h"

namespace specimen {
namespace {
constexpr double kPi = 3.14159265358979323846;
}

bool LatticeStrength::IsValid(std::string* error) const {
  if (!(tensile_strength_pa > 0.0 && std::isfinite(tensile_strength_pa))) {
    *error = "tensile_strength = " + Number(tensile_strength_pa) + ": must be a positive stress [Pa]";
    return false;
  }
  if (!(cohesion_pa > 0.0 && std::isfinite(cohesion_pa))) {
    *error = "cohesion = " + Number(cohesion_pa) + ": must be a positive stress [Pa]";
    return false;
  }
  if (!(friction_angle_deg >= 0.0 && friction_angle_deg <= 60.0)) {
    *error = "friction_angle = " + Number(friction_angle_deg) + ": must be in [0, 60] degrees";
    return false;
  }
  return true;
}

double LatticeStrength::TriangleCompressiveStrength() const {
  const double phi = friction_angle_deg * kPi / 180.0;
  return 2.0 * cohesion_pa * std::cos(phi) / (1.0 - std::sin(phi));
}

TriangleFailure FailureOf(const Eigen::Vector3d& stress, const LatticeStrength& strength) {
  const double mean = 0.5 * (stress[0] + stress[1]);
  const double radius = std::hypot(0.5 * (stress[0] - stress[1]), stress[2]);
  const double sigma_1 = mean + radius;
  if (sigma_1 >= strength.tensile_strength_pa) return TriangleFailure::kTension;
  const double phi = strength.friction_angle_deg * kPi / 180.0;
  if (radius + mean * std::sin(phi) >= strength.cohesion_pa * std::cos(phi)) return TriangleFailure::kShear;
  return TriangleFailure::kIntact;
}

double AreaBulkModulus(const PlaneElasticity& d) { return 0.25 * (d.d11 + d.d22 + 2.0 * d.d12); }

Eigen::Vector3d EdgeForcesOfStress(const TriangleLattice& lattice, int triangle, const Eigen::Vector3d& stress) {
  Eigen::Matrix3d c;
  for (int k = 0; k < 3; ++k) {
    const Vector<2>& e = lattice.rest_edges[triangle][k];
    const double length = lattice.rest_lengths[triangle][k];
    const Vector<2> n = e / length;
    c.col(k) << length * n.x() * n.x(), length * n.y() * n.y(), length * n.x() * n.y();
  }
  return c.partialPivLu().solve(lattice.areas[triangle] * lattice.thickness_m * stress);
}

Eigen::Vector3d AddFailedTriangleForces(const TriangleLattice& lattice, int triangle, double bulk_modulus_pa,
                                        const std::vector<Vector<2>>& displacements,
                                        std::vector<Vector<2>>* forces) {
  const Eigen::Vector3d strain = TriangleStrain(lattice, triangle, displacements);
  const double volumetric = strain[0] + strain[1];
  if (volumetric >= 0.0) return Eigen::Vector3d::Zero();
  const double pressure = bulk_modulus_pa * volumetric;  // negative: compression
  const Eigen::Vector3d stress(pressure, pressure, 0.0);
  const Eigen::Vector3d f = EdgeForcesOfStress(lattice, triangle, stress);
  const std::array<int, 3>& v = lattice.nodes[triangle];
  for (int k = 0; k < 3; ++k) {
    const Vector<2> n = lattice.rest_edges[triangle][k] / lattice.rest_lengths[triangle][k];
    (*forces)[v[k]] += f[k] * n;
    (*forces)[v[(k + 1) % 3]] -= f[k] * n;
  }
  return stress;
}

}  // namespace specimen
