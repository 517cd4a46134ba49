// The calibration loop (calibrate/calibration_solver.h) on a cheap closed-form "rock": its
// true responses are known functions of the micro parameters, the maps are fitted to a biased
// copy of them (the transfer error of small map specimens: strengths +16 % / -23 %, a slope
// error in Rt/Rn, nu +0.02), and every "measurement" carries noise of the size measured on
// 5,000 discs (strengths 1 %, elastic constants 0.1 %). Twin targets are made by the true
// model at hidden parameters: the loop must find them within the default tolerances
// (docs/calibration.md, "Tolerances and noise") and a budget of rounds, reject steps that
// make things worse, never swing a ratio across its box, report what is out of reach before
// the first strength round, give up on measurement only (after probing beside the measured
// extreme of the ratio), follow a ratio that peaks inside the box, honour again what a round
// measured within reach, and cope with a budget of one round and with maps that lack Rt/Rn.
#include "calibrate/calibration_solver.h"
#include "calibrate/map_sweep.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <random>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "common/error.h"

namespace specimen {
namespace {

PackingDescriptors Specimen2D() {
  PackingDescriptors d;
  d.dimension = 2;
  d.particles = 5000;
  d.porosity = 0.094;
  d.coordination = 5.83;
  d.mean_radius = 3.77e-4;
  d.radius_ratio = 9.0;
  d.mean_radius_squared = 1.3e-7;
  d.mean_branch_length = 6.6e-4;
  d.mean_branch_length_squared = 4.6e-7;
  return d;
}

// The "true" responses of the real specimen (a plausible shape: nu falls with kt/kn as the
// Voigt estimate and rises with kn/(Ep l); sigma_c / sigma_t rises with Rt/Rn and kt/kn and
// saturates where tension controls).
// sigma_c peaks inside the kt/kn axis at large Rt/Rn, by exp(kt_peak L(kt/kn) M(Rt/Rn)), L
// the quadratic that is 1 at kt/kn 0.375 and 0 at 0.15 and 0.6, M the one that is 1 at Rt/Rn
// 10 and 0 at 2 and 6 (the DDEM sweep measured sigma_c / sigma_t 13.1, 19.7, 11.5 at kt/kn
// 0.15, 0.375, 0.6 and Rt/Rn 10: a product a surface of total degree 2 cannot follow); 0: none.
double kt_peak = 0.0;
double PeakInStiffnessRatio(const MicroRatios& r) {
  const double s = r.tangential_to_normal_stiffness, x = r.shear_to_tensile_strength;
  const double l = (s - 0.15) * (s - 0.6) / ((0.375 - 0.15) * (0.375 - 0.6)), m = (x - 2.0) * (x - 6.0) / (8.0 * 4.0);
  return std::exp(kt_peak * l * m);
}

struct Rock {
  static double Poisson(const MicroRatios& r) {
    const double s = r.tangential_to_normal_stiffness;
    return (1.0 - s) / (4.0 + s) + 0.25 * r.normal_stiffness_to_particle;
  }
  static double YoungsPerStiffness(const MicroRatios& r) {
    const double s = r.tangential_to_normal_stiffness;
    return 1.3 * (1.0 + s) / (1.0 + 0.3 * s) * (1.0 - 0.6 * r.normal_stiffness_to_particle);
  }
  static double UcsPerStrength(const MicroRatios& r) {  // [Pa/N]
    const double s = r.tangential_to_normal_stiffness, x = r.shear_to_tensile_strength;
    return 2.0e4 * (0.4 + s) * (1.0 - std::exp(-x / 3.0)) * (1.0 + 0.3 * r.normal_stiffness_to_particle) *
           PeakInStiffnessRatio(r);
  }
  static double TensilePerStrength(const MicroRatios& r) {
    const double s = r.tangential_to_normal_stiffness, x = r.shear_to_tensile_strength;
    return 2.0e3 * (0.5 + 0.2 * s) * (1.0 - 0.5 * std::exp(-x / 1.5));
  }
};

// What the map specimens measure instead: biased, and with a wrong trend in Rt/Rn (the UCS
// slope off by `trend` per unit of Rt/Rn).
double trend = 0.015;
struct MapRock {
  static double Poisson(const MicroRatios& r) { return Rock::Poisson(r) + 0.02; }
  static double YoungsPerStiffness(const MicroRatios& r) { return 1.04 * Rock::YoungsPerStiffness(r); }
  static double UcsPerStrength(const MicroRatios& r) {
    return 1.16 * (1.0 + trend * (r.shear_to_tensile_strength - 6.0)) * Rock::UcsPerStrength(r);
  }
  static double TensilePerStrength(const MicroRatios& r) { return 0.77 * Rock::TensilePerStrength(r); }
};

std::vector<double> Linspace(double a, double b, int n) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(a + (b - a) * i / (n - 1));
  return v;
}

// Maps fitted (degree 2, the strength groups in logarithms, as the product's FitMaps) to MapRock on a full factorial grid, in
// group form (dimensionless_groups.h) on the descriptors of the real specimens.
MapSet FitMapsOf(bool deformable, double compliance_upper) {
  const PackingDescriptors d = Specimen2D();
  const double youngs = d.SolidCoordination() / d.CharacteristicRadius();
  const double strength = d.SolidCoordination() / d.CharacteristicArea();
  MapSet maps;
  maps.fixed.friction_coefficient = 0.8;
  maps.fixed.particle_poisson_ratio = deformable ? 0.45 : 0.0;
  std::vector<std::vector<double>> axes = {Linspace(0.15, 0.9, 4), Linspace(2.0, 10.0, 3)};
  maps.inputs = {MicroRatio::kStiffnessRatio, MicroRatio::kStrengthRatio};
  if (deformable) {
    axes = {Linspace(0.15, 0.6, 3), Linspace(0.0, compliance_upper, 3), Linspace(2.0, 10.0, 3)};
    maps.inputs = {MicroRatio::kStiffnessRatio, MicroRatio::kParticleCompliance, MicroRatio::kStrengthRatio};
  }
  std::vector<std::vector<double>> points(1);
  for (const auto& axis : axes) {
    std::vector<std::vector<double>> next;
    for (const auto& p : points)
      for (double v : axis) next.push_back(p), next.back().push_back(v);
    points = next;
  }
  Eigen::MatrixXd x(points.size(), axes.size()), x_elastic(points.size(), axes.size());
  Eigen::VectorXd nu(points.size()), pe(points.size()), pc(points.size()), pt(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const MicroRatios r = maps.RatiosAt(points[i]);
    for (size_t k = 0; k < axes.size(); ++k) {
      x(i, k) = points[i][k];
      x_elastic(i, k) = maps.inputs[k] == MicroRatio::kStrengthRatio ? 2.0 : points[i][k];
    }
    nu[i] = MapRock::Poisson(r);
    pe[i] = MapRock::YoungsPerStiffness(r) / youngs;
    pc[i] = MapRock::UcsPerStrength(r) / strength;
    pt[i] = MapRock::TensilePerStrength(r) / strength;
  }
  ResponseSurfaceOptions fit;
  fit.max_total_degree = 2;
  maps.poisson_ratio = ResponseSurface::Fit(x_elastic, nu, fit);
  maps.elastic_group = ResponseSurface::Fit(x_elastic, pe, fit);
  fit.log_values = true;  // the strength groups, as FitMaps fits them
  maps.compressive_group = ResponseSurface::Fit(x, pc, fit);
  maps.tensile_group = ResponseSurface::Fit(x, pt, fit);
  return maps;
}

class FakeModel : public ForwardModel {
 public:
  explicit FakeModel(unsigned seed, double strength_noise = 0.01, double elastic_noise = 0.001)
      : random_(seed), strength_noise_(strength_noise), elastic_noise_(elastic_noise) {}
  std::vector<ElasticMeasurement> MeasureElastic(const std::vector<ElasticQuery>& queries) override {
    std::vector<ElasticMeasurement> out;
    for (const ElasticQuery& q : queries) {
      ++elastic_runs;
      ElasticMeasurement m;
      m.youngs_modulus_pa = q.normal_stiffness * Rock::YoungsPerStiffness(q.ratios) * Noise(elastic_noise_);
      m.poisson_ratio = Rock::Poisson(q.ratios) * Noise(elastic_noise_);
      out.push_back(m);
    }
    return out;
  }
  StrengthMeasurement MeasureStrength(double kn, double rn, const MicroRatios& r) override {
    ++strength_rounds;
    if (diverges && diverges(strength_rounds, rn, r)) {
      ++diverged_rounds;
      throw ComputationError("UCS test: the run diverged at step 184,886: a wall reaction became NaN.");
    }
    if (repeatable) {  // the same point, the same draw: a seed from the inputs' bits
      std::uint64_t h = 1469598103934665603ULL;
      for (double v : {rn, r.shear_to_tensile_strength, r.tangential_to_normal_stiffness}) {
        std::uint64_t bits;
        std::memcpy(&bits, &v, sizeof bits);
        h = (h ^ bits) * 1099511628211ULL;
      }
      random_.seed(static_cast<std::mt19937::result_type>(h ^ (h >> 32)));
    }
    StrengthMeasurement m;
    const double ucs_per_strength = ucs_override ? ucs_override(r) : Rock::UcsPerStrength(r) * Steeper(r);
    m.ucs_pa = UcsScale(rn) * ucs_per_strength * Noise(strength_noise_);
    m.tensile_strength_pa = rn * Rock::TensilePerStrength(r) * Noise(strength_noise_);
    m.linear_youngs_modulus_pa = kn * Rock::YoungsPerStiffness(r);
    m.linear_poisson_ratio = Rock::Poisson(r);
    return m;
  }
  int elastic_runs = 0, strength_rounds = 0, diverged_rounds = 0;
  // The strength noise as a real specimen's path noise: a function of the inputs (a
  // deterministic run measures the same peak at the same point), else a fresh draw per call.
  bool repeatable = false;
  // Where a strength round's test diverges (the forward model throws ComputationError): by the
  // count of the round (1-based), Rn and the ratios. Empty: nowhere.
  std::function<bool(int, double, const MicroRatios&)> diverges;
  // sigma_c grows as Rn^beta about Rn 5e3 N (1: proportional; real specimens at high Rt/Rn
  // show less, since their strengths also depend on Rn / (kn r)).
  double ucs_strength_exponent = 1.0;
  double UcsScale(double rn) const { return 5e3 * std::pow(rn / 5e3, ucs_strength_exponent); }
  // sigma_c of the real specimen rises faster with Rt/Rn than the maps say, as (Rt/Rn / 5)^g.
  double ratio_steepening = 0.0;
  // ... or rises steeply and saturates, as (1 - exp(-(Rt/Rn) / s)) / (1 - exp(-5 / s)), s > 0:
  // concave in logarithms, as tension takes over (s 1.5: a DDEM twin of the default specimen).
  double ratio_saturation = 0.0;
  // ... or peaks at Rt/Rn = ratio_peak > 0 and falls beyond it, as (Rt/Rn)^-0.1: a rigid
  // twin of the default specimen measured 17.6 at Rt/Rn 4.5, 16.2 and 15.9 at 9.7 and 10.
  double ratio_peak = 0.0;
  // The real specimen's sigma_c per Rn [Pa/N] in place of all the above (empty: not used).
  std::function<double(const MicroRatios&)> ucs_override;
  double Steeper(const MicroRatios& r) const {
    const double x = r.shear_to_tensile_strength;
    const double saturating =
        ratio_saturation > 0.0 ? (1.0 - std::exp(-x / ratio_saturation)) / (1.0 - std::exp(-5.0 / ratio_saturation))
                               : 1.0;
    const double p = ratio_peak;
    const double falling =
        p > 0.0 && x > p ? (1.0 - std::exp(-p / 3.0)) / (1.0 - std::exp(-x / 3.0)) * std::pow(x / p, -0.1) : 1.0;
    return std::pow(x / 5.0, ratio_steepening) * saturating * falling;
  }

