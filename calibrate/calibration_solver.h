#pragma once
// The calibration as an inverse problem on the real specimens, in three stages. Every
// measurement is a sample of the true micro-macro map; the maps (surrogate.h) only propose
// where to measure next.
//
// 1. Reach. The elastic constants of the intact specimen at the corners of the maps' box
//    (rigid: kt/kn at both ends; DDEM: also kn/(Ep l) at its bound) give the interval of nu
//    this packing reaches, measured, not fitted. The corrected strength surfaces give the
//    interval of sigma_c / sigma_t reachable together with the target nu. A target outside
//    is reported with the reachable intervals, the nearest reachable point and the property
//    given up, before any strength test runs.
// 2. Elastic stage. E and nu are those of the intact specimen (the ISRM average modulus of
//    the linear portion), so they depend on kn, kt/kn (and kn/(Ep l)) only and the strengths
//    cannot disturb them. nu is a function of one ratio at a time (rigid: kt/kn; DDEM:
//    kn/(Ep l) at the kt/kn the strength ratio wants, then kt/kn at the bound), solved by a
//    model-based secant: the corrected surface plus the piecewise linear correction through
//    the runs on that line, safeguarded by the bracket the runs establish. E is exactly
//    proportional to kn at fixed ratios, so kn follows in one step. Each run is an elastic
//    test of a few thousand steps, 2-5 % of a strength test.
// 3. Strength stage. With the elastic set fixed, sigma_c and sigma_t are Rn times functions
//    of Rt/Rn alone. Each round runs the UCS and Brazilian tests; the line correction through
//    the rounds so far corrects the surfaces (output space mapping), and the next Rt/Rn solves
//    the corrected ratio sigma_c / sigma_t = target inside a trust region about the best round
//    so far (between two rounds that bracket the target ratio, their secant, bent into a
//    parabola by a third round); Rn then follows from the corrected groups. A round is
//    accepted only if its weighted error (errors over their tolerances, squared) falls below
//    the best. The region of Rt/Rn grows when a round's ratio came nearer the target than
//    any before and otherwise shrinks to half the step, so no ratio swings across its box.
//    A round whose test fails (diverges) is rejected like a worse one, and its point is a hole
//    the later rounds keep out of; the stage goes on with its budget. The result is the best
//    round, not the last.
//
//   CalibrationSolver solver(surrogate, target, options, &forward_model);
//   const CalibrationReach& reach = solver.AssessReach();   // a few elastic runs
//   CalibrationSolution solution = solver.Solve();

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "calibrate/forward_model.h"
#include "calibrate/surrogate.h"
#include "calibrate/target_material.h"
#include "common/progress.h"

namespace specimen {

struct CalibrationSolverOptions {
  // Tolerances, relative, in (0, 1): E and nu are held to them by the elastic stage, the
  // strengths by the strength rounds (the tensile strength only while sigma_c / sigma_t is
  // reachable).
  double tolerance_youngs = 0.015;
  double tolerance_poisson = 0.015;
  double tolerance_ucs = 0.02;
  double tolerance_tensile = 0.05;
  // The elastic stage aims at this share of the E and nu tolerances (its runs repeat within
  // about 0.1 %), in (0, 1].
  double elastic_tolerance_share = 1.0 / 3.0;
  int max_elastic_runs = 12;    // elastic runs in all, reach included, >= 4
  int max_strength_rounds = 6;  // UCS + Brazilian rounds, >= 1
  // The strength kept when sigma_c / sigma_t is out of reach.
  HonouredStrength honour = HonouredStrength::kCompressive;
  // DDEM maps: the largest kn/(Ep l) the convergence bound rho(B) admits on the real
  // specimens, > 0 (the maps' box is cut to it); rigid maps: 0.
  double admissible_particle_compliance = 0.0;
  ProgressCallback progress;  // may be empty

