#pragma once
// The critical time step of central differences on a six-spring lattice: dt_cr = 2 / omega_max
// with omega_max^2 the largest eigenvalue of M^-1/2 K M^-1/2, K the assembled Cartesian
// stiffness of the triangles (their natural stiffness, six_spring_lattice.h) and M the
// row-sum lumped masses. Found matrix-free by the certified Lanczos iteration of the bonded
// network's analysis (stability_lanczos.h): its upper bound holds except with probability
// `failure_probability`. On the infinite regular lattice the closed form is
// RegularLatticeStableTimeStep. Every node is taken free: held degrees of freedom only lower
// omega_max, so the step is safe for any supports.
//
//   LatticeStability s = AnalyseLatticeStability(lattice, LumpedMasses(lattice, n, rho), {});
//   double dt = 0.7 * s.critical_time_step_s;

#include <vector>

#include "solver/six_spring_lattice.h"
#include "solver/stability_lanczos.h"

namespace specimen {

struct LatticeStability {
  double omega_max_squared = 0.0;  // certified upper bound [1/s^2]
  double critical_time_step_s = 0.0;  // 2 / sqrt(omega_max_squared): safe
  // The Gershgorin bound (each row's absolute sum over its mass): cheap, never below
  // omega_max^2, often far above it on irregular lattices.
  double gershgorin_time_step_s = 0.0;
  LanczosResult lanczos;
};

// `masses` per node (a node of zero mass, in no triangle, is left out). InputError when no
// node has mass or a mass is negative.
LatticeStability AnalyseLatticeStability(const TriangleLattice& lattice, const std::vector<double>& masses,
                                         const LanczosOptions& options);

}  // namespace specimen
