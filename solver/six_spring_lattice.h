#pragma once
// The six-spring lattice of Kacianauskas & Vadluga (2009): nodes with two translational
// degrees of freedom, joined through triangles whose three edge forces depend on all three
// edge stretches, f = K^N h (their eq. (6)). K^N is the natural stiffness of a
// constant-strain triangle (Argyris; their Annex (A2)), so the model is exactly linear CST
// finite elements written in edge coordinates, with row-sum lumped masses: any homogeneous
// strain is reproduced, E and nu (or an anisotropic D) are inputs, nu is free over the
// whole admissible range.
//
// Conventions (the paper mixes two; Voigt is the consistent one, docs/sources.md):
//  - Voigt throughout: strain {exx, eyy, gamma_xy} with engineering shear, d33 = G, and the
//    edge matrix C of (A4) without sqrt(2);
//  - the triangle area is that of the triangle (sqrt(3) L^2 / 4 when equilateral; (A5)
//    prints twice that);
//  - K22 of (A6) carries -2 sqrt(3) d23 (printed with +).
// 2D quantities are per thickness s [m] (the rest of the solver uses s = 1 m).
//
//   PlaneElasticity d = IsotropicPlaneElasticity(17.1e9, 0.2, PlaneModel::kPlaneStress);
//   TriangleLattice lattice = BuildTriangleLattice(centres, triangles, d, 0.01);
//   std::vector<double> mass = LumpedMasses(lattice, centres.size(), 2500.0);
//   AddTriangleForces(lattice, displacements, &forces);  // per step

#include <array>
#include <string>
#include <vector>

#include "solver/material.h"
#include "solver/vector_algebra.h"

namespace specimen {

// A plane elasticity matrix in Voigt form, sigma = D eps with eps = {exx, eyy, gamma_xy}:
// the six independent entries d11, d12, d13, d22, d23, d33 (their (A3)).
struct PlaneElasticity {
  double d11 = 0.0, d12 = 0.0, d13 = 0.0, d22 = 0.0, d23 = 0.0, d33 = 0.0;

  Eigen::Matrix3d Matrix() const;
  // Positive definite (every admissible elastic material).
  bool IsPositiveDefinite() const;
};

// Isotropic D: plane stress E/(1 - nu^2) [[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu)/2]]; plane
// strain the same with E -> E/(1 - nu^2), nu -> nu/(1 - nu). E > 0; nu in (-1, 1) for plane
// stress, (-1, 0.5) for plane strain (InputError otherwise, naming the field).
PlaneElasticity IsotropicPlaneElasticity(double youngs_modulus_pa, double poisson_ratio, PlaneModel model);

// An orthotropic material in its own axes 1, 2 (axis 1 at `axis_angle_rad` from x,
// counter-clockwise), with the textbook compliance (nu21 = nu12 E2 / E1; the paper's eq. (13)
// simplifies this to a single nu over 1 - nu^2):
//   S = [[1/E1, -nu12/E1, 0], [-nu12/E1, 1/E2, 0], [0, 0, 1/G12]]   (plane stress).
// Plane strain needs the out-of-plane constants E3, nu13, nu23: S_ij - S_i3 S_j3 / S_33.
struct OrthotropicConstants {
  double youngs_modulus_1_pa = 0.0;
  double youngs_modulus_2_pa = 0.0;
  double poisson_ratio_12 = 0.0;
  double shear_modulus_12_pa = 0.0;
  double axis_angle_rad = 0.0;
  // Plane strain only.
  double youngs_modulus_3_pa = 0.0;
  double poisson_ratio_13 = 0.0;
  double poisson_ratio_23 = 0.0;

