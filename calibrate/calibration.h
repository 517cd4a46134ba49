#pragma once
// calibrate-to-material (issue 6): contact parameters kn, kt, Rn, Rt, mu (and Ep, nu_p of
// deformable particles) that make the virtual UCS and Brazilian tests reproduce a target
// E, nu, UCS and tensile strength, within the DDEM convergence bound, verified by running
// the tests. Options in, CalibrationSummary out (BriefReport, FullReport, ToJson):
//
//   CalibrationSpecimens<2> specimens = MakeCalibrationSpecimens<2>(SpecimenPlan<2>());
//   CalibrationOptions options;            // automatic model, maps under data/maps
//   CalibrationSummary summary = CalibrateToMaterial<2>(specimens, target, options);
//   std::cout << summary.FullReport();     // target, achieved, error, parameters, verdict
//
// The steps (Labra 2012 chapter 4; Madan 2019 section 4):
// 1. Maps (map_sweep.h, map_store.h): UCS and BTS at the points of a grid of micro ratios on
//    smaller specimens statistically equivalent to the real ones (same generator, same mean
//    radius), reduced to the dimensionless groups and fitted by smooth surfaces; reused from
//    the map directory when a map of the same design and protocol exists for an equivalent
//    packing. Rigid maps first; the automatic model adds deformable (DDEM) maps when the
//    target nu lies beyond what rigid particles reach on this packing.
// 2. Inversion (inversion.h): the ratios that match nu and sigma_c / sigma_t, within the
//    maps' box and the bound rho(B) <= max_spectral_radius (stability_analysis.h); kn and
//    Rn from the groups of the real specimens.
// 3. Verification: UCS and BTS on the real specimens (in parallel); while an error exceeds
//    its tolerance and rounds remain, correct: kn by E* / E, Rn by the honoured strength
//    (E ~ kn and strengths ~ Rn exactly at fixed ratios), kt/kn by the maps' slope of nu,
//    each scaled by the maps' change of the group the ratio change causes; when both
//    strengths are honoured, Rt/Rn by sigma_c / sigma_t, and once Rt/Rn cannot move that
//    ratio any more (the end of the maps' box), sigma_t is no longer honoured and the report
//    says why (the small map specimens can promise a ratio the real one does not give). The first round's
//    deviation from the maps' prediction is the transfer error of the smaller sweep specimens.
//    E and nu are the secants over the window x the target UCS (the stresses at which the
//    rock's were measured), not x the specimen's own, path-dependent peak (VerificationRound).
// 4. Stability verdict of the final set (time step and rho(B)) on the real UCS specimen.

#include <optional>
#include <utility>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "calibrate/dimensionless_groups.h"
#include "calibrate/inversion.h"
#include "calibrate/map_store.h"
#include "calibrate/map_sweep.h"
#include "calibrate/target_material.h"
#include "common/progress.h"
#include "generator/packing.h"
#include "solver/lab_test.h"
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
  double particle_poisson_ratio = 0.45;  // nu_p of the deformable maps, in (-1, 0.5)
  double friction_coefficient = 0.8;     // mu (Labra's verification value), >= 0
  int workers = 0;                       // sweep points at once; 0 = hardware threads

  // --- Protocol of every test (kind, progress set per test). Density scaling is on. ---
  LabTestOptions test;

  // --- Bounds and verification ---
  double max_spectral_radius = 0.9;  // rho(B) of the DDEM iteration, in (0, 1)
  HonouredStrength honour = HonouredStrength::kCompressive;  // when sigma_c/sigma_t is unreachable
  // Tolerances (relative, in (0, 1)) sit below the acceptance (E, nu 2 %, UCS 3 %)
  // so that a converged set meets it with a margin.
  int max_verification_rounds = 6;   // runs of UCS + BTS, 1 to 20
  double tolerance_youngs = 0.015;
  double tolerance_poisson = 0.015;
  double tolerance_ucs = 0.02;
  double tolerance_tensile = 0.05;
  ProgressCallback progress;

  CalibrationOptions();
  bool IsValid(std::string* error) const;
};

// One verification run of UCS and BTS.
struct VerificationRound {
  int round = 0;
  MaterialParameters material;
  MicroRatios ratios;
  // E and nu over the secant window x the target UCS (window_at_target; else x this
  // specimen's peak, when it failed below the window's end), the figures the errors and
  // corrections use; the own-peak figures are Labra's definition, reported beside them.
  double youngs_modulus_pa = 0.0, poisson_ratio = 0.0, ucs_pa = 0.0, tensile_strength_pa = 0.0;
  bool window_at_target = false;
  double own_peak_youngs_modulus_pa = 0.0, own_peak_poisson_ratio = 0.0;
  double error_youngs = 0.0, error_poisson = 0.0, error_ucs = 0.0, error_tensile = 0.0;
  bool ucs_peak_reached = false, bts_peak_reached = false;
  double seconds = 0.0;
  std::string correction;  // what the next round changed
};

// What the maps of one model reach on this packing.
struct ModelReach {
  bool built = false;
  double poisson_min = 0.0, poisson_max = 0.0;  // over the surface in the box (within the bound)
  double poisson_max_measured = 0.0;            // the largest nu of a sweep point
  double strength_ratio_max = 0.0;              // largest sigma_c / sigma_t of the surfaces
  double strength_ratio_max_measured = 0.0;
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
  ModelReach rigid_reach, deformable_reach;
  double admissible_particle_compliance = 0.0;  // kn/(Ep l) at rho(B) = max, at nu_p (DDEM)
  double sweep_seconds = 0.0;                   // this run (0 when reused)
  // Inversion and verification.
  InversionResult inversion;
  std::vector<VerificationRound> rounds;
  // The verification started from one stored with the maps (map_store.h VerifiedPoint).
  bool transfer_corrected = false;
  // Relative deviation of the first verification round from the maps' prediction.
  double transfer_error_youngs = 0.0, transfer_error_poisson = 0.0;
  double transfer_error_ucs = 0.0, transfer_error_tensile = 0.0;
  MaterialParameters material;  // the final set (density before scaling)
  bool converged = false;       // every honoured target within tolerance
  bool tensile_honoured = true; // false when sigma_c / sigma_t is unreachable
  // Stability of the final set on the UCS specimen.
  std::string stability_verdict, stability_binding_limit, stability_message;
  double stability_margin_percent = 0.0;
  double critical_time_step_s = 0.0, time_step_s = 0.0, spectral_radius = 0.0;
  // The final verification tests (for the outputs).
  LabTestResult final_ucs, final_bts;
  std::vector<std::string> notes;
  double seconds = 0.0;

  std::string BriefReport() const;
  std::string FullReport() const;
  nlohmann::json ToJson() const;
};

// Runs the calibration. InputError for invalid options or target, or maps that do not
// match the packing; FileError when the maps cannot be read or written; ComputationError
// when the sweep fails everywhere or a verification test diverges.
template <int Dim>
CalibrationSummary CalibrateToMaterial(const CalibrationSpecimens<Dim>& specimens,
                                       const TargetMaterial& target, const CalibrationOptions& options);

}  // namespace specimen
