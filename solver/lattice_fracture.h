#pragma once
// Fracture of the six-spring lattice: a triangle fails once its stress reaches a tension
// cut-off or a Mohr-Coulomb shear limit, and from then on resists compaction only. The rule
// (docs/sources.md, "Fracture of the lattice"), with sigma_1 >= sigma_2 the principal
// stresses of the triangle, tension positive:
//   tension: sigma_1 >= sigma_t;
//   shear:   (sigma_1 - sigma_2) / 2 + (sigma_1 + sigma_2) / 2 sin(phi) >= c cos(phi),
// the Mohr-Coulomb envelope tau = c - sigma_n tan(phi) in principal stresses. A failed
// triangle carries no tension and no shear: its stress is the pressure K eps_vol of a
// compacting area (eps_vol = exx + eyy < 0, K = (d11 + d22 + 2 d12) / 4 the 2D bulk
// modulus of D), zero otherwise, so broken pieces push on each other where they close but
// separate and slide freely. Failure is irreversible and is checked once per step.
//
//   LatticeStrength strength{5e6, 20e6, 30.0};
//   TriangleFailure f = FailureOf(TriangleStress(lattice, t, u), strength);

#include <cstdint>
#include <string>
#include <vector>

#include "solver/six_spring_lattice.h"

namespace specimen {

struct LatticeStrength {
  double tensile_strength_pa = 0.0;  // sigma_t, > 0
  double cohesion_pa = 0.0;          // c, > 0
  double friction_angle_deg = 30.0;  // phi, in [0, 60]

  // Names the first invalid field and its range.
  bool IsValid(std::string* error) const;
  // The uniaxial compressive strength of one triangle by the shear limit,
  // 2 c cos(phi) / (1 - sin(phi)) (capped by nothing: tension governs a uniaxial triangle
  // only under tension).
  double TriangleCompressiveStrength() const;
};

enum class TriangleFailure : std::uint8_t { kIntact = 0, kTension = 1, kShear = 2 };

// The failure mode reached at `stress` (Voigt {sxx, syy, sxy}), tension checked first.
TriangleFailure FailureOf(const Eigen::Vector3d& stress, const LatticeStrength& strength);

// The 2D bulk modulus K of D (sigma_m = K eps_vol under an isotropic strain).
double AreaBulkModulus(const PlaneElasticity& d);

// The edge forces that hold triangle t at the homogeneous stress `stress` (the inverse of the
// virial of TriangleStress: sum_k f_k L_k n_k (x) n_k = A s sigma, at rest geometry).
Eigen::Vector3d EdgeForcesOfStress(const TriangleLattice& lattice, int triangle, const Eigen::Vector3d& stress);

// Adds the forces of a failed triangle at `displacements` to `forces`: the pressure K eps_vol
// when its area compacts, nothing otherwise. Returns its stress.
Eigen::Vector3d AddFailedTriangleForces(const TriangleLattice& lattice, int triangle, double bulk_modulus_pa,
                                        const std::vector<Vector<2>>& displacements,
                                        std::vector<Vector<2>>* forces);

}  // namespace specimen
