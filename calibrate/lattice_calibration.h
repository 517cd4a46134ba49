#pragma once
// calibrate-to-material --model lattice: the six-spring lattice (lab/lattice_lab_test.h) for a
// target E, nu, UCS and tensile strength. The elastic constants need no calibration: D is the
// plane-strain matrix of the target's E and nu, which the lattice reproduces exactly (the
// linear portion of each round's UCS confirms it). The two strengths of the triangles, the
// cohesion c and the tensile strength sigma_t (phi: the target's friction angle, else free,
// from 30 degrees), are found by rounds of UCS and Brazilian tests on the real specimens:
//   - start: from the strength map when there is one for these specimens (options.map: the
//     (phi, sigma_t / c) whose UCS / sigma_t is the target's, c from its UCS / c; a target
//     out of its reach is said so before round 1, sigma_t given up); else c from the
//     triangles' own Mohr-Coulomb UCS, 2 c cos(phi) / (1 - sin(phi)) = UCS, and sigma_t = the
//     target's;
//   - each round measures the UCS and the Brazilian sigma_t; c is stepped by the UCS's
//     specimen factor (UCS over the closed form, the mean of the last three rounds: the UCS
//     has path noise; with a map, UCS over the map's, so that a change of sigma_t / c is
//     foreseen), sigma_t by its secant in logarithms against the Brazilian strength (the
//     slope 1 at first, then measured, clamped to [0.5, 1.5]), each at most a factor 3 per
//     step; rounds at the same c (within 3 %) on both sides of the target Brazilian strength
//     bracket the next sigma_t;
//   - a Brazilian strength that stops following the triangles' sigma_t is capped by their
//     shear limit. With a free friction angle it is lowered (at most twice, to 5 degrees at
//     the least; LowerFrictionAngle in the .cpp) and c follows; with the target's angle, or at
//     the lowest, sigma_t is out of reach, said so, and given up;
//   - a UCS that stops following c is capped by the tension cut-off: the UCS is then reached
//     through the triangles' sigma_t (c kept; between the nearest rounds on both sides of the
//     target once there are some; a bracket that closes on a leap of the UCS ends the
//     rounds, the UCS out of reach), and sigma_t is said out of reach and given up;
//   - stop when UCS and sigma_t are within their tolerances; the result is the best round.
//
//   LatticeCalibrationOptions options;
//   LatticeCalibrationSummary s = CalibrateLattice(ucs_packing, bts_packing, target, options);
//   std::cout << s.FullReport();

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "calibrate/target_material.h"
#include "common/progress.h"
#include "generator/packing.h"
#include "calibrate/lattice_strength_map.h"
#include "lab/lattice_lab_test.h"

namespace specimen {

struct LatticeCalibrationOptions {
  double tolerance_youngs = 0.015, tolerance_poisson = 0.015;  // the linear portion's check
  double tolerance_ucs = 0.02, tolerance_tensile = 0.05;
  int max_rounds = 12;                // in [1, 20]; a round is two tests
  LabTestOptions test;                // rate, sampling (kind is set per test)
  LatticeProtocol protocol;
  ProgressCallback progress;          // may be empty
  // The strength map of these specimens and tests (calibrate/lattice_strength_map.h), if
  // any: where it covers the target's nu (isotropic targets) it says before round 1 whether
  // UCS / sigma_t is within reach, gives the start (phi when free, c, sigma_t), and the c
  // steps follow its UCS / c between rounds at different sigma_t / c. Without it the rounds
  // start from the closed form.
  std::optional<LatticeStrengthMap> map;

  bool IsValid(std::string* error) const;
};

struct LatticeCalibrationRound {
  int round = 0;
  double cohesion_pa = 0.0, tensile_strength_pa = 0.0;  // of the triangles
  double friction_angle_deg = 0.0;                      // of the triangles
  double ucs_pa = 0.0, bts_pa = 0.0;                    // measured
  double youngs_modulus_pa = 0.0, poisson_ratio = 0.0;  // linear portion of the UCS
  double error_ucs = 0.0, error_tensile = 0.0, error_youngs = 0.0, error_poisson = 0.0;
  double weighted_error = 0.0;  // sum of (strength error / tolerance)^2
  double seconds = 0.0;
};

struct LatticeCalibrationSummary {
  TargetMaterial target;
  LatticeMaterial material;  // the best round's
  double friction_angle_deg = 30.0;  // of the result (the best round)
  std::vector<LatticeCalibrationRound> rounds;
  int best_round = 0;        // 1-based
  bool converged = false;    // UCS and sigma_t (unless given up) within tolerance, E, nu confirmed
  // sigma_t given up: the Brazilian strength stopped following the triangles' sigma_t (the
  // shear limit caps it at this friction angle), or the UCS stopped following c (the tension
  // cut-off caps it, and the UCS is reached through sigma_t).
  bool tensile_capped = false;
  // The map's reading before round 1 (map_used): the interval of UCS / sigma_t the lattice
  // reaches at the target's nu, and whether the target's lies in it.
  bool map_used = false;
  bool map_reachable = true;
  double map_ratio_low = 0.0, map_ratio_high = 0.0;
  std::vector<std::string> notes;
  int ucs_particles = 0, bts_particles = 0;
  double critical_time_step_s = 0.0;  // of the UCS test
  double wall_seconds = 0.0;

  std::string FullReport() const;
  std::string BriefReport() const;
  nlohmann::json ToJson() const;
  // The material as a run-test scene's [material] table (model = "lattice").
  std::string MaterialToml() const;
};

// InputError for invalid options, a non-rectangle UCS or a non-disc Brazilian specimen;
// ComputationError when a test reaches no peak.
LatticeCalibrationSummary CalibrateLattice(const Packing<2>& ucs, const Packing<2>& bts, const TargetMaterial& target,
                                           const LatticeCalibrationOptions& options);

// The same rounds on any model of the two tests (the one above runs the lattice on the two
// specimens; the tests use a cheap closed form with a cap and a leap, to check the steps in
// milliseconds). The particle counts of the summary are left 0.
LatticeCalibrationSummary CalibrateLattice(const TargetMaterial& target, const LatticeCalibrationOptions& options,
                                           const LatticeRoundModel& measure);

}  // namespace specimen