  bool IsValid(std::string* error) const;
};

// One point of the reach region: the elastic ratios, the nu they give and the interval of
// sigma_c / sigma_t over Rt/Rn in the box.
struct ReachSample {
  double stiffness_ratio = 0.0;      // kt/kn
  double particle_compliance = 0.0;  // kn/(Ep l), 0 = rigid
  double poisson_ratio = 0.0;
  double strength_ratio_min = 0.0, strength_ratio_max = 0.0;
};

struct CalibrationReach {
  bool assessed = false;
  bool deformable = false;
  // nu measured at the corners of the box on the real UCS specimen.
  double poisson_min = 0.0, poisson_max = 0.0;
  bool poisson_reachable = false;
  // sigma_c / sigma_t over Rt/Rn at the elastic ratios that give the target nu (or the
  // nearest reachable nu), from the corrected surfaces; for DDEM the union over the kt/kn
  // that can give that nu within the bound.
  double strength_ratio_min = 0.0, strength_ratio_max = 0.0;
  bool strength_ratio_reachable = false;
  // Within the transfer uncertainty of the surfaces (their spread at the stored measurements,
  // or, with none stored, the transfer error measured for the default map specimens): the
  // strength rounds measure whether it is reached. False: declared out of reach now.
  bool strength_ratio_possible = false;
  double nearest_poisson = 0.0, nearest_strength_ratio = 0.0;
  // The elastic ratios the elastic stage starts from (and, for DDEM, keeps kt/kn of).
  MicroRatios start;
  std::vector<ReachSample> region;  // over the box, for the report's table and picture
  std::vector<std::string> given_up;  // "nu", "sigma_t" or "UCS"

  bool reachable() const { return poisson_reachable && strength_ratio_reachable; }
  // Out of reach before any strength round: nu outside the measured interval, or the ratio
  // outside the surfaces' reach by more than their transfer uncertainty.
  bool declared_out_of_reach() const { return !poisson_reachable || !strength_ratio_possible; }
  // How far the nearest reachable point lies from the target, in tolerances: the root of the
  // summed squares of (nearest nu / nu - 1) / tolerance_poisson and of ln(ratio / nearest
  // ratio) / ln(1 + tolerance_ratio). 0 inside the reach; the automatic model choice takes
  // the smaller.
  double Miss(const TargetMaterial& target, double tolerance_poisson, double tolerance_ratio) const;
  // Sentences for the report: the intervals, where the target lies, what is given up.
  std::string Describe(const TargetMaterial& target) const;
  nlohmann::json ToJson() const;
};

struct ElasticRun {
  std::string purpose;  // "reach", "nu", "E"
  ElasticQuery query;
  ElasticMeasurement measured;
};

struct StrengthRound {
  int round = 0;  // 1-based
  double normal_stiffness = 0.0, bond_tensile_strength = 0.0;
  MicroRatios ratios;
  // What the corrected surrogate predicted for this round before it ran.
  double predicted_ucs_pa = 0.0, predicted_tensile_strength_pa = 0.0;
  StrengthMeasurement measured;
  // The elastic set of this round as its elastic stage confirmed it (DDEM: a re-planned
  // kt/kn gives later rounds another one).
  double elastic_youngs_modulus_pa = 0.0, elastic_poisson_ratio = 0.0;
  int elastic_set = 0;  // 0 = the first elastic stage, 1 = the first re-plan, ...
  bool elastic_met = false;  // its E (and nu, unless nu was given up) within tolerance
  double error_ucs = 0.0, error_tensile = 0.0;  // relative to the target
  double weighted_error = 0.0;  // sum of (error / tolerance)^2 over the honoured strengths
  bool accepted = false;        // the best so far when it ran
  double trust_radius = 0.0;    // of Rt/Rn after this round
  std::string step;             // how the next round was chosen
  // A test of the round failed (ForwardModel::MeasureStrength threw ComputationError: a run
  // diverged, found no peak, or the solver refused the point): nothing measured, the round is
  // rejected and the later rounds keep out of its point. `failure` names the test and why.
  bool failed = false;
  std::string failure;
};

struct CalibrationSolution {
  CalibrationReach reach;
  std::vector<ElasticRun> elastic_runs;
  // The final elastic set: its ratios, kn and the run that confirmed it.
  ElasticRun elastic;
  double error_youngs = 0.0, error_poisson = 0.0;
  bool elastic_converged = false;
  std::vector<StrengthRound> rounds;  // in the order they ran, failed ones included
  int best_round = -1;  // index into rounds; -1 when every round failed (no result)
  bool tensile_honoured = true;
  int replans = 0;  // DDEM: elastic stages re-run at another kt/kn for the strength ratio
  bool converged = false;  // every honoured property within its tolerance
  // The result: the best round's set.
  double normal_stiffness = 0.0, bond_tensile_strength = 0.0;
  MicroRatios ratios;
  // Transfer error of the map specimens: the first measurements against the fitted surfaces
  // alone, and against the surrogate corrected by the stored measurements.
  double transfer_youngs = 0.0, transfer_poisson = 0.0, transfer_ucs = 0.0, transfer_tensile = 0.0;
  double corrected_error_ucs = 0.0, corrected_error_tensile = 0.0;
  std::vector<std::string> notes;
};

class CalibrationSolver {
 public:
  // InputError for invalid options or target. The model must outlive the solver.
  CalibrationSolver(CalibrationSurrogate surrogate, TargetMaterial target, CalibrationSolverOptions options,
                    ForwardModel* model);

