#pragma once
// calibrate-to-material: contact parameters kn, kt, Rn, Rt, mu (and Ep, nu_p of deformable
// particles) that make the virtual UCS and Brazilian tests reproduce a target E, nu, UCS and
// tensile strength, within the DDEM convergence bound, measured on the real specimens.
// Options in, CalibrationSummary out (BriefReport, FullReport, ToJson):
//
//   CalibrationSpecimens<2> specimens = MakeCalibrationSpecimens<2>(SpecimenPlan<2>());
//   CalibrationOptions options;            // automatic model, maps under data/maps
//   CalibrationSummary summary = CalibrateToMaterial<2>(specimens, target, options);
//   std::cout << summary.FullReport();     // reach, rounds, achieved, parameters, verdict
//
// The steps (Labra 2012 chapter 4; Madan 2019 section 4):
// 1. Maps (map_sweep.h, map_store.h): UCS, Brazilian and elastic runs at the points of a grid
//    of micro ratios on smaller map specimens, reduced to the dimensionless groups and fitted
//    by smooth surfaces; when the maps are built, the same tests on the real specimens at the
//    transfer anchors (TransferAnchorPoints: 4, or 13 with anchor_levels 3), which measure how
//    the surfaces' offsets transfer.
//    Maps are reused from the map directory when maps of the same design and protocol exist
//    for an equivalent packing.
// 2. Reach and model (calibration_solver.h): elastic runs at the corners of the box give the
//    nu this specimen reaches; the surfaces, corrected by every stored measurement on it
//    (surrogate.h), give the sigma_c / sigma_t reachable with that nu. Rigid particles when
//    they reach both, else DDEM; a target outside both is reported before any strength test.
// 3. Elastic stage: kt/kn (DDEM: kn/(Ep l), then kt/kn) for nu and kn for E, by elastic runs
//    on the real UCS specimen (intact_elastic.h: E and nu of the intact specimen).
// 4. Strength stage: rounds of UCS and Brazilian tests; Rt/Rn for sigma_c / sigma_t and Rn
//    for the strengths, from the surfaces corrected through the rounds so far, inside a trust
//    region; the best round is the result.
// 5. Stability verdict of the final set (time step and rho(B)) on the real UCS specimen.
// Every run on the real specimens is stored with the maps: later calibrations start from
// surfaces corrected by them.

#include <optional>
#include <utility>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "calibrate/calibration_solver.h"
#include "calibrate/dimensionless_groups.h"
#include "calibrate/map_set.h"
#include "calibrate/map_set.h"
#include "calibrate/map_store.h"
#include "calibrate/map_sweep.h"
#include "calibrate/target_material.h"
#include "common/progress.h"
#include "generator/packing.h"
#include "lab/lab_test.h"
#include "solver/material.h"

namespace specimen {

enum class CalibrationModel { kRigid, kDeformable, kAutomatic };
const char* CalibrationModelName(CalibrationModel model);  // "rigid", "ddem", "auto"
bool ParseCalibrationModel(const std::string& name, CalibrationModel* model);

// How the specimens are generated when no packing files are given.
template <int Dim>
struct SpecimenPlan {
  // UCS specimen: 2D rectangle 50 x 50 mm (Labra's verification specimen), 3D cylinder of
  // diameter 50 mm and height 100 mm; the Brazilian disc (cylinder of length D/2) has the
  // UCS specimen's width as diameter and the same mean radius.
  std::string ucs_domain;     // empty: the default above
  int ucs_particles = 0;      // 0: 5,000 (2D), 20,000 (3D)
  // Sweep specimens: this share of the particles, same mean radius (domains scaled), in
  // (0, 1]; 1 = sweep on the real specimens.
  double sweep_fraction = 0.3;
  std::uint64_t seed = 1;
  double radius_ratio = 10.0;
  int threads = 2;
  ProgressCallback progress;
  bool IsValid(std::string* error) const;
};

template <int Dim>
struct CalibrationSpecimens {
  CalibrationSpecimens(Packing<Dim> ucs_specimen, Packing<Dim> bts_specimen, Packing<Dim> sweep_ucs_specimen,
                       Packing<Dim> sweep_bts_specimen)
      : ucs(std::move(ucs_specimen)),
        bts(std::move(bts_specimen)),
        sweep_ucs(std::move(sweep_ucs_specimen)),
        sweep_bts(std::move(sweep_bts_specimen)) {}
  Packing<Dim> ucs, bts;              // verification specimens
  Packing<Dim> sweep_ucs, sweep_bts;  // map specimens (may equal the above)
  std::string description;            // how they were made (domains, counts, seed, files)
};

// Generates the four specimens. InputError for an invalid plan.
template <int Dim>
CalibrationSpecimens<Dim> MakeCalibrationSpecimens(const SpecimenPlan<Dim>& plan);

struct CalibrationOptions {
  CalibrationModel model = CalibrationModel::kAutomatic;

