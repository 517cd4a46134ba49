#pragma once
// The sweep that builds the micro-macro maps: the virtual UCS and Brazilian tests
// (lab/lab_test.h) at every point of a grid of micro ratios, on a packing pair (a UCS
// specimen and a BTS disc), reduced to the dimensionless groups of dimensionless_groups.h.
//
//   SweepDesign design = DefaultSweepDesign(/*deformable=*/false);
//   MapSweepOptions options;             // reference kn, Rn, density; test protocol; workers
//   options.journal_path = "sweep.jsonl";  // a killed sweep resumes from here
//   MapSweep sweep = RunMapSweep<2>(ucs_packing, bts_packing, design, options);
//   MapSet maps = FitMaps(sweep, design, 2);
//
// Only the ratios matter: with global contact constants E ~ kn and strengths ~ Rn at fixed
// ratios (Labra 4.49-4.57, Madan 4.9-4.10), so the sweep runs at one reference kn and Rn
// (chosen near the target so the time step and rate are realistic) and stores groups.
// Points run in parallel, one solver thread each; each finished point is appended to the
// journal (one JSON line, flushed and synced) before the next starts, so a sweep killed at
// any moment loses at most the points in flight.
//
// Under mpirun (common/ranks.h) the pending points are split over the ranks (point k of the
// pending list on rank k % N), each rank running its share on its own `workers` threads and
// journaling to its own file (rank 0 the journal, rank r "<journal>.rank<r>"); a resume reads
// them all; at the end every rank has every point (the same maps whatever N, bit for bit).

#include <Eigen/Core>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "calibrate/dimensionless_groups.h"
#include "calibrate/map_set.h"
#include "common/progress.h"
#include "generator/packing.h"
#include "lab/lab_test.h"

namespace specimen {

// One varying micro ratio: `levels` values in [lower, upper], equally spaced, or in equal
// ratios (geometric, lower > 0) where the response varies as its logarithm.
struct SweepAxis {
  MicroRatio ratio = MicroRatio::kStiffnessRatio;
  double lower = 0.0;
  double upper = 0.0;
  int levels = 3;  // >= 2
  bool geometric = false;

  // The value at `fraction` of the axis in [0, 1] (the level k is at k / (levels - 1)).
  double At(double fraction) const;
};

// A full factorial grid over the axes; the ratios without an axis take `fixed`.
struct SweepDesign {
  std::vector<SweepAxis> axes;
  MicroRatios fixed;

  // The grid points, the first axis varying slowest.
  std::vector<MicroRatios> Points() const;
  std::vector<MicroRatio> Inputs() const;
  // Names the first invalid field, its value and the allowed range.
  bool IsValid(std::string* error) const;
  nlohmann::json ToJson() const;
  static SweepDesign FromJson(const nlohmann::json& j);
};

// Rigid particles: kt/kn in [0.15, 0.9] (4 levels; nu falls from near the DEM limit to about
// 0.03 in plane strain; below about 0.1 small specimens lose lateral stiffness and buckle) x
// Rt/Rn in [1, 10] (3 geometric levels 1, 3.16, 10; Labra's range, sections 4.3.3-4.3.4;
// sigma_c / sigma_t grows with it from Rt/Rn = 1, where shear failure dominates, steeply up to
// about 4 and then slowly: on the default 5,064-disc specimen at kt/kn 0.2 it is 8.4 at
// Rt/Rn 1, 10.1 at 1.45, 12.0 at 1.9, 16.4 at 4, and 10.2 again at 0.5), mu fixed. Deformable particles add
// kn/(Ep l) in [0, largest_particle_compliance] (3 levels) at the fixed nu_p: a nu_p above
// 0.25 shifts nu above the DEM curve (Madan section 4.5, Figs. 4.17-4.18), kt/kn then in
// [0.15, 0.6] (3 levels) where the high nu lies.
SweepDesign DefaultSweepDesign(bool deformable, double particle_poisson_ratio = 0.45,
                               double largest_particle_compliance = 0.0,
                               double friction_coefficient = 0.8);

// Where the maps are measured on the real (calibration) specimens as well, once, when they
// are built: the transfer anchors (quarters of a geometric axis in equal ratios). Surfaces fitted on smaller map specimens are offset from
// what the real specimens measure (strengths by 10-25 %, sigma_c / sigma_t by up to 50 %)
// but keep their trends; the anchors measure the offset across the box, and every
// calibration on these maps starts from surfaces corrected by them (surrogate.h). A
// two-level design at 1/4 and 3/4 of each axis: 2^k points for k <= 2 axes, the half
// fraction (the product of the signs +1) for k = 3, 4 points at most. With `levels` 3, besides
// these, a three-level design at the edges and the middle of each axis (where the extremes of
// sigma_c / sigma_t lie): the full 3 x 3 for k = 2, a Latin square of 9 points for k = 3 (every
// pair of levels of any two axes once; further axes at their middle): 13 anchors in all.
std::vector<MicroRatios> TransferAnchorPoints(const SweepDesign& design, int levels = 2);

// The ratios as JSON (the keys of the map files).
nlohmann::json SweepPointRatiosToJson(const MicroRatios& ratios);
MicroRatios SweepPointRatiosFromJson(const nlohmann::json& j);

// The measured results of one sweep point.
struct SweepPoint {
  int index = -1;  // in SweepDesign::Points()
  MicroRatios ratios;
  bool ok = false;
  std::string failure;  // why the point failed (ok = false)
  // Measured (2D: plane-strain E and nu, docs/lab.md, "Measurement"); E and nu those of the
  // intact specimen (intact_elastic.h).
  double youngs_modulus_pa = 0.0;
  double poisson_ratio = 0.0;
  double ucs_pa = 0.0;
  double tensile_strength_pa = 0.0;
  bool ucs_peak_reached = false;
  bool bts_peak_reached = false;
  // The groups (dimensionless_groups.h) with each test's own packing descriptors.
  double elastic_group = 0.0;
  double compressive_group = 0.0;
  double tensile_group = 0.0;
  double seconds = 0.0;  // wall time of the two tests

