#pragma once
// The lattice's strength map: what the two tests of a lattice calibration round (UCS and
// Brazilian) give per unit strength of the triangles, over the triangles' strength ratio
// s = sigma_t / c and friction angle phi, in rows of Poisson's ratio, on one pair of
// specimens. The lattice is elastic-brittle and quasi-static at its capped rate
// (lab/lattice_lab_test.h), so UCS / c and sigma_B / sigma_t depend on s, phi and nu, and
// only weakly on the strain scale c / E (docs/calibration.md, "The lattice's strength map":
// a few per cent in the UCS, 0.3 % in the Brazilian strength between c / E of
// 2.5e-4 and 2e-3); the map is measured at c / E = 1e-3 and the rounds correct the rest.
//
// A lattice calibration reads from it, before round 1, where the target's UCS / sigma_t lies
// (the interval the lattice reaches at the target's nu on these specimens) and its start:
// the (phi, s) whose ratio is the target's, c from the map's UCS / c, sigma_t = s c.
//
//   LatticeStrengthMap map;  // map.design: the default grid
//   MeasureLatticeMapRows({0.25}, LatticeTestsOn(ucs, bts, test, protocol), progress, &map);
//   LatticeMapStart start = StartFromMap(map, target);   // start.reachable, start.cohesion_pa, ...

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "calibrate/dimensionless_groups.h"
#include "calibrate/target_material.h"
#include "common/progress.h"
#include "generator/packing.h"
#include "lab/lattice_lab_test.h"

namespace specimen {

// What a round (or a map point) measures at the triangles' strengths: the UCS (and its
// linear portion's E and nu) and the Brazilian strength.
struct LatticeRoundMeasurement {
  double ucs_pa = 0.0, bts_pa = 0.0;
  double youngs_modulus_pa = 0.0, poisson_ratio = 0.0;
  double critical_time_step_s = 0.0;  // of the UCS test
};
// The two tests at `material` (round: 1-based, for messages); throws ComputationError when a
// test fails.
using LatticeRoundModel = std::function<LatticeRoundMeasurement(const LatticeMaterial& material, int round)>;

// The two lattice tests on the two specimens (which must outlive the model), run at once (two
// threads); a test that reaches no peak throws ComputationError naming it. InputError for a
// non-rectangle UCS or a non-disc Brazilian specimen.
LatticeRoundModel LatticeTestsOn(const Packing<2>& ucs, const Packing<2>& bts, const LabTestOptions& test,
                                 const LatticeProtocol& protocol);

// The grid of a map. Each row (one nu) holds every (phi, s) pair.
struct LatticeMapDesign {
  std::vector<double> poisson_ratios = {0.05, 0.15, 0.25, 0.35, 0.45};  // in [0, 0.5), ascending
  std::vector<double> friction_angles_deg = {5.0, 15.0, 30.0, 50.0};    // in [0, 60], ascending
  std::vector<double> tensile_over_cohesion = {0.05, 0.1, 0.2, 0.4, 1.0, 2.5};  // > 0, ascending
  double cohesion_over_modulus = 1e-3;  // the strain scale c / E of the points, in (0, 0.01]

  bool IsValid(std::string* error) const;
  nlohmann::json ToJson() const;
  static LatticeMapDesign FromJson(const nlohmann::json& j);
  // The rows of this grid needed at `poisson_ratio`: the one it falls on (within 0.005), else
  // the two around it; outside the grid, a row at `poisson_ratio` itself.
  std::vector<double> RowsFor(double poisson_ratio) const;
};

struct LatticeMapPoint {
  double poisson_ratio = 0.0, friction_angle_deg = 0.0, tensile_over_cohesion = 0.0;
  double ucs_over_cohesion = 0.0;  // UCS / c
  double bts_over_tensile = 0.0;   // sigma_B / sigma_t
  double seconds = 0.0;
  double StrengthRatio() const { return ucs_over_cohesion / (bts_over_tensile * tensile_over_cohesion); }
};

struct LatticeStrengthMap {
  std::string code_version, created_utc;
  PackingDescriptors ucs_descriptors, bts_descriptors;
  nlohmann::json protocol;  // LatticeMapProtocol of the tests it was measured with
  LatticeMapDesign design;  // the rows present are those of the points
  std::vector<LatticeMapPoint> points;
  double build_seconds = 0.0;