  // --- Maps ---
  std::string maps_directory = "data/maps";  // stored and reused here; empty: not stored
  bool reuse_maps = true;
  std::string maps_file;                     // use these maps (must match the packing)
  int max_total_degree = 2;                  // of the fitted surfaces, 1 to 4
  // Designs; an empty axis list takes DefaultSweepDesign.
  SweepDesign rigid_design;
  SweepDesign deformable_design;
  // Levels of kt/kn in the default designs (the other axes: one fewer, at least 3), 3 to 12;
  // 0 = DefaultSweepDesign's (4 rigid, 3 deformable). Denser sweeps: smaller fit error.
  int sweep_levels = 0;
  // The box of kt/kn in the default designs, 0 < lower < upper <= 1; both 0 = DefaultSweepDesign's
  // (rigid 0.15-0.9, DDEM 0.15-0.6). nu falls with kt/kn, so a lower bound below 0.15 reaches
  // a higher nu (docs/calibration.md, "Reach of the models"). The command line, which has no
  // unset value, refuses 0 itself.
  double stiffness_ratio_lower = 0.0;
  double stiffness_ratio_upper = 0.0;
  double particle_poisson_ratio = 0.45;  // nu_p of the deformable maps, in (-1, 0.5)
  double friction_coefficient = 0.8;     // mu (Labra's verification value), >= 0
  // gamma of every map and round: bonds within gamma (ri + rj) (solver/bond_range.h), [1, 1.5].
  // Above 1 it raises sigma_c / sigma_t of bonded spheres (docs/calibration.md, "Reach").
  double bond_range = 1.0;
  // Transfer anchors on the real specimens (map_sweep.h TransferAnchorPoints): 2 = the four
  // of a two-level design, 3 = besides them nine at the edges and middle of the box. Stored
  // maps that lack some for these real specimens (fewer levels, or anchored on specimens that
  // MapsMatchPacking refuses) are completed before use: the missing anchors measured, stored.
  int anchor_levels = 2;
  // Sweep points (and elastic runs) at once on each rank; 0 = hardware threads.
  int workers = 0;

  // --- Protocol of every test (kind, progress set per test). Density scaling is on. ---
  LabTestOptions test;

  // --- Bounds and verification ---
  double max_spectral_radius = 0.9;  // rho(B) of the DDEM iteration, in (0, 1)
  HonouredStrength honour = HonouredStrength::kCompressive;  // when sigma_c/sigma_t is unreachable
  // Tolerances, relative, in (0, 1). The strengths' path noise on 5,000 discs is 0.3-1.2 %
  // (UCS) and about 1 % (sigma_t); the elastic runs repeat within 0.1 %.
  int max_verification_rounds = 6;   // strength rounds (UCS + BTS), 1 to 20
  int max_elastic_runs = 12;         // elastic runs (reach included), 4 to 100
  double tolerance_youngs = 0.015;
  double tolerance_poisson = 0.015;
  double tolerance_ucs = 0.02;
  double tolerance_tensile = 0.05;
  ProgressCallback progress;