  // Stage 1 (once; Solve calls it when not yet done).
  const CalibrationReach& AssessReach();
  // Stages 2 and 3.
  CalibrationSolution Solve();

  const CalibrationSurrogate& surrogate() const { return surrogate_; }

 private:
  struct ElasticSet {
    MicroRatios ratios;
    double normal_stiffness = 0.0;
    ElasticMeasurement confirmed;
    bool poisson_met = false;
  };
  ElasticSet ElasticStage(const MicroRatios& start);
  // DDEM: the kt/kn (with the kn/(Ep l) that gives nu) whose interval of sigma_c / sigma_t
  // holds the target with the largest margin; kt/kn within 5 % of the box of one in `avoid` is
  // not considered. ratio_min, ratio_max: the ratio's extremes over those considered.
  // False when no kt/kn can give nu.
  bool DeformableStart(double poisson, const std::vector<double>& avoid, MicroRatios* start, double* ratio_min,
                       double* ratio_max) const;
  double RatioUncertainty() const;
  ElasticMeasurement RunElastic(const MicroRatios& ratios, double kn, const std::string& purpose);
  std::vector<ElasticMeasurement> RunElastic(const std::vector<MicroRatios>& ratios, double kn,
                                             const std::string& purpose);
  double ReferenceStiffness(const MicroRatios& ratios) const;
  double StrengthRatioMin(const MicroRatios& elastic, double* at) const;
  double StrengthRatioMax(const MicroRatios& elastic, double* at) const;
  // The nu measured on the line through `through` along `axis` (this calibration's elastic
  // runs and the stored measurements), with their ratios.
  std::vector<std::pair<MicroRatios, double>> PoissonOnLine(const MicroRatios& through, MicroRatio axis) const;
  bool SolvePoissonAlong(MicroRatio axis, MicroRatios* ratios, double lower, double upper);
  void StrengthStage(ElasticSet set, CalibrationSolution* solution);
  double Progress(double share, const std::string& message) const;

  CalibrationSurrogate surrogate_;
  TargetMaterial target_;
  CalibrationSolverOptions options_;
  ForwardModel* model_;
  double compliance_upper_ = 0.0;  // kn/(Ep l) box cut to the admissible bound
  CalibrationReach reach_;
  std::vector<ElasticRun> runs_;
  double reference_kn_ = 0.0;
  MicroRatios base_;  // the maps' fixed ratios, mid-box elsewhere
};

}  // namespace specimen