  std::vector<double> Rows() const;  // the nu of the complete rows present, ascending
  const LatticeMapPoint* Find(double poisson_ratio, double friction_angle_deg, double tensile_over_cohesion) const;
  // Whether the rows present interpolate nu: a row within 0.005, or rows on both sides at
  // most 0.1 apart. `why` says what is missing.
  bool Covers(double poisson_ratio, std::string* why = nullptr) const;
  // UCS / c and sigma_B / sigma_t at (nu, phi, s): linear in nu and phi, in ln s, of the
  // logarithms; phi and s clamped to the grid. InputError unless Covers(nu).
  LatticeMapPoint At(double poisson_ratio, double friction_angle_deg, double tensile_over_cohesion) const;

  nlohmann::json ToJson() const;
  // InputError naming what is missing or malformed (`source` names the file).
  static LatticeStrengthMap FromJson(const nlohmann::json& j, const std::string& source);
};

// The identity of the tests a map was measured with (the rate group, the lattice protocol,
// the post-peak stop): a map is used only by tests with the same.
nlohmann::json LatticeMapProtocol(const LabTestOptions& test, const LatticeProtocol& protocol);

// Measures the points of the map's design at the rows `poisson_ratios` (in [0, 0.5); a row
// new to the design is added to it), appending to `map` (rows already present are measured
// again and replaced; an exception leaves `map` as it was). A failed or refused test (no
// peak, or beyond its step budget) throws ComputationError naming the point.
// Each point runs `measure` at E = c / cohesion_over_modulus, c = 30 MPa. Progress: fraction
// of the points, with the point.
void MeasureLatticeMapRows(const std::vector<double>& poisson_ratios, const LatticeRoundModel& measure,
                           const ProgressCallback& progress, LatticeStrengthMap* map);

// Where a target lies on the map, and the start of its rounds.
struct LatticeMapStart {
  bool reachable = false;         // the target's UCS / sigma_t lies in [ratio_low, ratio_high]
  double ratio_low = 0.0, ratio_high = 0.0;  // at the target's nu, over the angles allowed
  double friction_angle_deg = 0.0;           // the start's
  double cohesion_pa = 0.0, tensile_strength_pa = 0.0;
  double predicted_ucs_pa = 0.0, predicted_bts_pa = 0.0;  // by the map at the start
  // d ln sigma_B / d ln sigma_t at fixed c, from the map at the start (for the first step).
  double tensile_slope = 1.0;
  std::string statement;  // one sentence for the report
};

// Allowed angles: the target's friction angle when it gives one (it must lie within the
// map's), else the map's whole range, with 30 degrees (the calibration's default) preferred
// and the angle nearest it that reaches the ratio otherwise. Among roots in s at that angle
// the one nearest the closed-form start (sigma_t of the target, c of the Mohr-Coulomb UCS)
// is taken. Out of reach: the start is the nearest reachable ratio's point (UCS honoured).
// InputError if the map does not cover the target's nu or angle.
LatticeMapStart StartFromMap(const LatticeStrengthMap& map, const TargetMaterial& target);

// Atomic write (FileError if it cannot be written); load: FileError if unreadable,
// InputError if not a lattice map.
void SaveLatticeStrengthMap(const LatticeStrengthMap& map, const std::string& path);
// Adds to `map` the complete rows of `stored` that it lacks (their points, and their nu to its
// design); the two must be maps of the same specimens and tests. Another run may have added
// rows to the file since `map` was read: merged before a save, neither run's rows are lost.
// Returns the number of rows added.
int MergeLatticeMapRows(const LatticeStrengthMap& stored, LatticeStrengthMap* map);
LatticeStrengthMap LoadLatticeStrengthMap(const std::string& path);

// The file name for maps on these specimens with this protocol:
// maps_2d_lattice_<hash of descriptors and protocol>.json.
std::string LatticeMapFileName(const PackingDescriptors& ucs, const PackingDescriptors& bts,
                               const nlohmann::json& protocol);
// Whether `map` was measured on equivalent specimens (descriptors as MapsMatchPacking,
// particle counts within 10 %: the strengths depend on the size) with this protocol; `why`
// names the first difference.
bool LatticeMapMatches(const LatticeStrengthMap& map, const PackingDescriptors& ucs, const PackingDescriptors& bts,
                       const nlohmann::json& protocol, std::string* why);
// The lattice map in `directory` for these specimens and protocol (descriptors as
// MapsMatchPacking, particle counts within 10 %): a path, or empty. Unreadable files are
// skipped.
std::string FindLatticeStrengthMap(const std::string& directory, const PackingDescriptors& ucs,
                                   const PackingDescriptors& bts, const nlohmann::json& protocol);

}  // namespace specimen