 private:
  double Noise(double relative) { return 1.0 + relative * std::normal_distribution<double>()(random_); }
  std::mt19937 random_;
  double strength_noise_, elastic_noise_;
};

// A twin target: the true model at hidden parameters (noise-free).
TargetMaterial Twin(double kn, double rn, const MicroRatios& r) {
  TargetMaterial t;
  t.name = "twin";
  t.youngs_modulus_pa = kn * Rock::YoungsPerStiffness(r);
  t.poisson_ratio = Rock::Poisson(r);
  t.ucs_pa = rn * Rock::UcsPerStrength(r);
  t.tensile_strength_pa = rn * Rock::TensilePerStrength(r);
  t.density_kg_per_m3 = 2600.0;
  return t;
}

SweepDesign DesignOf(bool deformable, double compliance_upper) {
  SweepDesign d;
  d.fixed.friction_coefficient = 0.8;
  d.axes = {{MicroRatio::kStiffnessRatio, 0.15, 0.9, 4}, {MicroRatio::kStrengthRatio, 2.0, 10.0, 3}};
  if (deformable) {
    d.fixed.particle_poisson_ratio = 0.45;
    d.axes = {{MicroRatio::kStiffnessRatio, 0.15, 0.6, 3},
              {MicroRatio::kParticleCompliance, 0.0, compliance_upper, 3},
              {MicroRatio::kStrengthRatio, 2.0, 10.0, 3}};
  }
  return d;
}

// The surrogate of FitMapsOf with the transfer anchors of the design measured on the real
// specimen (by the true model, with the strength noise of a real test), as the maps store them.
CalibrationSurrogate Anchored(bool deformable, double compliance_upper, unsigned seed) {
  CalibrationSurrogate s(FitMapsOf(deformable, compliance_upper), Specimen2D(), Specimen2D());
  std::mt19937 random(seed);
  auto noise = [&] { return 1.0 + 0.01 * std::normal_distribution<double>()(random); };
  for (const MicroRatios& r : TransferAnchorPoints(DesignOf(deformable, compliance_upper))) {
    SurrogateMeasurement m;
    m.ratios = r;
    m.youngs_per_stiffness = Rock::YoungsPerStiffness(r);
    m.poisson_ratio = Rock::Poisson(r);
    m.ucs_per_strength = Rock::UcsPerStrength(r) * noise();
    m.tensile_per_strength = Rock::TensilePerStrength(r) * noise();
    s.AddMeasurement(m, /*stored=*/true);
  }
  return s;
}

MicroRatios Rigid(double s, double x) {
  MicroRatios r;
  r.tangential_to_normal_stiffness = s;
  r.shear_to_tensile_strength = x;
  r.friction_coefficient = 0.8;
  return r;
}

// FitMapsOf's rigid maps with a strength surface refitted (on the same 4 x 3 grid, in
// logarithms, of total degree `degree`) to a given response [Pa/N]; an empty one is kept.
using Response = std::function<double(const MicroRatios&)>;
MapSet RigidMapsWithStrengths(const Response& ucs, const Response& tensile, int degree = 2) {
  MapSet maps = FitMapsOf(false, 0.0);
  const PackingDescriptors d = Specimen2D();
  const double strength = d.SolidCoordination() / d.CharacteristicArea();
  Eigen::MatrixXd x(12, 2);
  Eigen::VectorXd pc(12), pt(12);
  int i = 0;
  for (double s : Linspace(0.15, 0.9, 4))
    for (double b : Linspace(2.0, 10.0, 3)) {
      x(i, 0) = s, x(i, 1) = b;
      pc[i] = ucs ? ucs(Rigid(s, b)) / strength : 1.0;
      pt[i++] = tensile ? tensile(Rigid(s, b)) / strength : 1.0;
    }
  ResponseSurfaceOptions fit;
  fit.max_total_degree = degree;
  fit.log_values = true;
  if (ucs) maps.compressive_group = ResponseSurface::Fit(x, pc, fit);
  if (tensile) maps.tensile_group = ResponseSurface::Fit(x, pt, fit);
  return maps;
}

CalibrationSolverOptions Options(double compliance = 0.0) {
  CalibrationSolverOptions o;
  o.max_strength_rounds = 6;
  o.admissible_particle_compliance = compliance;
  return o;
}

// The rounds as text, for failure messages.
std::string Rounds(const CalibrationSolution& s) {
  std::string text;
  char line[300];
  for (const ElasticRun& r : s.elastic_runs) {
    std::snprintf(line, sizeof(line), "  elastic %s: kt/kn %.4f c %.4f kn %.4g -> E %.4g nu %.5f\n", r.purpose.c_str(),
                  r.query.ratios.tangential_to_normal_stiffness, r.query.ratios.normal_stiffness_to_particle,
                  r.query.normal_stiffness, r.measured.youngs_modulus_pa, r.measured.poisson_ratio);
    text += line;
  }
  for (const StrengthRound& r : s.rounds) {
    if (r.failed) {
      std::snprintf(line, sizeof(line), "  round %d FAILED: Rt/Rn %.4f Rn %.5g trust %.3g | %s | %s\n", r.round,
                    r.ratios.shear_to_tensile_strength, r.bond_tensile_strength, r.trust_radius, r.failure.c_str(),
                    r.step.c_str());
      text += line;
      continue;
    }
    std::snprintf(line, sizeof(line),
                  "  round %d: Rt/Rn %.4f Rn %.5g predicted %.4g / %.4g errors %+.4f %+.4f W %.3f %s trust %.3g | %s\n",
                  r.round, r.ratios.shear_to_tensile_strength, r.bond_tensile_strength, r.predicted_ucs_pa,
                  r.predicted_tensile_strength_pa, r.error_ucs, r.error_tensile, r.weighted_error,
                  r.accepted ? "accepted" : "rejected", r.trust_radius, r.step.c_str());
    text += line;
  }
  for (const std::string& n : s.notes) text += "  note: " + n + "\n";
  return text;
}

// sigma_c / sigma_t grows with Rt/Rn: while every round of an elastic set measured the ratio on
// one side of the target, no round steps back past them.
void ExpectNoStepAgainstTheRounds(const CalibrationSolution& s, double target_ratio) {
  for (size_t k = 1; k < s.rounds.size(); ++k) {
    bool all_above = true, all_below = true, any = false;
    double smallest = 1e300, largest = -1e300;
    for (size_t j = 0; j < k; ++j) {
      const StrengthRound& r = s.rounds[j];
      if (r.elastic_set != s.rounds[k].elastic_set || r.failed) continue;  // a failed round measured nothing
      any = true;
      const double ratio = r.measured.ucs_pa / r.measured.tensile_strength_pa;
      all_above = all_above && ratio > target_ratio;
      all_below = all_below && ratio < target_ratio;
      smallest = std::min(smallest, r.ratios.shear_to_tensile_strength);
      largest = std::max(largest, r.ratios.shear_to_tensile_strength);
    }
    const double x = s.rounds[k].ratios.shear_to_tensile_strength;
    if (any && all_above) {
      EXPECT_LE(x, smallest * (1.0 + 1e-9)) << "round " << k + 1;
    }
    if (any && all_below) {
      EXPECT_GE(x, largest * (1.0 - 1e-9)) << "round " << k + 1;
    }
  }
}

void ExpectConverged(const CalibrationSolution& s, const CalibrationSolverOptions& o, int max_rounds) {
  SCOPED_TRACE(Rounds(s));
  EXPECT_TRUE(s.converged);
  EXPECT_TRUE(s.reach.reachable());
  EXPECT_LE(static_cast<int>(s.rounds.size()), max_rounds);
  EXPECT_LE(std::abs(s.error_youngs), o.tolerance_youngs);
  EXPECT_LE(std::abs(s.error_poisson), o.tolerance_poisson);
  const StrengthRound& b = s.rounds[s.best_round];
  EXPECT_LE(std::abs(b.error_ucs), o.tolerance_ucs);
  EXPECT_LE(std::abs(b.error_tensile), o.tolerance_tensile);
}

// Twin targets across the rigid box, each from its own noise, on maps with their transfer
// anchors: all converge within 3 strength rounds, and the hidden parameters are recovered
// (kt/kn by nu to 0.1 % noise; kn, Rn to the tolerances).
TEST(CalibrationSolver, RigidTwinTargetsConvergeWithinThreeRounds) {
  const double hidden[][2] = {{0.2, 3.0}, {0.3, 8.0}, {0.5, 5.0}, {0.7, 2.5}, {0.85, 9.0}, {0.25, 6.0}};
  unsigned seed = 1;
  for (const auto& h : hidden) {
    SCOPED_TRACE("hidden kt/kn " + std::to_string(h[0]) + ", Rt/Rn " + std::to_string(h[1]));
    const MicroRatios truth = Rigid(h[0], h[1]);
    const TargetMaterial target = Twin(2e10, 5e3, truth);
    FakeModel model(seed++);
    CalibrationSolver solver(Anchored(false, 0.0, seed + 100), target, Options(), &model);
    const CalibrationReach& reach = solver.AssessReach();
    EXPECT_EQ(model.strength_rounds, 0);  // the reach costs no strength test
    EXPECT_TRUE(reach.reachable()) << reach.Describe(target);
    const CalibrationSolution s = solver.Solve();
    ExpectConverged(s, Options(), 3);
    ExpectNoStepAgainstTheRounds(s, target.StrengthRatio());
    EXPECT_NEAR(s.ratios.tangential_to_normal_stiffness, h[0], 0.02);
    EXPECT_NEAR(s.normal_stiffness / 2e10, 1.0, 0.02);
    EXPECT_NEAR(s.bond_tensile_strength / 5e3, 1.0, 0.06);
    EXPECT_LE(model.elastic_runs, 10);
    // The transfer error is the first round against the fitted surfaces alone (their bias and
    // fit error), within the strength noise.
    const MicroRatios& first = s.rounds[0].ratios;
    EXPECT_NEAR(s.transfer_ucs, Rock::UcsPerStrength(first) / solver.surrogate().MapUcsPerStrength(first) - 1.0, 0.03);
    EXPECT_NEAR(s.transfer_tensile,
                Rock::TensilePerStrength(first) / solver.surrogate().MapTensilePerStrength(first) - 1.0, 0.03);
  }
}

// Where sigma_c grows less than in proportion to Rn (as Rn^0.45, while the anchors were
// measured at half the hidden Rn, so every map and anchor is 32 % high on the UCS), the loop
// still converges, in one round more; in proportion, within three.
TEST(CalibrationSolver, StrengthsNotProportionalToRnConverge) {
  const double hidden[][2] = {{0.22, 8.8}, {0.45, 9.0}, {0.3, 6.0}, {0.6, 4.0}};
  unsigned seed = 41;
  for (const auto& h : hidden) {
    SCOPED_TRACE("hidden kt/kn " + std::to_string(h[0]) + ", Rt/Rn " + std::to_string(h[1]));
    for (double beta : {0.45, 1.0}) {
      SCOPED_TRACE("beta " + std::to_string(beta));
      FakeModel model(seed++);
      model.ucs_strength_exponent = beta;
      TargetMaterial target = Twin(2e10, 1e4, Rigid(h[0], h[1]));
      target.ucs_pa = model.UcsScale(1e4) * Rock::UcsPerStrength(Rigid(h[0], h[1]));
      CalibrationSolver solver(Anchored(false, 0.0, seed + 100), target, Options(), &model);
      const CalibrationSolution s = solver.Solve();
      ExpectConverged(s, Options(), beta == 1.0 ? 3 : 4);
      ExpectNoStepAgainstTheRounds(s, target.StrengthRatio());
    }
  }
}

// A real specimen's sigma_c / sigma_t can rise with Rt/Rn much faster than the maps say
// (concrete C50/60 on the default specimen: 8.9 at Rt/Rn 1, 17.2 at 3.8, where the maps had
// 12.7 at 3.8). The first correction then overshoots to the end of the box; the two rounds
// bracket the target ratio, and the secant of the measurements between them (not the
// surfaces, which can be far off there) finds it: within four rounds.
TEST(CalibrationSolver, ASteeperRatioThanTheMapsIsFoundBetweenTheBracketingRounds) {
  const double hidden[][2] = {{0.3, 7.0}, {0.5, 4.0}, {0.25, 6.0}, {0.4, 8.5}};
  unsigned seed = 71;
  for (const auto& h : hidden) {
    SCOPED_TRACE("hidden kt/kn " + std::to_string(h[0]) + ", Rt/Rn " + std::to_string(h[1]));
    FakeModel model(seed++);
    model.ratio_steepening = 0.6;
    TargetMaterial target = Twin(2e10, 5e3, Rigid(h[0], h[1]));
    target.ucs_pa *= model.Steeper(Rigid(h[0], h[1]));
    // Maps without anchors: every correction comes from the rounds.
    CalibrationSolver solver(CalibrationSurrogate(FitMapsOf(false, 0.0), Specimen2D(), Specimen2D()), target,
                             Options(), &model);
    const CalibrationSolution s = solver.Solve();
    ExpectConverged(s, Options(), 4);
    ExpectNoStepAgainstTheRounds(s, target.StrengthRatio());
  }
}

// A ratio that rises steeply at small Rt/Rn and saturates (concave in logarithms) where the maps
// have it nearly flat, as a DDEM twin of the default specimen measured: the secant from the
// bracket's far end steps short (round 3 misses by up to 8 % in the ratio), yet the loop still
// converges within five rounds. (A convergence test of this shape, not of the parabola alone:
// on these targets the rounds come out the same without it.)
TEST(CalibrationSolver, ASaturatingRatioConvergesFromTheBracket) {
  const double hidden[][2] = {{0.3, 3.3}, {0.5, 2.5}, {0.25, 4.0}, {0.4, 3.0}, {0.6, 3.5}, {0.45, 2.8}};
  unsigned seed = 91;
  for (const auto& h : hidden) {
    SCOPED_TRACE("hidden kt/kn " + std::to_string(h[0]) + ", Rt/Rn " + std::to_string(h[1]));
    FakeModel model(seed++);
    model.ratio_saturation = 1.5;
    TargetMaterial target = Twin(2e10, 5e3, Rigid(h[0], h[1]));
    target.ucs_pa *= model.Steeper(Rigid(h[0], h[1]));
    CalibrationSolver solver(CalibrationSurrogate(FitMapsOf(false, 0.0), Specimen2D(), Specimen2D()), target,
                             Options(), &model);
    const CalibrationSolution s = solver.Solve();
    ExpectConverged(s, Options(), 5);
    ExpectNoStepAgainstTheRounds(s, target.StrengthRatio());
  }
}

// Maps whose ratio falls with Rt/Rn where the specimen's rises (a wrong trend, as surfaces bent
// at the box end): once the rounds all lie above the target ratio, the next one goes below
// them, never back up where the surfaces point.
TEST(CalibrationSolver, RoundsOnOneSideOfTheTargetBoundTheNextStep) {
  const double saved_trend = trend;
  trend = -0.2;
  const double hidden[][2] = {{0.3, 2.5}, {0.5, 3.0}, {0.25, 2.2}, {0.4, 4.0}};
  unsigned seed = 131;
  for (const auto& h : hidden) {
    SCOPED_TRACE("hidden kt/kn " + std::to_string(h[0]) + ", Rt/Rn " + std::to_string(h[1]));
    FakeModel model(seed++);
    const TargetMaterial target = Twin(2e10, 5e3, Rigid(h[0], h[1]));
    CalibrationSolver solver(CalibrationSurrogate(FitMapsOf(false, 0.0), Specimen2D(), Specimen2D()), target,
                             Options(), &model);
    const CalibrationSolution s = solver.Solve();
    SCOPED_TRACE(Rounds(s));
    ExpectNoStepAgainstTheRounds(s, target.StrengthRatio());
    EXPECT_TRUE(s.converged);
  }
  trend = saved_trend;
}

// Without the anchors the first round carries the whole transfer error (sigma_t +30 %): the
// loop still converges, in more rounds.
TEST(CalibrationSolver, WithoutTransferAnchorsTheLoopStillConverges) {
  const MapSet maps = FitMapsOf(false, 0.0);
  const double hidden[][2] = {{0.2, 3.0}, {0.3, 8.0}, {0.5, 5.0}, {0.7, 2.5}, {0.85, 9.0}, {0.25, 6.0}};
  unsigned seed = 21;
  int most = 0;
  for (const auto& h : hidden) {
    SCOPED_TRACE("hidden kt/kn " + std::to_string(h[0]) + ", Rt/Rn " + std::to_string(h[1]));
    const TargetMaterial target = Twin(2e10, 5e3, Rigid(h[0], h[1]));
    FakeModel model(seed++);
    CalibrationSolver solver(CalibrationSurrogate(maps, Specimen2D(), Specimen2D()), target, Options(), &model);
    const CalibrationSolution s = solver.Solve();
    ExpectConverged(s, Options(), 6);
    ExpectNoStepAgainstTheRounds(s, target.StrengthRatio());
    most = std::max(most, static_cast<int>(s.rounds.size()));
  }
  std::printf("without anchors: at most %d strength rounds\n", most);
}

// The same with deformable particles, for a nu above what rigid particles reach.
TEST(CalibrationSolver, DeformableTwinTargetsAboveTheRigidLimit) {
  const double compliance = 0.4;
  const MapSet maps = FitMapsOf(true, compliance);
  const double hidden[][3] = {{0.2, 0.3, 4.0}, {0.4, 0.35, 8.0}, {0.15, 0.2, 6.0}};
  unsigned seed = 11;
  for (const auto& h : hidden) {
    MicroRatios truth = Rigid(h[0], h[2]);
    truth.normal_stiffness_to_particle = h[1];
    truth.particle_poisson_ratio = 0.45;
    const TargetMaterial target = Twin(3e10, 8e3, truth);
    SCOPED_TRACE("hidden nu " + std::to_string(target.poisson_ratio));
    ASSERT_GT(target.poisson_ratio, Rock::Poisson(Rigid(0.15, 5.0)));  // beyond the rigid box
    FakeModel model(seed++);
    CalibrationSolver solver(Anchored(true, compliance, seed + 100), target, Options(compliance), &model);
    const CalibrationSolution s = solver.Solve();
    ExpectConverged(s, Options(compliance), 3);
    EXPECT_LE(s.ratios.normal_stiffness_to_particle, compliance + 1e-12);  // the stability bound
  }
}

// DDEM maps whose transfer anchors lie near the ends of kt/kn (0.15, 0.6), and a real
// specimen whose UCS, and so sigma_c / sigma_t, is `height` higher than the maps' in a bump
// about kt/kn `centre` (a Gaussian of that width) that the anchors barely see. The twin is
// the real specimen at kt/kn `kt`, Rt/Rn `x` and nu; *start is the reach's start.
CalibrationSolution SolveWithUcsBump(double height, double centre, double width, double kt, double x, double nu,
                                     CalibrationSolverOptions* options, MicroRatios* start) {
  const double compliance = 0.4;
  auto real_ucs = [=](const MicroRatios& r) {
    const double d = (r.tangential_to_normal_stiffness - centre) / width;
    return Rock::UcsPerStrength(r) * (1.0 + height * std::exp(-d * d));
  };
  CalibrationSurrogate surrogate(FitMapsOf(true, compliance), Specimen2D(), Specimen2D());
  for (double s : {0.15, 0.6})
    for (double b : {3.0, 8.0}) {
      SurrogateMeasurement m;
      m.ratios = Rigid(s, b);
      m.ratios.normal_stiffness_to_particle = b < 5.0 ? 0.1 : 0.3, m.ratios.particle_poisson_ratio = 0.45;
      m.youngs_per_stiffness = Rock::YoungsPerStiffness(m.ratios);
      m.poisson_ratio = Rock::Poisson(m.ratios);
      m.ucs_per_strength = real_ucs(m.ratios);
      m.tensile_per_strength = Rock::TensilePerStrength(m.ratios);
      surrogate.AddMeasurement(m, /*stored=*/true);
    }
  MicroRatios truth = Rigid(kt, x);
  truth.normal_stiffness_to_particle = (nu - Rock::Poisson(truth)) / 0.25;  // Rock::Poisson is linear in it
  truth.particle_poisson_ratio = 0.45;
  TargetMaterial target = Twin(3e10, 8e3, truth);
  target.ucs_pa = 8e3 * real_ucs(truth);
  FakeModel model(23);
  model.ucs_override = real_ucs;
  *options = Options(compliance);
  CalibrationSolver solver(surrogate, target, *options, &model);
  *start = solver.AssessReach().start;
  return solver.Solve();
}

// The start, by the maps' margin, lands in a bump (1.6 times the maps' UCS about kt/kn
// 0.375), and the rounds there measure the ratio above the target at every Rt/Rn. The
// elastic stage re-runs at the kt/kn that holds the target with the largest margin by the
// maps, corrected by those rounds: away from the bump, where the target is met.
TEST(CalibrationSolver, TheRatioOutOfReachAtTheStartSetIsMetAtAnotherSet) {
  CalibrationSolverOptions o;
  MicroRatios start;
  const CalibrationSolution s = SolveWithUcsBump(0.6, 0.375, 0.05, 0.24, 7.0, 0.225, &o, &start);
  SCOPED_TRACE(Rounds(s));
  ASSERT_NEAR(start.tangential_to_normal_stiffness, 0.375, 0.05);  // in the bump
  ASSERT_GE(s.replans, 1);
  EXPECT_LT(s.ratios.tangential_to_normal_stiffness, 0.27);
  EXPECT_TRUE(s.converged);
  EXPECT_TRUE(s.tensile_honoured);
  EXPECT_LE(std::abs(s.rounds[s.best_round].error_tensile), o.tolerance_tensile);
}

// After the start set misses the ratio, the other sets are judged as the reach judges the target
// before round 1: within the corrected maps' transfer uncertainty, not only within sigma_t's
// tolerance. Here (a wide bump, twice the UCS about kt/kn 0.375) the start's rounds measure the
// ratio below the target. Judged by the tolerance alone, or with those rounds counted one by one
// in the corrections of every other set, no set holds the target and sigma_t is given up after
// two rounds; as it is, the elastic stage re-runs where the twin is met.
TEST(CalibrationSolver, AnotherSetIsTriedWhereTheRatioIsWithinTheMapsUncertainty) {
  CalibrationSolverOptions o;
  MicroRatios start;
  const CalibrationSolution s = SolveWithUcsBump(1.0, 0.375, 0.16, 0.20, 5.0, 0.17, &o, &start);
  SCOPED_TRACE(Rounds(s));
  ASSERT_GE(s.replans, 1);
  EXPECT_TRUE(s.converged);
  EXPECT_TRUE(s.tensile_honoured);
  EXPECT_LE(std::abs(s.rounds[s.best_round].error_tensile), o.tolerance_tensile);
}

// The sweep of MapRock over a design's full-factorial grid, as the product's sweep stores it.
MapSweep MapRockSweep(const SweepDesign& design) {
  const PackingDescriptors d = Specimen2D();
  const double youngs = d.SolidCoordination() / d.CharacteristicRadius();
  const double strength = d.SolidCoordination() / d.CharacteristicArea();
  MapSweep sweep;
  sweep.ucs_descriptors = sweep.bts_descriptors = d;
  const std::vector<MicroRatios> grid = design.Points();
  for (size_t i = 0; i < grid.size(); ++i) {
    SweepPoint p;
    p.index = static_cast<int>(i), p.ratios = grid[i], p.ok = true;
    p.poisson_ratio = MapRock::Poisson(grid[i]);
    p.elastic_group = MapRock::YoungsPerStiffness(grid[i]) / youngs;
    p.compressive_group = MapRock::UcsPerStrength(grid[i]) / strength;
    p.tensile_group = MapRock::TensilePerStrength(grid[i]) / strength;
    sweep.points.push_back(p);
  }
  return sweep;
}

// The surrogate of that sweep (surfaces of total degree 2, and its grid when asked), corrected
// by the design's transfer anchors (of `anchor_levels`) measured exactly on the real specimen (Rock).
CalibrationSurrogate SweepSurrogate(const MapSweep& sweep, const SweepDesign& design, bool with_grid,
                                    int anchor_levels = 2) {
  CalibrationSurrogate surrogate(FitMaps(sweep, design, 2), Specimen2D(), Specimen2D());
  if (with_grid) surrogate.SetSweepGrid(SweepGrid(design, sweep.points));
  for (const MicroRatios& r : TransferAnchorPoints(design, anchor_levels)) {
    SurrogateMeasurement m;
    m.ratios = r;
    m.youngs_per_stiffness = Rock::YoungsPerStiffness(r);
    m.poisson_ratio = Rock::Poisson(r);
    m.ucs_per_strength = Rock::UcsPerStrength(r);
    m.tensile_per_strength = Rock::TensilePerStrength(r);
    surrogate.AddMeasurement(m, /*stored=*/true);
  }
  return surrogate;
}

// sigma_c / sigma_t peaks inside the kt/kn axis where Rt/Rn is large, a shape the fitted
// surfaces (total degree 2) flatten. Of the elastic sets that give the target's nu, the start is
// the one whose ratio reaches farthest towards a target above every set: ranked by the sweep's
// own points (sweep_grid.h) it is the true one, ranked by the fitted surfaces it is not.
TEST(CalibrationSolver, TheSweepPointsRankTheDeformableElasticSetsAndGiveTheReach) {
  const double compliance = 0.4;
  kt_peak = std::log(1.6);
  struct Reset {
    ~Reset() { kt_peak = 0.0; }
  } reset;
  const SweepDesign design = DesignOf(true, compliance);
  const MapSweep sweep = MapRockSweep(design);
  MicroRatios truth = Rigid(0.4, 10.0);
  truth.normal_stiffness_to_particle = 0.2, truth.particle_poisson_ratio = 0.45;
  TargetMaterial target = Twin(3e10, 8e3, truth);
  target.tensile_strength_pa /= 1.5;  // above the ratio every set reaches
  // The true reach: along nu = target's, the kt/kn whose largest ratio (Rt/Rn 2 to 10) is largest.
  double true_best = 0.0, true_top = 0.0;
  for (double s = 0.15; s <= 0.6 + 1e-9; s += 0.0025) {
    const double c = (target.poisson_ratio - Rock::Poisson(Rigid(s, 5.0))) / 0.25;  // Rock::Poisson is linear in c
    if (c < 0.0 || c > compliance) continue;
    for (double x = 2.0; x <= 10.0 + 1e-9; x += 0.1) {
      MicroRatios r = Rigid(s, x);
      r.normal_stiffness_to_particle = c, r.particle_poisson_ratio = 0.45;
      const double ratio = Rock::UcsPerStrength(r) / Rock::TensilePerStrength(r);
      if (ratio > true_top) true_top = ratio, true_best = s;
    }
  }
  auto start = [&](bool with_grid) {
    FakeModel model(5);
    CalibrationSolver solver(SweepSurrogate(sweep, design, with_grid), target, Options(compliance), &model);
    const CalibrationReach& reach = solver.AssessReach();
    return std::make_pair(reach.start.tangential_to_normal_stiffness, reach.strength_ratio_max);
  };
  const auto [ranked, grid_top] = start(true);
  const auto [unranked, surface_top] = start(false);
  SCOPED_TRACE("true best kt/kn " + std::to_string(true_best) + ", by the sweep points " + std::to_string(ranked) +
               ", by the surfaces " + std::to_string(unranked) + "; the top of the ratio " + std::to_string(true_top) +
               ", reported " + std::to_string(grid_top) + " (by the surfaces " + std::to_string(surface_top) + ")");
  EXPECT_NEAR(ranked, true_best, 0.03);
  EXPECT_GT(std::abs(unranked - true_best), 0.06);
  // The reach reported is the sweep points' too: its top near the true one, which the
  // surfaces flatten.
  EXPECT_NEAR(grid_top / true_top, 1.0, 0.05);
  EXPECT_LT(surface_top / true_top, 0.9);
}

// A strength ratio above the reach is reported before any strength test, with the interval,
// the nearest point and what is given up; the UCS is still met, sigma_t is not chased.
TEST(CalibrationSolver, UnreachableStrengthRatioIsDeclaredBeforeTheFirstRound) {
  const MapSet maps = FitMapsOf(false, 0.0);
  TargetMaterial target = Twin(2e10, 5e3, Rigid(0.3, 6.0));
  target.tensile_strength_pa = target.ucs_pa / 40.0;  // sigma_c / sigma_t = 40
  FakeModel model(3);
  CalibrationSolver solver(CalibrationSurrogate(maps, Specimen2D(), Specimen2D()), target, Options(), &model);
  const CalibrationReach& reach = solver.AssessReach();
  EXPECT_EQ(model.strength_rounds, 0);
  EXPECT_TRUE(reach.poisson_reachable);
  EXPECT_FALSE(reach.strength_ratio_reachable);
  EXPECT_LT(reach.strength_ratio_max, 40.0);
  EXPECT_GT(reach.strength_ratio_max, reach.strength_ratio_min);
  EXPECT_DOUBLE_EQ(reach.nearest_strength_ratio, reach.strength_ratio_max);
  ASSERT_EQ(reach.given_up.size(), 1u);
  EXPECT_EQ(reach.given_up[0], "sigma_t");
  const std::string text = reach.Describe(target);
  EXPECT_NE(text.find("lies outside"), std::string::npos) << text;
  EXPECT_NE(text.find("given up: sigma_t"), std::string::npos) << text;
  const CalibrationSolution s = solver.Solve();
  EXPECT_FALSE(s.tensile_honoured);
  EXPECT_TRUE(s.converged);  // every honoured property met
  EXPECT_LE(std::abs(s.rounds[s.best_round].error_ucs), Options().tolerance_ucs);
  EXPECT_LE(static_cast<int>(s.rounds.size()), 3);
  // Rt/Rn went to where the ratio is largest (near the upper end of the box), and stayed.
  EXPECT_GE(s.rounds[0].ratios.shear_to_tensile_strength, 9.0);
  for (const StrengthRound& r : s.rounds)
    EXPECT_DOUBLE_EQ(r.ratios.shear_to_tensile_strength, s.rounds[0].ratios.shear_to_tensile_strength);
}

// A nu beyond the measured interval: the reach names the interval measured at the corners.
TEST(CalibrationSolver, PoissonRatioOutsideTheMeasuredIntervalIsGivenUp) {
  const MapSet maps = FitMapsOf(false, 0.0);
  TargetMaterial target = Twin(2e10, 5e3, Rigid(0.3, 6.0));
  target.poisson_ratio = 0.35;
  FakeModel model(4);
  CalibrationSolver solver(CalibrationSurrogate(maps, Specimen2D(), Specimen2D()), target, Options(), &model);
  const CalibrationReach& reach = solver.AssessReach();
  EXPECT_FALSE(reach.poisson_reachable);
  EXPECT_NEAR(reach.poisson_max, Rock::Poisson(Rigid(0.15, 0)), 0.002);  // measured, not the map's +0.02
  EXPECT_NEAR(reach.poisson_min, Rock::Poisson(Rigid(0.9, 0)), 0.002);
  EXPECT_DOUBLE_EQ(reach.nearest_poisson, reach.poisson_max);
  EXPECT_EQ(reach.given_up.front(), "nu");
  const CalibrationSolution s = solver.Solve();
  EXPECT_NEAR(s.ratios.tangential_to_normal_stiffness, 0.15, 1e-9);  // the nearest end
  // nu is given up, not chased: E is still met there, and the elastic stage counts as met.
  EXPECT_LE(std::abs(s.error_youngs), Options().tolerance_youngs);
  EXPECT_TRUE(s.elastic_converged);
  EXPECT_EQ(s.reach.given_up.front(), "nu");
}

// Path noise of 5 % (the UCS where tension controls failure), repeatable as a deterministic
// run's: rounds at one Rt/Rn take the level of their mean, so a round never lands on the
// very point of an earlier one (anchored on the best round, a worse round at that Rt/Rn
// sent the next one back to its own point, which measures the same again).
TEST(CalibrationSolver, RepeatableNoiseNeverSendsARoundBackToAMeasuredPoint) {
  const double hidden[][2] = {{0.3, 9.5}, {0.45, 8.0}, {0.25, 10.0}, {0.6, 7.0}};
  unsigned seed = 71;
  int rounds = 0;
  for (const auto& h : hidden) {
    SCOPED_TRACE("hidden kt/kn " + std::to_string(h[0]) + ", Rt/Rn " + std::to_string(h[1]));
    const TargetMaterial target = Twin(2e10, 5e3, Rigid(h[0], h[1]));
    FakeModel model(seed++, 0.05);
    model.repeatable = true;
    model.ratio_saturation = 1.5;  // a plateau in Rt/Rn
    CalibrationSolverOptions o = Options();
    o.max_strength_rounds = 8;
    CalibrationSolver solver(Anchored(false, 0.0, seed + 100), target, o, &model);
    const CalibrationSolution s = solver.Solve();
    SCOPED_TRACE(Rounds(s));
    rounds += static_cast<int>(s.rounds.size());
    for (size_t a = 0; a < s.rounds.size(); ++a)
      for (size_t b = a + 1; b < s.rounds.size(); ++b) {
        const StrengthRound &p = s.rounds[a], &q = s.rounds[b];
        const bool same = p.elastic_set == q.elastic_set &&
                          p.ratios.shear_to_tensile_strength == q.ratios.shear_to_tensile_strength &&
                          p.bond_tensile_strength == q.bond_tensile_strength;
        EXPECT_FALSE(same) << "rounds " << p.round << " and " << q.round;
      }
  }
  EXPECT_GT(rounds, 8);  // the loop did work at several points
}

// The distance of a reach from the target, in tolerances, which the automatic model choice
// compares when neither model reaches: a nu 2.2 % beyond one model's end is nearer than one
// 33 % beyond the other's, whatever their strength ratios (the Nevada Test Site basalt: nu
// 0.32, sigma_c / sigma_t 11.3; DDEM reaches nu 0.313, rigid particles 0.214).
TEST(CalibrationReach, MissCountsToleranceWidthsToTheNearestReachablePoint) {
  TargetMaterial target;
  target.poisson_ratio = 0.32;
  target.ucs_pa = 113e6;
  target.tensile_strength_pa = 10e6;
  CalibrationReach ddem, rigid;
  ddem.nearest_poisson = 0.313, ddem.nearest_strength_ratio = 11.3;
  rigid.nearest_poisson = 0.2137, rigid.nearest_strength_ratio = 11.3;
  EXPECT_NEAR(ddem.Miss(target, 0.015, 0.05), (0.32 - 0.313) / (0.015 * 0.32), 1e-12);
  EXPECT_LT(ddem.Miss(target, 0.015, 0.05), rigid.Miss(target, 0.015, 0.05));
  // Inside the reach: nothing missed. A ratio one tolerance off: one.
  CalibrationReach inside;
  inside.nearest_poisson = 0.32, inside.nearest_strength_ratio = 11.3;
  EXPECT_EQ(inside.Miss(target, 0.015, 0.05), 0.0);
  inside.nearest_strength_ratio = 11.3 * 1.05;
  EXPECT_NEAR(inside.Miss(target, 0.015, 0.05), 1.0, 1e-12);
  // Both misses add in quadrature.
  inside.nearest_poisson = 0.32 * (1 - 0.015);
  EXPECT_NEAR(inside.Miss(target, 0.015, 0.05), std::sqrt(2.0), 1e-9);
}

// Maps whose strengths vary with Rt/Rn three times less than the real specimen's (without
// any offset): the first round overshoots, the offset correction then asks for a step three
// times too long the other way, that round is worse, it is rejected, the region shrinks to
// half that step about the best round, and the loop still converges; Rt/Rn never moves
// further than the region allows.
TEST(CalibrationSolver, AWorseRoundIsRejectedAndTheRegionShrinks) {
  auto shallow = [](const MicroRatios& r) {
    return Rigid(r.tangential_to_normal_stiffness, 3.0 + (r.shear_to_tensile_strength - 3.0) / 3.0);
  };
  const MapSet maps = RigidMapsWithStrengths([&](const MicroRatios& r) { return Rock::UcsPerStrength(shallow(r)); },
                                             [&](const MicroRatios& r) { return Rock::TensilePerStrength(shallow(r)); },
                                             3);
  const TargetMaterial target = Twin(2e10, 5e3, Rigid(0.4, 4.0));
  FakeModel model(7, 0.003);
  CalibrationSolver solver(CalibrationSurrogate(maps, Specimen2D(), Specimen2D()), target, Options(), &model);
  const CalibrationSolution s = solver.Solve();
  SCOPED_TRACE(Rounds(s));
  bool rejected = false;
  double best_x = s.rounds[0].ratios.shear_to_tensile_strength;  // of the best round so far
  for (size_t k = 1; k < s.rounds.size(); ++k) {
    rejected = rejected || !s.rounds[k].accepted;
    // Each step stays within the region the previous round left, about the best round.
    EXPECT_LE(std::abs(s.rounds[k].ratios.shear_to_tensile_strength - best_x), s.rounds[k - 1].trust_radius + 1e-9);
    if (s.rounds[k].accepted) best_x = s.rounds[k].ratios.shear_to_tensile_strength;
  }
  EXPECT_TRUE(rejected);  // the overlong step was caught
  EXPECT_TRUE(s.converged);
  EXPECT_LE(static_cast<int>(s.rounds.size()), 6);
  // The reported set is the best round, whichever came last.
  const StrengthRound& best = s.rounds[s.best_round];
  for (const StrengthRound& r : s.rounds) EXPECT_LE(best.weighted_error, r.weighted_error);
  EXPECT_DOUBLE_EQ(s.bond_tensile_strength, best.bond_tensile_strength);
}

// Map specimens whose UCS trend in Rt/Rn is wrong by 5 % per unit (the map's sigma_c / sigma_t
// 20 % low at Rt/Rn 2, 20 % high at 10, as the DDEM map specimens transfer it): four anchors
// at the quarters of the box leave the ends of Rt/Rn, where the reach's extremes lie, off;
// the thirteen of anchor_levels 3 (edges and middle besides) correct them better.
TEST(CalibrationSolver, ThirteenTransferAnchorsCorrectTheRatioAcrossTheBox) {
  const double saved_trend = trend;
  trend = 0.05;
  struct Reset {
    double saved;
    ~Reset() { trend = saved; }
  } reset{saved_trend};
  const SweepDesign design = DesignOf(false, 0.0);
  const MapSweep sweep = MapRockSweep(design);
  auto rms_error = [&](int levels, double* worst_end) {
    const CalibrationSurrogate surrogate = SweepSurrogate(sweep, design, /*with_grid=*/true, levels);
    double sum = 0.0;
    int n = 0;
    *worst_end = 0.0;
    for (double s : Linspace(0.15, 0.9, 7))
      for (double x : Linspace(2.0, 10.0, 9)) {
        const MicroRatios r = Rigid(s, x);
        const double e = std::log(surrogate.GridStrengthRatio(r) / (Rock::UcsPerStrength(r) / Rock::TensilePerStrength(r)));
        sum += e * e, ++n;
        if (x == 2.0 || x == 10.0) *worst_end = std::max(*worst_end, std::abs(e));
      }
    return std::sqrt(sum / n);
  };
  double end4 = 0.0, end13 = 0.0;
  const double rms4 = rms_error(2, &end4), rms13 = rms_error(3, &end13);
  SCOPED_TRACE("rms " + std::to_string(rms4) + " -> " + std::to_string(rms13) + ", worst at the ends of Rt/Rn " +
               std::to_string(end4) + " -> " + std::to_string(end13));
  EXPECT_GT(end4, 0.1);  // the case is one where four anchors fall short
  // The inverse-distance mean still pulls an edge towards the middle's correction (7 % of the
  // 20 % left here), but the error where the reach is read falls by nearly half.
  EXPECT_LT(rms13, 0.75 * rms4);
  EXPECT_LT(end13, 0.6 * end4);
}

// Measurements stored with the maps (from earlier calibrations on this specimen) correct the
// transfer error before the first round: the first strength round lands closer.
TEST(CalibrationSolver, StoredMeasurementsCorrectTheFirstPrediction) {
  const MapSet maps = FitMapsOf(false, 0.0);
  const TargetMaterial target = Twin(2e10, 5e3, Rigid(0.35, 7.0));
  CalibrationSurrogate fresh(maps, Specimen2D(), Specimen2D());
  CalibrationSurrogate learned = fresh;
  for (const auto& p : std::vector<std::pair<double, double>>{{0.2, 4.0}, {0.6, 8.0}, {0.8, 3.0}}) {
    SurrogateMeasurement m;
    m.ratios = Rigid(p.first, p.second);
    m.youngs_per_stiffness = Rock::YoungsPerStiffness(m.ratios);
    m.poisson_ratio = Rock::Poisson(m.ratios);
    m.ucs_per_strength = Rock::UcsPerStrength(m.ratios);
    m.tensile_per_strength = Rock::TensilePerStrength(m.ratios);
    learned.AddMeasurement(m, /*stored=*/true);
  }
  FakeModel a(9, 0.0, 0.0), b(9, 0.0, 0.0);
  const CalibrationSolution s_fresh = CalibrationSolver(fresh, target, Options(), &a).Solve();
  const CalibrationSolution s_learned = CalibrationSolver(learned, target, Options(), &b).Solve();
  auto first_error = [](const CalibrationSolution& s) {
    return std::hypot(s.corrected_error_ucs, s.corrected_error_tensile);
  };
  EXPECT_LT(first_error(s_learned), 0.5 * first_error(s_fresh)) << Rounds(s_fresh) << Rounds(s_learned);
  EXPECT_LE(s_learned.rounds.size(), s_fresh.rounds.size());
}

// Maps whose sigma_t is a third of the real specimen's (sigma_c / sigma_t three times too
// high) and no stored measurement: a low target ratio looks out of reach even within the
// maps' transfer uncertainty and is declared so before any strength test; the first round,
// at the end of the box that comes nearest, measures it within reach, sigma_t is honoured
// again, and nothing stays given up.
TEST(CalibrationSolver, ARatioDeclaredOutOfReachButMeasuredWithinIsHonouredAgain) {
  const MapSet maps =
      RigidMapsWithStrengths({}, [](const MicroRatios& r) { return Rock::TensilePerStrength(r) / 3.0; });
  const TargetMaterial target = Twin(2e10, 5e3, Rigid(0.3, 2.0));
  FakeModel model(13, 0.003);
  CalibrationSolver solver(CalibrationSurrogate(maps, Specimen2D(), Specimen2D()), target, Options(), &model);
  ASSERT_TRUE(solver.AssessReach().declared_out_of_reach()) << solver.AssessReach().Describe(target);
  const CalibrationSolution s = solver.Solve();
  SCOPED_TRACE(Rounds(s));
  EXPECT_TRUE(s.tensile_honoured);
  EXPECT_TRUE(s.reach.given_up.empty());
  EXPECT_TRUE(s.converged);
  bool noted = false;
  for (const std::string& n : s.notes) noted = noted || n.find("honoured again") != std::string::npos;
  EXPECT_TRUE(noted);
}

// A ratio the maps think possible but the specimen cannot give (the target's sigma_t is 30 %
// above anything the box reaches): the round at the end that comes nearest misses it, a probe
// inwards measures the trend (no stored measurement shows it), then sigma_t is given up and
// the UCS is met with Rn alone at that end.
TEST(CalibrationSolver, AnUnreachableRatioIsGivenUpOnMeasurementAfterAProbe) {
  // Unbiased maps (fitted to the true model) without stored measurements.
  const MapSet maps = RigidMapsWithStrengths(Rock::UcsPerStrength, Rock::TensilePerStrength);
  TargetMaterial target = Twin(2e10, 5e3, Rigid(0.3, 2.0));
  target.tensile_strength_pa *= 1.3;  // sigma_c / sigma_t below what Rt/Rn = 2 gives
  FakeModel model(17, 0.003);
  CalibrationSolver solver(CalibrationSurrogate(maps, Specimen2D(), Specimen2D()), target, Options(), &model);
  ASSERT_FALSE(solver.AssessReach().declared_out_of_reach()) << solver.AssessReach().Describe(target);
  const CalibrationSolution s = solver.Solve();
  SCOPED_TRACE(Rounds(s));
  bool probed = false;
  for (const StrengthRound& r : s.rounds) probed = probed || r.step.find("probing beside") != std::string::npos;
  EXPECT_TRUE(probed);
  EXPECT_FALSE(s.tensile_honoured);
  ASSERT_EQ(s.reach.given_up.size(), 1u);
  EXPECT_EQ(s.reach.given_up[0], "sigma_t");
  EXPECT_TRUE(s.converged);  // on what is kept
  EXPECT_LE(std::abs(s.rounds[s.best_round].error_ucs), Options().tolerance_ucs);
  EXPECT_NEAR(s.ratios.shear_to_tensile_strength, 2.0, 0.2);  // the end that comes nearest
  EXPECT_LE(static_cast<int>(s.rounds.size()), 4);
}

// A ratio the maps reach but the specimen does not come near: sigma_c / sigma_t is flat in
// Rt/Rn (within 8 %, a mild bump inside the box) at about 0.6 of the target's, as a 3D rigid
// specimen measured 5.6-6.1 over Rt/Rn 1-10 against the Labra rock's 10.4. Rounds that
// measure the ratio that far below at points a tenth of the box apart show the target out of
// reach whether or not the ratio between them is distinctly lower than its measured extreme
// (a bump of the path noise's size cannot close a 40 % miss): sigma_t is given up after a
// few rounds, not after probing every side of each new noisy extreme, and Rn meets the UCS.
TEST(CalibrationSolver, ARatioFarOutOfReachOnAFlatLineIsGivenUpWithinFourRounds) {
  const MapSet maps = RigidMapsWithStrengths(Rock::UcsPerStrength, Rock::TensilePerStrength);
  const MicroRatios hidden = Rigid(0.3, 6.0);
  auto flat_ratio = [](const MicroRatios& r) {
    const double x = r.shear_to_tensile_strength;
    return 6.0 * (1.0 + 0.08 * std::exp(-std::pow((x - 7.0) / 2.0, 2)));
  };
  TargetMaterial target = Twin(2e10, 5e3, hidden);
  target.ucs_pa = target.tensile_strength_pa * 1.7 * flat_ratio(Rigid(0.3, 7.0));
  for (unsigned seed : {71u, 72u, 73u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    FakeModel model(seed);
    model.ucs_override = [&](const MicroRatios& r) { return Rock::TensilePerStrength(r) * flat_ratio(r); };
    CalibrationSolver solver(CalibrationSurrogate(maps, Specimen2D(), Specimen2D()), target, Options(), &model);
    ASSERT_FALSE(solver.AssessReach().declared_out_of_reach()) << solver.AssessReach().Describe(target);
    const CalibrationSolution s = solver.Solve();
    SCOPED_TRACE(Rounds(s));
    EXPECT_FALSE(s.tensile_honoured);
    ASSERT_EQ(s.reach.given_up.size(), 1u);
    EXPECT_EQ(s.reach.given_up[0], "sigma_t");
    EXPECT_TRUE(s.converged);  // on what is kept
    EXPECT_LE(std::abs(s.rounds[s.best_round].error_ucs), Options().tolerance_ucs);
    EXPECT_LE(static_cast<int>(s.rounds.size()), 5);
    int given_up_in = 0;  // the round whose note gives sigma_t up
    for (const std::string& n : s.notes)
      if (n.find("is out of reach on this specimen: round ") != std::string::npos)
        given_up_in = std::atoi(n.c_str() + n.find(": round ") + 8);
    EXPECT_GE(given_up_in, 2);
    EXPECT_LE(given_up_in, 4);
  }
}

// Once sigma_t is given up, a round measured before may already meet the UCS: the stage ends
// there instead of spending rounds on the UCS alone (a ratio 8 % below the box's least: Rn
// splits the miss by the tolerances, so round 1 meets the UCS while sigma_t misses by about
// 6 %; round 2 probes the other side and gives sigma_t up).
TEST(CalibrationSolver, TheStageEndsWhenAnEarlierRoundMeetsWhatIsKept) {
  const MapSet maps = RigidMapsWithStrengths(Rock::UcsPerStrength, Rock::TensilePerStrength);
  TargetMaterial target = Twin(2e10, 5e3, Rigid(0.3, 2.0));
  target.tensile_strength_pa *= 1.08;
  const CalibrationSolverOptions options = Options();
  FakeModel model(17, 0.003);
  CalibrationSolver solver(CalibrationSurrogate(maps, Specimen2D(), Specimen2D()), target, options, &model);
  const CalibrationSolution s = solver.Solve();
  SCOPED_TRACE(Rounds(s));
  ASSERT_GE(s.rounds.size(), 2u);
  EXPECT_LE(std::abs(s.rounds[0].error_ucs), options.tolerance_ucs);
  EXPECT_GT(std::abs(s.rounds[0].error_tensile), options.tolerance_tensile);
  EXPECT_FALSE(s.tensile_honoured);
  EXPECT_EQ(s.rounds.size(), 2u);
  EXPECT_EQ(s.best_round, 0);
  EXPECT_TRUE(s.converged);
}

// A target below every ratio of the box, on maps whose UCS is 40 % low: round 1 lands inside
// the box (about Rt/Rn 5.5), the corrected line comes nearest at the box end, and the probe goes
// to that end at once rather than a quarter of the box towards it.
TEST(CalibrationSolver, TheProbeTowardsTheLinesNearestBoxEndGoesToTheEnd) {
  const MapSet maps = RigidMapsWithStrengths([](const MicroRatios& r) { return 0.6 * Rock::UcsPerStrength(r); },
                                             Rock::TensilePerStrength);
  TargetMaterial target = Twin(2e10, 5e3, Rigid(0.3, 2.0));
  target.tensile_strength_pa *= 1.08;  // 8 % below the ratio at Rt/Rn 2, the box's least
  FakeModel model(17, 0.003);
  CalibrationSolver solver(CalibrationSurrogate(maps, Specimen2D(), Specimen2D()), target, Options(), &model);
  const CalibrationSolution s = solver.Solve();
  SCOPED_TRACE(Rounds(s));
  ASSERT_GE(s.rounds.size(), 2u);
  EXPECT_GT(s.rounds[0].ratios.shear_to_tensile_strength, 4.0);
  EXPECT_NE(s.rounds[0].step.find("probing beside"), std::string::npos);
  EXPECT_DOUBLE_EQ(s.rounds[1].ratios.shear_to_tensile_strength, 2.0);
}

// sigma_c / sigma_t can peak inside the box and fall towards its end, where the maps put the
// target (a rigid twin of the default specimen: 17.6 at Rt/Rn 4.5, 16.2 and 15.9 at 9.7 and 10,
// where the maps reached 17.7). A target at the peak is reached: rounds at the end do not
// declare it out of reach before the other side of their extreme is measured, and once the
// rounds measure the ratio falling, its root is sought below them.
TEST(CalibrationSolver, ARatioThatPeaksInsideTheBoxIsFoundBelowTheBoxEnd) {
  // Maps whose UCS is 17 % low (a transfer error): their ratio meets the target's only near
  // the box end.
  const MapSet maps = RigidMapsWithStrengths([](const MicroRatios& r) { return 0.83 * Rock::UcsPerStrength(r); },
                                             Rock::TensilePerStrength);
  for (unsigned seed : {61u, 62u, 63u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const TargetMaterial target = Twin(2e10, 5e3, Rigid(0.25, 4.5));
    FakeModel model(seed);
    model.ratio_peak = 4.5;
    CalibrationSolver solver(CalibrationSurrogate(maps, Specimen2D(), Specimen2D()), target, Options(), &model);
    const CalibrationSolution s = solver.Solve();
    SCOPED_TRACE(Rounds(s));
    EXPECT_TRUE(s.tensile_honoured);
    ExpectConverged(s, Options(), 6);
  }
}

// One strength round: the loop runs it and stops; nothing is given up on a budget.
TEST(CalibrationSolver, ABudgetOfOneRoundGivesNothingUp) {
  const MapSet maps = FitMapsOf(false, 0.0);
  const TargetMaterial target = Twin(2e10, 5e3, Rigid(0.3, 6.0));
  FakeModel model(19);
  CalibrationSolverOptions o = Options();
  o.max_strength_rounds = 1;
  const CalibrationSolution s =
      CalibrationSolver(CalibrationSurrogate(maps, Specimen2D(), Specimen2D()), target, o, &model).Solve();
  EXPECT_EQ(s.rounds.size(), 1u);
  EXPECT_EQ(s.best_round, 0);
  EXPECT_TRUE(s.tensile_honoured);
  EXPECT_TRUE(s.reach.given_up.empty());
  EXPECT_FALSE(s.converged);  // the maps' transfer error (sigma_t +30 %) is still in it
}

// Maps without Rt/Rn (a design that sweeps kt/kn alone): sigma_c / sigma_t is what the elastic
// set gives; one round shows it, sigma_t is given up, and Rn meets the UCS.
TEST(CalibrationSolver, MapsWithoutTheStrengthRatioGiveUpSigmaTAfterOneRound) {
  const PackingDescriptors d = Specimen2D();
  const double youngs = d.SolidCoordination() / d.CharacteristicRadius();
  const double strength = d.SolidCoordination() / d.CharacteristicArea();
  MapSet maps;
  maps.inputs = {MicroRatio::kStiffnessRatio};
  maps.fixed = Rigid(0.0, 6.0);
  Eigen::MatrixXd x(4, 1);
  Eigen::VectorXd nu(4), pe(4), pc(4), pt(4);
  int i = 0;
  for (double s : Linspace(0.15, 0.9, 4)) {
    const MicroRatios r = Rigid(s, 6.0);
    x(i, 0) = s;
    nu[i] = MapRock::Poisson(r), pe[i] = MapRock::YoungsPerStiffness(r) / youngs;
    pc[i] = MapRock::UcsPerStrength(r) / strength, pt[i] = MapRock::TensilePerStrength(r) / strength;
    ++i;
  }
  ResponseSurfaceOptions fit;
  fit.max_total_degree = 2;
  maps.poisson_ratio = ResponseSurface::Fit(x, nu, fit);
  maps.elastic_group = ResponseSurface::Fit(x, pe, fit);
  fit.log_values = true;
  maps.compressive_group = ResponseSurface::Fit(x, pc, fit);
  maps.tensile_group = ResponseSurface::Fit(x, pt, fit);
  TargetMaterial target = Twin(2e10, 5e3, Rigid(0.4, 6.0));
  target.tensile_strength_pa *= 1.2;
  FakeModel model(23, 0.003);
  const CalibrationSolution s =
      CalibrationSolver(CalibrationSurrogate(maps, Specimen2D(), Specimen2D()), target, Options(), &model).Solve();
  SCOPED_TRACE(Rounds(s));
  EXPECT_FALSE(s.tensile_honoured);
  EXPECT_TRUE(s.converged);
  EXPECT_LE(static_cast<int>(s.rounds.size()), 3);
  for (const StrengthRound& r : s.rounds) EXPECT_DOUBLE_EQ(r.ratios.shear_to_tensile_strength, 6.0);
}

// Two rounds at one point, as the loop judges it: Rt/Rn within 1 % of its box (8 wide here)
// and Rn within 1 %.
bool SamePoint(const StrengthRound& a, const StrengthRound& b) {
  constexpr double kBoxWidth = 8.0;
  return a.elastic_set == b.elastic_set &&
         std::abs(a.ratios.shear_to_tensile_strength - b.ratios.shear_to_tensile_strength) <= 0.01 * kBoxWidth &&
         std::abs(std::log(a.bond_tensile_strength / b.bond_tensile_strength)) <= std::log(1.01);
}

// No round after a failed one runs at its point.
void ExpectNoStepOntoAFailedRound(const CalibrationSolution& s) {
  for (size_t f = 0; f < s.rounds.size(); ++f)
    for (size_t k = f + 1; s.rounds[f].failed && k < s.rounds.size(); ++k)
      EXPECT_FALSE(SamePoint(s.rounds[f], s.rounds[k])) << "round " << k + 1 << " at failed round " << f + 1;
}

// The test of round `first` diverges, and so would any later one at that point (a hole in the
// box): the model counts it as a second divergence.
void DivergeAtRoundAndAfterAtItsPoint(FakeModel* model, int first) {
  auto hole = std::make_shared<StrengthRound>();
  model->diverges = [first, hole](int round, double rn, const MicroRatios& r) {
    StrengthRound here;
    here.ratios = r;
    here.bond_tensile_strength = rn;
    if (round == first) *hole = here;
    return round == first || (round > first && SamePoint(*hole, here));
  };
}

// A verification round whose test diverges (the forward model throws ComputationError, as the
// lab's does for "a wall reaction became NaN") is a failed round, not the end of the
// calibration: it is recorded with its message, rejected, its point is not stepped on again,
// and the loop converges with the rest of its budget. Round 1 failing (nothing measured yet on
// the line) and round 2 failing (after a measured round), on maps without anchors, where no
// twin is met in round 1. (Their twin at kt/kn 0.85, Rt/Rn 9 is left out: its ratio lies on
// the plateau at the top of the reach, where the parabola of three rounds can peak below it
// and the reach rule give sigma_t up, whether a round failed or not.)
TEST(CalibrationSolver, ADivergedRoundIsRejectedAndTheLoopGoesOn) {
  const double hidden[][2] = {{0.2, 3.0}, {0.3, 8.0}, {0.5, 5.0}, {0.7, 2.5}, {0.25, 6.0}};
  for (int failing : {1, 2}) {
    unsigned seed = 21;
    for (const auto& h : hidden) {
      SCOPED_TRACE("hidden kt/kn " + std::to_string(h[0]) + ", Rt/Rn " + std::to_string(h[1]) + "; round " +
                   std::to_string(failing) + " diverges");
      const TargetMaterial target = Twin(2e10, 5e3, Rigid(h[0], h[1]));
      FakeModel model(seed++);
      DivergeAtRoundAndAfterAtItsPoint(&model, failing);
      CalibrationSolverOptions o = Options();
      o.max_strength_rounds = 7;  // the budget without anchors, and the failed round
      CalibrationSolver solver(CalibrationSurrogate(FitMapsOf(false, 0.0), Specimen2D(), Specimen2D()), target, o,
                               &model);
      const CalibrationSolution s = solver.Solve();
      SCOPED_TRACE(Rounds(s));
      ASSERT_GE(static_cast<int>(s.rounds.size()), failing);
      const StrengthRound& failed = s.rounds[failing - 1];
      EXPECT_TRUE(failed.failed);
      EXPECT_NE(failed.failure.find("a wall reaction became NaN"), std::string::npos) << failed.failure;
      EXPECT_FALSE(failed.accepted);
      EXPECT_EQ(model.diverged_rounds, 1);  // its point was not tried again
      ExpectNoStepOntoAFailedRound(s);
      ExpectNoStepAgainstTheRounds(s, target.StrengthRatio());
      ExpectConverged(s, o, o.max_strength_rounds);
      EXPECT_FALSE(s.rounds[s.best_round].failed);
      for (size_t k = 0; k < s.rounds.size(); ++k) EXPECT_EQ(s.rounds[k].round, static_cast<int>(k) + 1);
    }
  }
}

// Where sigma_t is given up, Rt/Rn stays at the end of the box and Rn alone meets the UCS. A
// step of Rn that diverges is not repeated: the next one goes half way back to the best round's
// Rn, and the loop still meets the UCS or ends without stepping on the failed point.
TEST(CalibrationSolver, ADivergedStepOfRnAloneIsNotRepeated) {
  TargetMaterial target = Twin(2e10, 5e3, Rigid(0.3, 6.0));
  target.tensile_strength_pa = target.ucs_pa / 40.0;  // sigma_c / sigma_t = 40: out of reach
  for (unsigned seed : {3u, 5u, 8u}) {
    FakeModel model(seed);
    DivergeAtRoundAndAfterAtItsPoint(&model, 2);
    const CalibrationSolution s =
        CalibrationSolver(CalibrationSurrogate(FitMapsOf(false, 0.0), Specimen2D(), Specimen2D()), target, Options(),
                          &model)
            .Solve();
    SCOPED_TRACE(Rounds(s));
    ASSERT_GE(s.rounds.size(), 2u);
    EXPECT_TRUE(s.rounds[1].failed);
    EXPECT_DOUBLE_EQ(s.rounds[1].ratios.shear_to_tensile_strength, s.rounds[0].ratios.shear_to_tensile_strength);
    EXPECT_EQ(model.diverged_rounds, 1);
    ExpectNoStepOntoAFailedRound(s);
    EXPECT_FALSE(s.tensile_honoured);
    EXPECT_TRUE(s.converged);
    EXPECT_LE(std::abs(s.rounds[s.best_round].error_ucs), Options().tolerance_ucs);
  }
}

// A test that diverges everywhere: every round fails, each at another point (nothing measured
// corrects the line, so the loop spreads them over the box), the budget is spent and there is
// no result; the solution says so instead of throwing.
TEST(CalibrationSolver, WhenEveryRoundDivergesThereIsNoResult) {
  const TargetMaterial target = Twin(2e10, 5e3, Rigid(0.3, 6.0));
  FakeModel model(29);
  model.diverges = [](int, double, const MicroRatios&) { return true; };
  const CalibrationSolution s =
      CalibrationSolver(Anchored(false, 0.0, 30), target, Options(), &model).Solve();
  SCOPED_TRACE(Rounds(s));
  EXPECT_EQ(s.best_round, -1);
  EXPECT_FALSE(s.converged);
  EXPECT_EQ(static_cast<int>(s.rounds.size()), Options().max_strength_rounds);
  for (const StrengthRound& r : s.rounds) EXPECT_TRUE(r.failed);
  ExpectNoStepOntoAFailedRound(s);
  EXPECT_LE(std::abs(s.error_youngs), Options().tolerance_youngs);  // the elastic set stands
  bool noted = false;
  for (const std::string& n : s.notes) noted = noted || n.find("no result") != std::string::npos;
  EXPECT_TRUE(noted);
}

TEST(CalibrationSolver, BadOptionsAreRefused) {
  const MapSet maps = FitMapsOf(true, 0.4);
  const TargetMaterial target = Twin(2e10, 5e3, Rigid(0.3, 6.0));
  FakeModel model(1);
  CalibrationSolverOptions o;
  o.tolerance_ucs = 0.0;
  try {
    CalibrationSolver(CalibrationSurrogate(maps, Specimen2D(), Specimen2D()), target, o, &model);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tolerance_ucs"), std::string::npos) << e.what();
  }
  // DDEM maps without the stability bound.
  EXPECT_THROW(CalibrationSolver(CalibrationSurrogate(maps, Specimen2D(), Specimen2D()), target, Options(), &model),
               InputError);
}

}  // namespace
}  // namespace specimen
