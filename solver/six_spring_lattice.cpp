#include "solver/six_spring_lattice.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>

#include "common/error.h"
#include "common/format.h"

namespace specimen {
namespace {

const double kSqrt3 = std::sqrt(3.0);

void CheckPoisson(double nu, PlaneModel model, const char* field) {
  const double upper = model == PlaneModel::kPlaneStrain ? 0.5 : 1.0;
  if (!(nu > -1.0 && nu < upper)) {
    throw InputError(std::string(field) + " = " + Number(nu) + ": must lie in (-1, " +
                     (model == PlaneModel::kPlaneStrain ? "0.5" : "1") + ") for " + PlaneModelName(model));
  }
}

// Plane strain from plane stress constants: E -> E / (1 - nu^2), nu -> nu / (1 - nu).
void PlaneStrainSubstitution(PlaneModel model, double* youngs, double* nu) {
  if (model != PlaneModel::kPlaneStrain) return;
  *youngs /= 1.0 - *nu * *nu;
  *nu /= 1.0 - *nu;
}

PlaneElasticity FromMatrix(const Eigen::Matrix3d& m) {
  PlaneElasticity d;
  d.d11 = m(0, 0);
  d.d12 = 0.5 * (m(0, 1) + m(1, 0));
  d.d13 = 0.5 * (m(0, 2) + m(2, 0));
  d.d22 = m(1, 1);
  d.d23 = 0.5 * (m(1, 2) + m(2, 1));
  d.d33 = m(2, 2);
  return d;
}

// Voigt strain transformation into axes rotated by theta: eps_material = T eps_global.
Eigen::Matrix3d StrainRotation(double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  Eigen::Matrix3d t;
  t << c * c, s * s, c * s,  //
      s * s, c * c, -c * s,  //
      -2.0 * c * s, 2.0 * c * s, c * c - s * s;
  return t;
}

Eigen::Matrix3d OrthotropicCompliance(const OrthotropicConstants& k, PlaneModel model) {
  const double e1 = k.youngs_modulus_1_pa, e2 = k.youngs_modulus_2_pa;
  Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
  s(0, 0) = 1.0 / e1;
  s(1, 1) = 1.0 / e2;
  s(0, 1) = s(1, 0) = -k.poisson_ratio_12 / e1;
  s(2, 2) = 1.0 / k.shear_modulus_12_pa;
  if (model == PlaneModel::kPlaneStrain) {
    // eps_33 = 0 eliminates sigma_33: S_ij - S_i3 S_j3 / S_33.
    const double e3 = k.youngs_modulus_3_pa;
    const double s13 = -k.poisson_ratio_13 / e1, s23 = -k.poisson_ratio_23 / e2, s33 = 1.0 / e3;
    s(0, 0) -= s13 * s13 / s33;
    s(1, 1) -= s23 * s23 / s33;
    s(0, 1) -= s13 * s23 / s33;
    s(1, 0) = s(0, 1);
  }
  return s;
}

// Column k of C (A4, Voigt): (cx^2, cy^2, cx cy) of the unit edge vector.
Eigen::Vector3d EdgeColumn(const Vector<2>& unit) {
  return Eigen::Vector3d(unit.x() * unit.x(), unit.y() * unit.y(), unit.x() * unit.y());
}

}  // namespace

Eigen::Matrix3d PlaneElasticity::Matrix() const {
  Eigen::Matrix3d m;
  m << d11, d12, d13,  //
      d12, d22, d23,   //
      d13, d23, d33;
  return m;
}

bool PlaneElasticity::IsPositiveDefinite() const {
  Eigen::LLT<Eigen::Matrix3d> llt(Matrix());
  return llt.info() == Eigen::Success;
}

PlaneElasticity IsotropicPlaneElasticity(double youngs_modulus_pa, double poisson_ratio, PlaneModel model) {
  if (!(youngs_modulus_pa > 0.0 && std::isfinite(youngs_modulus_pa))) {
    throw InputError("youngs_modulus = " + Number(youngs_modulus_pa) + ": must be a positive number [Pa]");
  }
  CheckPoisson(poisson_ratio, model, "poisson_ratio");
  double e = youngs_modulus_pa, nu = poisson_ratio;
  PlaneStrainSubstitution(model, &e, &nu);
  const double f = e / (1.0 - nu * nu);
  PlaneElasticity d;
  d.d11 = d.d22 = f;
  d.d12 = f * nu;
  d.d33 = f * 0.5 * (1.0 - nu);  // G = E / (2 (1 + nu))
  return d;
}

bool OrthotropicConstants::IsValid(PlaneModel model, std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  auto positive = [&](double v, const char* name) {
    return v > 0.0 && std::isfinite(v) ? true : fail(std::string(name) + " = " + Number(v) +
                                                     ": must be a positive number [Pa]");
  };
  if (!positive(youngs_modulus_1_pa, "youngs_modulus_1") || !positive(youngs_modulus_2_pa, "youngs_modulus_2") ||
      !positive(shear_modulus_12_pa, "shear_modulus_12")) {
    return false;
  }
  if (!std::isfinite(axis_angle_rad)) return fail("axis_angle must be a finite angle");
  if (model == PlaneModel::kPlaneStrain && !positive(youngs_modulus_3_pa, "youngs_modulus_3")) return false;
  // Positive definite compliance: 1 - nu12 nu21 > 0 in plane, and the 3 x 3 one in plane strain.
  Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
  s(0, 0) = 1.0 / youngs_modulus_1_pa;
  s(1, 1) = 1.0 / youngs_modulus_2_pa;
  s(0, 1) = s(1, 0) = -poisson_ratio_12 / youngs_modulus_1_pa;
  if (model == PlaneModel::kPlaneStrain) {
    s(2, 2) = 1.0 / youngs_modulus_3_pa;
    s(0, 2) = s(2, 0) = -poisson_ratio_13 / youngs_modulus_1_pa;
    s(1, 2) = s(2, 1) = -poisson_ratio_23 / youngs_modulus_2_pa;
  } else {
    s(2, 2) = 1.0;
  }
  if (!(std::isfinite(poisson_ratio_12) && std::isfinite(poisson_ratio_13) && std::isfinite(poisson_ratio_23)) ||
      Eigen::LLT<Eigen::Matrix3d>(s).info() != Eigen::Success) {
    return fail("poisson_ratio_12 = " + Number(poisson_ratio_12) +
                (model == PlaneModel::kPlaneStrain ? ", poisson_ratio_13, poisson_ratio_23" : "") +
                ": the compliance is not positive definite (in plane |nu12| < sqrt(E1 / E2))");
  }
  return true;
}

PlaneElasticity OrthotropicPlaneElasticity(const OrthotropicConstants& constants, PlaneModel model) {
  std::string error;
  if (!constants.IsValid(model, &error)) throw InputError(error);
  const Eigen::Matrix3d d_material = OrthotropicCompliance(constants, model).inverse();
  // Energy 1/2 eps_m^T D_m eps_m with eps_m = T eps: D = T^T D_m T.
  const Eigen::Matrix3d t = StrainRotation(constants.axis_angle_rad);
  return FromMatrix(t.transpose() * d_material * t);
}

Eigen::Matrix3d TriangleNaturalStiffness(const Vector<2>& a, const Vector<2>& b, const Vector<2>& c,
                                         const PlaneElasticity& d, double thickness_m) {
  const std::array<Vector<2>, 3> edges = {b - a, c - b, a - c};
  const double area = 0.5 * std::abs(edges[0].x() * (c - a).y() - edges[0].y() * (c - a).x());
  Eigen::Matrix3d cm;
  Eigen::Vector3d inverse_length;
  for (int k = 0; k < 3; ++k) {
    const double length = edges[k].norm();
    cm.col(k) = EdgeColumn(edges[k] / length);
    inverse_length[k] = 1.0 / length;
  }
  // h = l C^T eps, so eps = C^-T l^-1 h and the energy 1/2 A s eps^T D eps gives (A2).
  const Eigen::Matrix3d c_inverse = cm.inverse();
  const Eigen::Matrix3d k = area * thickness_m * inverse_length.asDiagonal() * c_inverse * d.Matrix() *
                            c_inverse.transpose() * inverse_length.asDiagonal();
  return 0.5 * (k + k.transpose());
}

Eigen::Matrix3d EquilateralNaturalStiffness(const PlaneElasticity& d, double s) {
  // (A6) with the corrected sign of d23 in K22; edge 0 at 0, edge 1 at 120, edge 2 at 60 degrees.
  Eigen::Matrix3d k;
  k(0, 0) = kSqrt3 / 36.0 * (9.0 * d.d11 - 6.0 * d.d12 + d.d22) * s;
  k(0, 1) = kSqrt3 / 18.0 * (3.0 * d.d12 - d.d22 - 3.0 * kSqrt3 * d.d13 + kSqrt3 * d.d23) * s;
  k(0, 2) = kSqrt3 / 18.0 * (3.0 * d.d12 - d.d22 + 3.0 * kSqrt3 * d.d13 - kSqrt3 * d.d23) * s;
  k(1, 1) = kSqrt3 / 9.0 * (d.d22 - 2.0 * kSqrt3 * d.d23 + 3.0 * d.d33) * s;
  k(1, 2) = kSqrt3 / 9.0 * (d.d22 - 3.0 * d.d33) * s;
  k(2, 2) = kSqrt3 / 9.0 * (d.d22 + 2.0 * kSqrt3 * d.d23 + 3.0 * d.d33) * s;
  k(1, 0) = k(0, 1);
  k(2, 0) = k(0, 2);
  k(2, 1) = k(1, 2);
  return k;
}

SixSpringConstants IsotropicSixSpringConstants(double poisson_ratio, PlaneModel model) {
  CheckPoisson(poisson_ratio, model, "poisson_ratio");
  // (11), (12) per E s; plane strain: E -> E / (1 - nu^2) scales both, nu -> nu / (1 - nu).
  double scale = 1.0, nu = poisson_ratio;
  PlaneStrainSubstitution(model, &scale, &nu);
  const double denominator = 6.0 * kSqrt3 * (1.0 - nu * nu);
  return {scale * (5.0 - 3.0 * nu) / denominator, scale * (3.0 * nu - 1.0) / denominator};
}

void IsotropicConstantsFromEigenvalues(double volumetric, double deviatoric, double* youngs_times_thickness,
                                       double* poisson_ratio) {
  const double es = 4.0 * kSqrt3 * volumetric * deviatoric / (deviatoric + 2.0 * volumetric);
  *youngs_times_thickness = es;
  *poisson_ratio = es / (kSqrt3 * deviatoric) - 1.0;
}

double RegularLatticeStableTimeStep(double youngs_modulus_pa, double poisson_ratio, PlaneModel model,
                                    double density_kg_per_m3, double side_m) {
  CheckPoisson(poisson_ratio, model, "poisson_ratio");
  double e = youngs_modulus_pa, nu = poisson_ratio;
  PlaneStrainSubstitution(model, &e, &nu);
  const double wave_speed = std::sqrt(e / density_kg_per_m3);
  return std::sqrt(3.0 * (1.0 - nu * nu)) / 2.0 * side_m / wave_speed;
}

double PaperTimeStepEstimate(double youngs_modulus_pa, double poisson_ratio, PlaneModel model,
                             double density_kg_per_m3, double side_m, double thickness_m) {
  const double mass = kSqrt3 / 2.0 * density_kg_per_m3 * side_m * side_m * thickness_m;  // (2)
  const double k_max = 2.0 * IsotropicSixSpringConstants(poisson_ratio, model).k_nn * youngs_modulus_pa * thickness_m;
  return std::sqrt(mass / k_max);  // (15)
}

TriangleLattice BuildTriangleLattice(const std::vector<Vector<2>>& centres,
                                     const std::vector<std::array<int, 3>>& triangles, const PlaneElasticity& d,
                                     double thickness_m) {
  if (!(thickness_m > 0.0 && std::isfinite(thickness_m))) {
    throw InputError("thickness = " + std::to_string(thickness_m) + ": must be a positive length [m]");
  }
  if (!d.IsPositiveDefinite()) throw InputError("the elasticity matrix D is not positive definite");
  const int n = static_cast<int>(centres.size());
  TriangleLattice lattice;
  lattice.thickness_m = thickness_m;
  lattice.nodes.reserve(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    std::array<int, 3> v = triangles[t];
    for (int i : v) {
      if (i < 0 || i >= n) throw InputError("triangle " + std::to_string(t) + " names node " + std::to_string(i));
    }
    const Vector<2> ab = centres[v[1]] - centres[v[0]], ac = centres[v[2]] - centres[v[0]];
    const double cross = ab.x() * ac.y() - ab.y() * ac.x();
    const double scale = std::max(ab.squaredNorm(), ac.squaredNorm());
    if (!(std::abs(cross) > 1e-12 * scale)) {
      throw InputError("triangle " + std::to_string(t) + " has zero area (collinear nodes)");
    }
    if (cross < 0.0) std::swap(v[1], v[2]);
    const Vector<2>& a = centres[v[0]];
    const Vector<2>& b = centres[v[1]];
    const Vector<2>& c = centres[v[2]];
    lattice.nodes.push_back(v);
    lattice.rest_edges.push_back({b - a, c - b, a - c});
    lattice.rest_lengths.push_back({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    lattice.stiffness.push_back(TriangleNaturalStiffness(a, b, c, d, thickness_m));
    lattice.areas.push_back(0.5 * std::abs(cross));
  }
  return lattice;
}

std::vector<double> LumpedMasses(const TriangleLattice& lattice, int node_count, double density_kg_per_m3) {
  std::vector<double> mass(node_count, 0.0);
  for (int t = 0; t < lattice.size(); ++t) {
    const double share = density_kg_per_m3 * lattice.thickness_m * lattice.areas[t] / 3.0;
    for (int i : lattice.nodes[t]) mass[i] += share;
  }
  return mass;
}

double AddTriangleForces(const TriangleLattice& lattice, const std::vector<Vector<2>>& displacements,
                         std::vector<Vector<2>>* forces) {
  std::vector<Vector<2>>& f = *forces;
  double energy = 0.0;
  for (int t = 0; t < lattice.size(); ++t) {
    const std::array<int, 3>& v = lattice.nodes[t];
    std::array<Vector<2>, 3> direction;
    const Eigen::Vector3d h = EdgeStretches(lattice, t, displacements, &direction);
    const Eigen::Vector3d edge_force = lattice.stiffness[t] * h;  // f = K^N h, (6)
    energy += 0.5 * h.dot(edge_force);
    for (int k = 0; k < 3; ++k) {
      const Vector<2> pull = edge_force[k] * direction[k];
      f[v[k]] += pull;
      f[v[(k + 1) % 3]] -= pull;
    }
  }
  return energy;
}

Eigen::Matrix<double, 6, 6> CartesianTriangleStiffness(const TriangleLattice& lattice, int triangle) {
  // h_k = n_k . (u_end - u_start): row k of B_n holds -n_k at the start node, +n_k at the end.
  Eigen::Matrix<double, 3, 6> bn = Eigen::Matrix<double, 3, 6>::Zero();
  for (int k = 0; k < 3; ++k) {
    const Vector<2> n = lattice.rest_edges[triangle][k] / lattice.rest_lengths[triangle][k];
    const int start = k, end = (k + 1) % 3;
    bn.block<1, 2>(k, 2 * start) -= n.transpose();
    bn.block<1, 2>(k, 2 * end) += n.transpose();
  }
  return bn.transpose() * lattice.stiffness[triangle] * bn;
}

}  // namespace specimen