  nlohmann::json ToJson() const;
  static SweepPoint FromJson(const nlohmann::json& j);
};

struct MapSweepOptions {
  // Reference contact constants of the sweep (any positive values: the groups are
  // independent of them; near the target they keep the step and rate realistic).
  double normal_stiffness_n_per_m = 0.0;   // kn, > 0
  double bond_tensile_strength_n = 0.0;    // Rn, > 0
  double density_kg_per_m3 = 0.0;          // rho, > 0 (scaled per test when asked)
  PlaneModel plane_model = PlaneModel::kPlaneStrain;
  // The protocol of both tests (kind and progress are set per test).
  LabTestOptions test;
  // Points run at once on each rank (one solver thread each), >= 1.
  int workers = 2;
  // Journal of finished points (JSON lines); empty: none. Points already in it (same
  // design) are not run again.
  std::string journal_path;
  ProgressCallback progress;  // may be empty

  bool IsValid(std::string* error) const;
};

struct MapSweep {
  std::vector<SweepPoint> points;  // in design order
  PackingDescriptors ucs_descriptors;
  PackingDescriptors bts_descriptors;
  int resumed_points = 0;  // taken from the journal
  int failed_points = 0;
  double seconds = 0.0;    // wall time of this call
};

// The protocol of a strength test (UCS or Brazilian) of the sweep and of the calibration's
// rounds: `protocol` on one solver thread, without the half-rate repeat, its automatic strain
// limit raised to 0.05 (soft, compliant corners of a design peak late).
LabTestOptions StrengthTestProtocol(LabTestOptions protocol);

// The material of one test at one point: kn, kt = (kt/kn) kn, Rn, Rt = (Rt/Rn) Rn, mu, rho,
// Ep = kn / ((kn/(Ep l)) l) when deformable (l = 1 m in 2D, the mean radius in 3D).
MaterialParameters MaterialAt(const MicroRatios& ratios, double normal_stiffness_n_per_m,
                              double bond_tensile_strength_n, double density_kg_per_m3,
                              PlaneModel plane_model, double group_length_m);

// Runs (or resumes) the sweep. Throws InputError for invalid designs or options, FileError
// when the journal cannot be written. A point whose simulation fails is kept with ok = false.
// With several ranks every rank calls it with the same arguments; a rank whose point throws
// lets the others finish theirs, then every rank throws the same error, naming the point and
// the rank; progress is reported on rank 0 only, counting the points of every rank.
template <int Dim>
MapSweep RunMapSweep(const Packing<Dim>& ucs_packing, const Packing<Dim>& bts_packing,
                     const SweepDesign& design, const MapSweepOptions& options);

// The same at a list of points (the transfer anchors on the real specimens, say); the
// journal key is the list. `index` of each result is its place in the list.
template <int Dim>
MapSweep RunSweepPoints(const Packing<Dim>& ucs_packing, const Packing<Dim>& bts_packing,
                        const std::vector<MicroRatios>& points, const MapSweepOptions& options);

// Removes the journal of a finished sweep and the rank journals beside it (one process: rank
// 0 when distributed).
void RemoveSweepJournals(const std::string& journal_path);

// Fits the four surfaces (nu, Psi_E, Psi_c, Psi_t) over the design's inputs from the
// points that succeeded; InputError if too few did. max_total_degree as ResponseSurface.
MapSet FitMaps(const MapSweep& sweep, const SweepDesign& design, int max_total_degree);

}  // namespace specimen