  CalibrationOptions();
  bool IsValid(std::string* error) const;
};

// One strength round of UCS and BTS, as the report shows it.
struct VerificationRound {
  int round = 0;
  MaterialParameters material;
  MicroRatios ratios;
  // E and nu of the round's elastic set (the intact specimen, intact_elastic.h), the figures
  // the calibration matches; Labra's secants over 1-50 % of this UCS's own peak beside them.
  double youngs_modulus_pa = 0.0, poisson_ratio = 0.0, ucs_pa = 0.0, tensile_strength_pa = 0.0;
  double own_peak_youngs_modulus_pa = 0.0, own_peak_poisson_ratio = 0.0;
  double error_youngs = 0.0, error_poisson = 0.0, error_ucs = 0.0, error_tensile = 0.0;
  double predicted_ucs_pa = 0.0, predicted_tensile_strength_pa = 0.0;  // before it ran
  bool accepted = false;  // the best so far when it ran
  double seconds = 0.0;
  std::string correction;  // how the next round was chosen
  // A test of the round failed (diverged, no peak, or the solver refused the point): the
  // strengths and their errors are not measured; `failure` names the test and the reason.
  bool failed = false;
  std::string failure;
};

struct CalibrationSummary {
  int dimension = 2;
  TargetMaterial target;
  std::string model_requested, model_used, model_reason;
  PackingDescriptors ucs_descriptors, bts_descriptors;
  // Maps.
  std::string maps_path;  // file used (stored or given); empty if not stored
  bool maps_reused = false;
  StoredMaps maps;
  int stored_measurements = 0;                  // on this specimen, correcting the surfaces
  double admissible_particle_compliance = 0.0;  // kn/(Ep l) at rho(B) = max, at nu_p (DDEM)
  double sweep_seconds = 0.0;                   // this run (0 when reused), anchors included
  // Reach of each model assessed (calibration_solver.h); the chosen one in `solution`.
  CalibrationReach rigid_reach, deformable_reach;
  // The reach of the model used as it was assessed before the first strength round (the
  // two above end as the strength stage left them: a ratio can be given up on measurement).
  CalibrationReach reach_before_rounds;
  // The calibration loop: elastic runs, strength rounds, transfer errors, notes.
  CalibrationSolution solution;
  std::vector<VerificationRound> rounds;  // the strength rounds, failed ones included
  int best_round = 0;                     // 1-based; 0 when every round failed (no result)
  MaterialParameters material;  // the final set (density before scaling)
  bool converged = false;       // every honoured target within tolerance
  bool tensile_honoured = true; // false when sigma_c / sigma_t is out of reach
  bool gave_up = false;         // a property was given up (out of reach): exit status 4
  // Stability of the final set on the UCS specimen; not judged (no final set, or not on this
  // rank): the verdict says so, the message why, and the numbers are not reported.
  bool stability_judged = false;
  std::string stability_verdict, stability_binding_limit, stability_message;
  double stability_margin_percent = 0.0;
  double critical_time_step_s = 0.0, time_step_s = 0.0, spectral_radius = 0.0;
  // The tests of the best round (for the outputs). With several ranks (common/ranks.h) the
  // Brazilian test ran on rank 1, which holds it and writes its outputs (final_bts_rank).
  LabTestResult final_ucs, final_bts;
  int final_bts_rank = 0;
  std::vector<std::string> notes;
  double seconds = 0.0;

  std::string BriefReport() const;
  std::string FullReport() const;
  nlohmann::json ToJson() const;
};

// Runs the calibration. InputError for invalid options or target, or maps that do not
// match the packing; FileError when the maps cannot be read or written; ComputationError
// when the sweep fails everywhere or an elastic run before the strength rounds fails. A
// strength round whose test fails (diverges) is a failed round of the summary: the loop goes
// on, and with no round measured there is no result (best_round 0, not converged).
template <int Dim>
CalibrationSummary CalibrateToMaterial(const CalibrationSpecimens<Dim>& specimens,
                                       const TargetMaterial& target, const CalibrationOptions& options);

}  // namespace specimen
