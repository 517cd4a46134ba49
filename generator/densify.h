#pragma once
// Step 4 of the generator: Levenberg-Marquardt densification of centres and radii
// (Labra sections 3.2.1-3.2.3) with Ceres on a sparse problem.
//
// Unknowns: every centre and radius. Residuals, on the current contact graph:
//   edge (i, j):        d = |xi - xj|^2 - (ri + rj)^2                    (Labra 3.1)
//   tie (i, facet k):   b = s|s| - ri^2,  s = signed distance to facet   (Labra 3.8)
// (3.8 as printed, s^2 - r^2, vanishes again for a particle a radius beyond the wall;
// s|s| keeps pulling it back.) Radii are bounded to [radius_min, radius_max].

#include <functional>
#include <string>
#include <vector>

#include "generator/contact_graph.h"
#include "generator/domain.h"

namespace specimen {

struct LevenbergMarquardtOptions {
  // Radius bounds, as Ceres parameter bounds.
  double radius_min = 0.0;
  double radius_max = 0.0;
  // Weight multiplying residuals of overlapping pairs (d < 0); 1 = plain least squares.
  double overlap_weight = 1.0;
  // Residual scale (a length, usually the mean radius): residuals are divided by its
  // square so that the solver's tolerances are scale-free.
  double length_scale = 1.0;
  int max_iterations = 50;
  // Stop as soon as the cost (half the sum of squared residuals) is below this: once every
  // residual is far inside the tolerances that matter, further iterations only polish
  // round-off (and near a solution CGNR steps get expensive). 0 = off.
  double stop_cost = 0.0;
  double function_tolerance = 1e-12;
  double gradient_tolerance = 1e-14;
  double parameter_tolerance = 1e-12;
  int num_threads = 1;
  // Extra weight on boundary residuals of particles beyond their facet: a protrusion is
  // never acceptable downstream, an interior gap is, so a least-squares compromise should
  // land in the interior.
  double protrusion_weight = 10.0;
  // Edges and ties flagged here are one-sided (residual only when overlapping): pairs
  // that are neighbours but not contacts must not be pushed together, only kept apart.
  std::vector<char> edge_one_sided;   // per graph edge; empty = all two-sided
  std::vector<char> tie_one_sided;    // per boundary tie
  // Proximal term: position_anchor_weight * (x_i - x_i at the start) / length_scale keeps
  // every solve a local step and removes the null space of underdetermined problems.
  double position_anchor_weight = 0.0;
  // Particles free to move in this solve; empty = all. Residuals that touch no free
  // particle are left out and the others' fixed particles are held constant, so a repair
  // of a few defects costs in proportion to the defects, not to the packing.
  std::vector<char> free_particles;
  // Called after every iteration with the current [x, r] blocks (size N (Dim + 1)) when set;
  // for convergence traces (benchmarks), it costs a copy of the state per iteration.
  std::function<void(int iteration, const std::vector<double>& blocks)> on_iteration;
  // Use conjugate gradients on the normal equations (inexact steps) instead of sparse
  // Cholesky; cheaper per iteration on large 3D problems.
  bool iterative_linear_solver = false;
  // Banded edges (the contact band, contact_band.h) when band_gap > 0: the residual of
  // an edge is the part of its gap (|xi - xj| - ri - rj, absolute) outside
  // [-band_overlap, band_gap] for a two-sided edge, below -band_overlap for a one-sided one.
  // These are inequalities, not equalities: more than (Dim + 1) N pairs can sit in the band
  // at once, which exact contacts with free radii cannot (README, the rigidity bound).
  double band_overlap = 0.0;
  double band_gap = 0.0;
};

struct LevenbergMarquardtSummary {
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  double seconds = 0.0;
  std::string termination;  // Ceres' termination message
};

// Minimises the sum of squared residuals over the given graph, updating centres and radii
// in place.
template <int Dim>
LevenbergMarquardtSummary SolveLevenbergMarquardt(const Domain<Dim>& domain,
                                                  const ContactGraph<Dim>& graph,
                                                  const LevenbergMarquardtOptions& options,
                                                  std::vector<Vector<Dim>>& centres,
                                                  std::vector<double>& radii);

// The residuals and their Jacobians, exposed for testing against finite differences.
// Parameters are [x..., r] blocks of size Dim + 1.
template <int Dim>
double EdgeResidual(const double* particle_i, const double* particle_j, double length_scale,
                    double overlap_weight, bool one_sided, double* jacobian_i, double* jacobian_j);
template <int Dim>
double BandEdgeResidual(const double* particle_i, const double* particle_j, double length_scale,
                        double band_overlap, double band_gap, double overlap_weight,
                        bool one_sided, double* jacobian_i, double* jacobian_j);
template <int Dim>
double BoundaryResidual(const Domain<Dim>& domain, const BoundaryFacet<Dim>& facet,
                        const double* particle, double length_scale, double protrusion_weight,
                        bool one_sided, double* jacobian);

}  // namespace specimen
