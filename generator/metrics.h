#pragma once
// Packing metrics (Labra section 3.3 and what a DEM user checks before trusting a
// specimen): size, porosity (nominal and overlap-corrected), coordination, overlaps and
// gaps, fabric, contact orientations, protrusion through the boundary, and the
// descriptors the calibrator needs (Labra 4.47-4.59).

#include <Eigen/Core>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "generator/packing.h"

namespace specimen {

struct MetricsOptions {
  // Bins of the contact-orientation histogram over [0, 180) degrees (contacts have no
  // direction). In 3D the histogram is made for the projections onto the xy, xz and yz
  // planes (Labra Fig. 3.17), each weighted by the length of the projected normal.
  int orientation_bins = 36;
  // 3D overlap-corrected porosity: directions of the spherical quadrature used for the
  // particles that are cut by a neighbour or the boundary (the others are exact).
  // NOT USED ANY MORE, kept so that existing callers compile: the cut spheres are now
  // exact (disjoint caps) or bracketed by exact slice areas with a guaranteed bound (see
  // union_volume.h, ball_clip_volume.h); corrected_porosity_tolerance sets the accuracy.
  int sphere_quadrature_directions = 4000;
  // 3D overlap-corrected porosity: target for the guaranteed bound corrected_porosity_error
  // (absolute porosity), in (0, 1). Met unless a sphere exhausts max_slices_per_sphere;
  // the bound reached is reported either way. 2D is exact and ignores it.
  double corrected_porosity_tolerance = 2.5e-4;
  // 3D: most slice areas evaluated for one sphere that has no closed form, >= 8.
  int max_slices_per_sphere = 2000;

  // False (and a message naming the field, its value and the range) if a field is invalid.
  bool IsValid(std::string* error) const;
};

template <int Dim>
struct PackingMetrics {
  int particle_count = 0;
  double domain_volume = 0.0;    // area in 2D (per unit thickness)
  double particle_volume = 0.0;  // sum of particle volumes, overlaps counted twice
  double mean_radius = 0.0;      // volume-based, Labra (3.12)
  double min_radius = 0.0;
  double max_radius = 0.0;
  double radius_ratio = 0.0;     // max / min

  // Labra (3.13) with V_p = sum of particle volumes (the "nominal" porosity he reports).
  double nominal_porosity = 0.0;
  // 1 - |union of particles clipped to the domain| / |domain|: exact in 2D, within
  // +-0.001 absolute in 3D (corrected_porosity_error is the bound used).
  double corrected_porosity = 0.0;
  double corrected_porosity_error = 0.0;

  int contact_count = 0;                  // packing.contacts.size()
  double coordination_number = 0.0;       // 2 Nc / Np, Labra (3.17)
  double under_coordinated_fraction = 0.0;  // share of particles with fewer than Dim + 1 contacts

  // Overlaps over every overlapping pair in the packing (not only contacts), relative to
  // mean_radius; gaps over the contacts with a positive gap, relative to mean_radius.
  // Pairs whose overlap is round-off (below 1e-12 mean_radius) count as touching.
  int overlapping_pairs = 0;
  double mean_overlap = 0.0;
  double max_overlap = 0.0;
  double mean_contact_gap = 0.0;
  double max_contact_gap = 0.0;

  // Normalised fabric tensor phi' = sum n n^T / Nc, Labra (3.19)-(3.21); eigenvalues ascending.
  Eigen::Matrix<double, Dim, Dim> fabric = Eigen::Matrix<double, Dim, Dim>::Zero();
  Eigen::Matrix<double, Dim, 1> fabric_eigenvalues = Eigen::Matrix<double, Dim, 1>::Zero();

  // Contact orientation histogram(s): one row in 2D (angle of n in [0, 180) deg), three rows
  // in 3D (projections onto xy, xz, yz). Each row has orientation_bins counts (weights).
  std::vector<std::vector<double>> orientation_histograms;

  // Largest distance a particle reaches beyond the domain boundary, relative to mean_radius
  // (0 if every particle is inside), and how many particles protrude at all.
  double max_protrusion = 0.0;
  int protruding_particles = 0;

  // Descriptors for the calibrator (Labra 4.47-4.59): moments of the radius and of the
  // branch length l = |xj - xi| over the contacts.
  double mean_radius_squared = 0.0;  // <r^2>
  double mean_radius_cubed = 0.0;    // <r^3>
  double mean_branch_length = 0.0;   // <l>
  double mean_branch_length_squared = 0.0;  // <l^2>
};

// Computes every metric. Cost: O(N) plus a neighbour search for overlapping pairs.
template <int Dim>
PackingMetrics<Dim> ComputePackingMetrics(const Packing<Dim>& packing,
                                          const MetricsOptions& options = MetricsOptions());

// A table for the terminal (Ceres FullReport style) and the same content as JSON.
template <int Dim>
std::string MetricsReport(const PackingMetrics<Dim>& metrics);
template <int Dim>
nlohmann::json MetricsToJson(const PackingMetrics<Dim>& metrics);

// Area (2D) / volume (3D) of the union of the particles clipped to the domain, used for
// the corrected porosity; exposed for tests. In 3D `error_bound` receives the bound on the
// absolute error of the returned volume.
template <int Dim>
double ClippedUnionVolume(const Packing<Dim>& packing, const MetricsOptions& options,
                          double* error_bound);

}  // namespace specimen