  // Names the first invalid field and its range (positive moduli, a positive definite
  // compliance).
  bool IsValid(PlaneModel model, std::string* error) const;
};
PlaneElasticity OrthotropicPlaneElasticity(const OrthotropicConstants& constants, PlaneModel model);

// Natural stiffness of one triangle (A2): K^N = A s l^-1 C^-1 D C^-T l^-1, with l the edge
// lengths and column k of C = (cx^2, cy^2, cx cy) of edge k. Edge k of triangle (a, b, c)
// joins (a, b), (b, c), (c, a) for k = 0, 1, 2. Symmetric: stored as the full 3 x 3 matrix.
Eigen::Matrix3d TriangleNaturalStiffness(const Vector<2>& a, const Vector<2>& b, const Vector<2>& c,
                                         const PlaneElasticity& d, double thickness_m);

// The natural stiffness constants of the equilateral triangle from the closed forms (A6):
// K(0), K(120), K(60) on the diagonal, their couplings off it, for edge 0 along x, edge 1 at
// 120 degrees, edge 2 at 60 degrees.
Eigen::Matrix3d EquilateralNaturalStiffness(const PlaneElasticity& d, double thickness_m);

// Isotropic six-spring constants per triangle, per E s (their eqs. (11), (12); plane strain by
// the substitution above): K^nn = k_nn E s on the diagonal, K^ns = k_ns E s off it.
struct SixSpringConstants {
  double k_nn = 0.0;
  double k_ns = 0.0;
  // The eigenvalues of K^N per E s: the volumetric mode k_nn + 2 k_ns and the (double)
  // deviatoric mode k_nn - k_ns.
  double volumetric() const { return k_nn + 2.0 * k_ns; }
  double deviatoric() const { return k_nn - k_ns; }
};
SixSpringConstants IsotropicSixSpringConstants(double poisson_ratio, PlaneModel model);

// E s and nu back from the two eigenvalues of an isotropic K^N (plane stress):
// E s = 4 sqrt(3) lv ld / (ld + 2 lv), nu = E s / (sqrt(3) ld) - 1.
void IsotropicConstantsFromEigenvalues(double volumetric, double deviatoric, double* youngs_times_thickness,
                                       double* poisson_ratio);

// The exact stability limit of central differences on the infinite regular lattice of side L
// with lumped masses rho s sqrt(3)/2 L^2 (plane stress; plane strain by the substitution):
// omega_max^2 = 16 E / (3 (1 - nu^2) rho L^2) at the M point of the Brillouin zone, so
// dt = 2 / omega_max = sqrt(3 (1 - nu^2)) / 2 * L / c with c = sqrt(E / rho).
double RegularLatticeStableTimeStep(double youngs_modulus_pa, double poisson_ratio, PlaneModel model,
                                    double density_kg_per_m3, double side_m);
// The paper's estimate (15), sqrt(m / 2 K^nn): above the exact limit by 9.5-30 % (plane stress,
// nu in [0, 0.5)), safe only with their divisor beta >= 10.
double PaperTimeStepEstimate(double youngs_modulus_pa, double poisson_ratio, PlaneModel model,
                             double density_kg_per_m3, double side_m, double thickness_m);

// The triangles of a lattice in flat arrays: nodes, rest edge vectors and natural stiffness.
struct TriangleLattice {
  double thickness_m = 1.0;
  std::vector<std::array<int, 3>> nodes;             // counter-clockwise
  std::vector<std::array<Vector<2>, 3>> rest_edges;  // x_end - x_start of edges 0, 1, 2
  std::vector<std::array<double, 3>> rest_lengths;
  std::vector<Eigen::Matrix3d> stiffness;            // K^N [N/m]
  std::vector<double> areas;                         // A [m^2]

  int size() const { return static_cast<int>(nodes.size()); }
};

// Builds the lattice of `triangles` (node indices into `centres`, either orientation; made
// counter-clockwise) with one D for every triangle. A triangle of zero area is an InputError.
TriangleLattice BuildTriangleLattice(const std::vector<Vector<2>>& centres,
                                     const std::vector<std::array<int, 3>>& triangles, const PlaneElasticity& d,
                                     double thickness_m);

// Row-sum lumped masses: each node gets rho s A / 3 of every triangle it belongs to (their
// eq. (2) for interior nodes of the regular lattice; the same rule on cut boundaries).
std::vector<double> LumpedMasses(const TriangleLattice& lattice, int node_count, double density_kg_per_m3);

// The stretches h_k = |d_k| - L0_k of triangle t's edges at `displacements`, for the current
// edge vector d = d0 + u_end - u_start, computed as (2 d0.du + du.du) / (|d| + L0) (no
// cancellation for small du; objective under rigid rotation), and the current unit edge
// directions.
inline Eigen::Vector3d EdgeStretches(const TriangleLattice& lattice, int t, const std::vector<Vector<2>>& displacements,
                                     std::array<Vector<2>, 3>* directions) {
  const std::array<int, 3>& v = lattice.nodes[t];
  Eigen::Vector3d h;
  for (int k = 0; k < 3; ++k) {
    const Vector<2>& d0 = lattice.rest_edges[t][k];
    const Vector<2> du = displacements[v[(k + 1) % 3]] - displacements[v[k]];
    const Vector<2> d = d0 + du;
    const double length = d.norm();
    h[k] = (2.0 * d0.dot(du) + du.squaredNorm()) / (length + lattice.rest_lengths[t][k]);
    (*directions)[k] = d / length;
  }
  return h;
}

// Adds the triangle forces at `displacements` (from the rest configuration of the lattice) to
// `forces` (sized to the node count): edge force f = K^N h of the stretches above, tension
// positive, pulling its two nodes together. Returns the elastic energy 1/2 h^T K^N h summed.
double AddTriangleForces(const TriangleLattice& lattice, const std::vector<Vector<2>>& displacements,
                         std::vector<Vector<2>>* forces);

// The Cartesian stiffness of one triangle from its natural stiffness, B_n^T K^N B_n with
// B_n the edge directions (the linearised map u -> h), in the node order a, b, c and
// components (x, y): the matrix the CST gives, A s B^T D B.
Eigen::Matrix<double, 6, 6> CartesianTriangleStiffness(const TriangleLattice& lattice, int triangle);

}  // namespace specimen
