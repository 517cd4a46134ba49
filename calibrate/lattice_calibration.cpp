#include "calibrate/lattice_calibration.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/error.h"
#include "common/format.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string Format(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

}  // namespace

bool LatticeCalibrationOptions::IsValid(std::string* error) const {
  for (const auto& [name, value] : {std::pair<const char*, double>{"tolerance_youngs", tolerance_youngs},
                                    {"tolerance_poisson", tolerance_poisson},
                                    {"tolerance_ucs", tolerance_ucs},
                                    {"tolerance_tensile", tolerance_tensile}})
    if (!(value > 0.0 && value < 1.0)) {
      *error = std::string(name) + " = " + Number(value) + ": must be in (0, 1)";
      return false;
    }
  if (max_rounds < 1 || max_rounds > 20) {
    *error = "max_rounds = " + std::to_string(max_rounds) + ": must be in [1, 20]";
    return false;
  }
  return test.IsValid(error) && protocol.IsValid(error);
}

namespace {

constexpr int kMaxFrictionLowerings = 2;
constexpr double kLowestFrictionAngle = 5.0;  // degrees

// The UCS of the triangles' Mohr-Coulomb limit per unit cohesion, 2 cos(phi) / (1 - sin(phi)).
double MohrCoulombUcsPerCohesion(double phi_deg) { return LatticeStrength{1.0, 1.0, phi_deg}.TriangleCompressiveStrength(); }

// The friction angle at which the shear limit lets the Brazilian strength reach the target's.
// At the centre of a Brazilian disc sigma_1 = -3 sigma_B, sigma_3 = sigma_B, and the
// Mohr-Coulomb limit sigma_1 = UCS + N sigma_3 (compression positive, N = (1 + sin phi) /
// (1 - sin phi)) caps UCS / sigma_B at 3 + N. The specimens fail first near the loading
// strips, so the measured cap lies above 3 + N by a factor (about 1.8 at 30 degrees on the
// default specimens); that factor is taken as measured at the present angle, and the new angle
// aims 15 % below the target ratio: N' = (3 + N) (ratio / 1.15) / measured_cap - 3. Between
// kLowestFrictionAngle and 5 degrees below the present one.
double LowerFrictionAngle(double phi_deg, double measured_cap_ratio, double target_ratio) {
  const double phi = phi_deg * kPi / 180.0;
  const double n = (1.0 + std::sin(phi)) / (1.0 - std::sin(phi));
  const double wanted = (3.0 + n) * (target_ratio / 1.15) / measured_cap_ratio - 3.0;
  double lowered = kLowestFrictionAngle;
  if (wanted > 1.0) lowered = std::asin((wanted - 1.0) / (wanted + 1.0)) * 180.0 / kPi;
  return std::clamp(lowered, kLowestFrictionAngle, std::max(kLowestFrictionAngle, phi_deg - 5.0));
}

}  // namespace

LatticeCalibrationSummary CalibrateLattice(const Packing<2>& ucs, const Packing<2>& bts, const TargetMaterial& target,
                                           const LatticeCalibrationOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  const LatticeRoundModel run_round = LatticeTestsOn(ucs, bts, options.test, options.protocol);
  LatticeCalibrationSummary summary = CalibrateLattice(target, options, run_round);
  summary.ucs_particles = ucs.size();
  summary.bts_particles = bts.size();
  return summary;
}

LatticeCalibrationSummary CalibrateLattice(const TargetMaterial& target, const LatticeCalibrationOptions& options,
                                           const LatticeRoundModel& measure) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  if (!target.IsValid(&error)) throw InputError(error);
  if (!(target.poisson_ratio > -1.0 && target.poisson_ratio < 0.5))
    throw InputError("poisson_ratio = " + Number(target.poisson_ratio) +
                     ": the plane-strain lattice needs nu in (-1, 0.5)");
  const auto start = std::chrono::steady_clock::now();
  LatticeCalibrationSummary summary;
  summary.target = target;
  summary.friction_angle_deg = target.friction_angle_deg.value_or(30.0);
  if (summary.friction_angle_deg > 60.0)
    throw InputError("friction_angle = " + Number(summary.friction_angle_deg) +
                     ": the lattice's Mohr-Coulomb limit takes at most 60 degrees");
  LatticeMaterial material;
  // D in closed form: the target's own constants (the orthotropic ones where given; E and nu
  // are then the apparent constants along y that the UCS checks).
  material.elasticity = target.orthotropic
                            ? OrthotropicPlaneElasticity(*target.orthotropic, PlaneModel::kPlaneStrain)
                            : IsotropicPlaneElasticity(target.youngs_modulus_pa, target.poisson_ratio,
                                                       PlaneModel::kPlaneStrain);
  material.density_kg_per_m3 = target.density_kg_per_m3;
  // The friction angle is the target's when it gives one; otherwise it is free, and lowered
  // when the shear limit caps the Brazilian strength below the target's (LowerFrictionAngle).
  const bool friction_free = !target.friction_angle_deg.has_value();
  double phi_deg = summary.friction_angle_deg;
  // ln of (c, sigma_t of the triangles): the UCS's closed form and the target's sigma_t.
  Eigen::Vector2d p(std::log(target.ucs_pa / MohrCoulombUcsPerCohesion(phi_deg)),
                    std::log(target.tensile_strength_pa));
  const Eigen::Vector2d goal(std::log(target.ucs_pa), std::log(target.tensile_strength_pa));
  Eigen::Vector2d slopes(1.0, 1.0);  // d ln UCS / d ln c (not used for steps), d ln sigma_t(BTS) / d ln sigma_t
  Eigen::Vector2d previous_p = Eigen::Vector2d::Zero(), previous_m = Eigen::Vector2d::Zero();
  const double tau_c = std::log1p(options.tolerance_ucs), tau_t = std::log1p(options.tolerance_tensile);
  int first_round_at_phi = 1, lowerings = 0;
  bool ucs_on_tension = false;  // the UCS capped by the tension cut-off: stepped by sigma_t
  struct LogPoint {
    double log_sigma_t, log_strength;  // ln of the triangles' sigma_t and of the measured strength
    double log_c = 0.0;                // ln of the triangles' c (the Brazilian rounds)
  };
  std::vector<LogPoint> on_tension;  // the rounds stepped by sigma_t (c kept)
  std::vector<LogPoint> brazilian;   // this friction angle's rounds: sigma_t -> the Brazilian strength
  std::vector<double> ucs_offsets;   // this friction angle's rounds: ln UCS - ln c (- the map's ln UCS / c)
  // The map's start, where it covers the target; its ln(UCS / c) at (ln c, ln sigma_t) at the
  // present angle (0 without a map: the offsets are then ln UCS - ln c).
  const LatticeStrengthMap* map = nullptr;
  if (options.map) {
    std::string why;
    const std::vector<double>& angles = options.map->design.friction_angles_deg;
    if (target.orthotropic)
      summary.notes.push_back("the strength map holds isotropic rows; this orthotropic target starts from the closed form");
    else if (!options.map->Covers(target.poisson_ratio, &why))
      summary.notes.push_back("the strength map has " + why + "; the rounds start from the closed form");
    else if (target.friction_angle_deg &&
             (*target.friction_angle_deg < angles.front() || *target.friction_angle_deg > angles.back()))
      summary.notes.push_back("the strength map's friction angles are " + Number(angles.front()) + "-" +
                              Number(angles.back()) + " degrees, the target's " + Number(*target.friction_angle_deg) +
                              "; the rounds start from the closed form");
    else
      map = &*options.map;
  }
  auto map_log_ucs = [&](double log_c, double log_sigma_t) {
    return map ? std::log(map->At(target.poisson_ratio, phi_deg, std::exp(log_sigma_t - log_c)).ucs_over_cohesion)
               : 0.0;
  };
  // With a map: the ln c within a factor 3 of `around` at which the map's UCS, times the
  // specimen factor exp(offset), is the target's, at the triangles' ln sigma_t. ln c + ln(UCS / c)
  // rises with ln c while d ln(UCS / c) / d ln s < 1 (the UCS never falls as c rises), so the
  // root is bracketed and bisected; without a root, the end nearer it.
  auto solve_log_c = [&](double offset, double log_sigma_t, double around) {
    auto h = [&](double x) { return x + offset + map_log_ucs(x, log_sigma_t) - goal[0]; };
    double lo = around - std::log(3.0), hi = around + std::log(3.0);
    const double h_lo = h(lo), h_hi = h(hi);
    if (h_lo >= 0.0 || h_hi <= 0.0) return std::abs(h_lo) < std::abs(h_hi) ? lo : hi;
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      (h(mid) < 0.0 ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  };
  if (map) {
    const LatticeMapStart start = StartFromMap(*map, target);
    summary.map_used = true;
    summary.map_reachable = start.reachable;
    summary.map_ratio_low = start.ratio_low;
    summary.map_ratio_high = start.ratio_high;
    summary.notes.push_back("before round 1: " + start.statement);
    phi_deg = start.friction_angle_deg;
    p = Eigen::Vector2d(std::log(start.cohesion_pa), std::log(start.tensile_strength_pa));
    slopes[1] = std::clamp(start.tensile_slope, 0.5, 1.5);
    if (!start.reachable) summary.tensile_capped = true;  // the UCS alone is judged
  }
  // The nearest rounds on both sides of `goal` (the one below at the largest sigma_t, the one
  // above at the smallest), when they bracket it in sigma_t.
  struct Bracket {
    const LogPoint* below = nullptr;
    const LogPoint* above = nullptr;
    explicit operator bool() const { return below && above && below->log_sigma_t < above->log_sigma_t; }
  };
  auto bracket_of = [](const std::vector<LogPoint>& points, double goal_log) {
    Bracket b;
    for (const LogPoint& q : points) {
      if (q.log_strength < goal_log && (!b.below || q.log_sigma_t > b.below->log_sigma_t)) b.below = &q;
      if (q.log_strength > goal_log && (!b.above || q.log_sigma_t < b.above->log_sigma_t)) b.above = &q;
    }
    return b;
  };
  // The secant between a bracket's ends, kept a tenth of the bracket from either end.
  auto inside = [](const Bracket& b, double goal_log) {
    const double width = b.above->log_sigma_t - b.below->log_sigma_t;
    const double secant = b.below->log_sigma_t + (goal_log - b.below->log_strength) * width /
                                                     (b.above->log_strength - b.below->log_strength);
    return std::clamp(secant, b.below->log_sigma_t + 0.1 * width, b.above->log_sigma_t - 0.1 * width);
  };
  // The weighted error of a round: the UCS's, and sigma_t's unless it is given up.
  auto weighted_error = [&](const LatticeCalibrationRound& r) {
    return std::pow(std::log1p(r.error_ucs) / tau_c, 2) +
           (summary.tensile_capped ? 0.0 : std::pow(std::log1p(r.error_tensile) / tau_t, 2));
  };
  std::vector<LatticeMaterial> round_materials;
  // Once sigma_t is given up the UCS alone is judged: every round re-ranked.
  auto rerank = [&]() {
    for (LatticeCalibrationRound& k : summary.rounds) k.weighted_error = weighted_error(k);
    for (const LatticeCalibrationRound& k : summary.rounds)
      if (k.weighted_error < summary.rounds[summary.best_round - 1].weighted_error) {
        summary.best_round = k.round;
        summary.material = round_materials[k.round - 1];
      }
  };

  for (int round = 1; round <= options.max_rounds; ++round) {
    const auto round_start = std::chrono::steady_clock::now();
    material.strength = {std::exp(p[1]), std::exp(p[0]), phi_deg};
    if (options.progress)
      options.progress(static_cast<double>(round - 1) / options.max_rounds,
                       "lattice round " + std::to_string(round) + ": c " + Format("%.4g", material.strength.cohesion_pa) +
                           " Pa, sigma_t " + Format("%.4g", material.strength.tensile_strength_pa) + " Pa, phi " +
                           Format("%.3g", phi_deg) + " degrees");
    const LatticeRoundMeasurement u = measure(material, round);
    summary.critical_time_step_s = u.critical_time_step_s;
    LatticeCalibrationRound r;
    r.round = round;
    r.cohesion_pa = material.strength.cohesion_pa;
    r.tensile_strength_pa = material.strength.tensile_strength_pa;
    r.friction_angle_deg = phi_deg;
    r.ucs_pa = u.ucs_pa;
    r.bts_pa = u.bts_pa;
    r.youngs_modulus_pa = u.youngs_modulus_pa;
    r.poisson_ratio = u.poisson_ratio;
    r.error_ucs = r.ucs_pa / target.ucs_pa - 1.0;
    r.error_tensile = r.bts_pa / target.tensile_strength_pa - 1.0;
    r.error_youngs = r.youngs_modulus_pa / target.youngs_modulus_pa - 1.0;
    r.error_poisson = r.poisson_ratio / target.poisson_ratio - 1.0;
    const Eigen::Vector2d m(std::log(r.ucs_pa), std::log(r.bts_pa));
    r.weighted_error = weighted_error(r);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - round_start).count();
    summary.rounds.push_back(r);
    round_materials.push_back(material);
    if (summary.best_round == 0 || r.weighted_error < summary.rounds[summary.best_round - 1].weighted_error) {
      summary.best_round = round;
      summary.material = material;
    }
    if (std::abs(r.error_ucs) <= options.tolerance_ucs &&
        (summary.tensile_capped || std::abs(r.error_tensile) <= options.tolerance_tensile))
      break;
    // Each strength is stepped by its own triangle strength (the UCS by c, below; sigma_t by
    // its secant in logarithms: the slope measured between the last two rounds at this
    // friction angle where it moved, clamped to [0.5, 1.5], else 1: below the shear limit the
    // Brazilian strength is near proportional to sigma_t, on it it barely moves, and a flatter
    // secant across that knee would throw the step far past the target). Rounds on both
    // sides of the target Brazilian strength bracket the next sigma_t. A Brazilian strength
    // that no longer follows the triangles' sigma_t (a rise of 10 % or more moving it less
    // than 1 %) is capped by the shear limit at this friction angle.
    // Likewise a UCS that no longer follows c (a rise of 10 % or more raising it by less than
    // 1 %, or lowering it: the path noise of a capped peak) is capped by the tension cut-off: the specimen splits before the Mohr-Coulomb limit, and
    // UCS / sigma_t cannot rise further at this sigma_t.
    bool capped_now = false, ucs_capped_now = false;
    for (int k = 0; k < 2; ++k) {
      if (round > first_round_at_phi && std::abs(p[k] - previous_p[k]) > 1e-6) {
        const double slope = (m[k] - previous_m[k]) / (p[k] - previous_p[k]);
        const bool stalled = p[k] - previous_p[k] >= std::log(1.1) && std::abs(m[k] - previous_m[k]) < std::log(1.01);
        if (k == 1 && stalled && !summary.tensile_capped) capped_now = true;
        // (or rising less than a tenth as fast as c: Navajo sandstone's UCS rose 6 % as c
        // doubled, then fell as c tripled, one round later)
        const bool not_rising = p[k] - previous_p[k] >= std::log(1.1) &&
                                (m[k] - previous_m[k] < std::log(1.01) || slope < 0.1);
        if (k == 0 && not_rising && !ucs_on_tension) ucs_capped_now = true;
        slopes[k] = std::clamp(slope, 0.5, 1.5);
      }
    }
    if (round == first_round_at_phi) {
      brazilian.clear();
      ucs_offsets.clear();
    }
    brazilian.push_back({p[1], m[1], p[0]});
    ucs_offsets.push_back(m[0] - p[0] - map_log_ucs(p[0], p[1]));
    if (ucs_capped_now) {
      // The UCS is then reached through the triangles' sigma_t (slope 1: on the cut-off both
      // strengths scale with it), c kept where it is; the Brazilian strength follows sigma_t
      // too, so the target's sigma_t is given up (the UCS is honoured, as in the bonded
      // calibration's default).
      ucs_on_tension = true;
      summary.tensile_capped = true;
      summary.notes.push_back(
          "round " + std::to_string(round) + ": the UCS stays at " + Format("%.4g", r.ucs_pa / 1e6) +
          " MPa as c rises: the tension cut-off caps it (UCS / sigma_t " + Format("%.3g", r.ucs_pa / r.bts_pa) +
          " at most, " + Format("%.3g", target.StrengthRatio()) +
          " sought), so the UCS is reached through the triangles' sigma_t and sigma_t is given up");
      rerank();
      if (std::abs(r.error_ucs) <= options.tolerance_ucs) break;
      on_tension.push_back({p[1], m[0]});  // (at the c kept from now on)
      previous_p = p;
      previous_m = m;
      p[1] += std::clamp(goal[0] - m[0], -std::log(3.0), std::log(3.0));
      first_round_at_phi = round + 1;  // no secant across the switch
      continue;
    }
    if (capped_now && friction_free && lowerings < kMaxFrictionLowerings && phi_deg > kLowestFrictionAngle + 0.5) {
      // A lower friction angle lowers the cap relative to the UCS (LowerFrictionAngle); c
      // follows from the UCS at the new angle, with this specimen's ratio of the measured UCS
      // to the closed form carried over. Later rounds judge sigma_t as before.
      const double new_phi = LowerFrictionAngle(phi_deg, r.ucs_pa / r.bts_pa, target.StrengthRatio());
      const double specimen_factor = r.ucs_pa / (r.cohesion_pa * MohrCoulombUcsPerCohesion(phi_deg));
      summary.notes.push_back(
          "round " + std::to_string(round) + ": the Brazilian strength stays at " + Format("%.4g", r.bts_pa / 1e6) +
          " MPa as the triangles' sigma_t rises (UCS / sigma_t at least " + Format("%.3g", r.ucs_pa / r.bts_pa) +
          " at phi " + Format("%.3g", phi_deg) + " degrees, " + Format("%.3g", target.StrengthRatio()) +
          " sought): the shear limit caps it, so the friction angle is lowered to " + Format("%.3g", new_phi) +
          " degrees (the target gives none)");
      phi_deg = new_phi;
      ++lowerings;
      if (map)  // the specimen's factor over the map carried over, c from the map at the new angle
        p[0] = solve_log_c(ucs_offsets.back(), p[1], p[0]);
      else
        p[0] = std::log(target.ucs_pa / (specimen_factor * MohrCoulombUcsPerCohesion(phi_deg)));
      slopes = Eigen::Vector2d(1.0, 1.0);
      first_round_at_phi = round + 1;
      continue;
    }
    if (capped_now) {
      summary.tensile_capped = true;
      summary.notes.push_back("the Brazilian strength stays at " + Format("%.4g", r.bts_pa / 1e6) +
                              " MPa as the triangles' sigma_t rises: the shear limit (c, phi) caps it, and " +
                              Format("%.4g", target.tensile_strength_pa / 1e6) + " MPa is out of reach at " +
                              (friction_free ? "the lowest friction angle tried, " + Format("%.3g", phi_deg) +
                                                   " degrees"
                                             : "the target's friction angle") +
                              "; sigma_t is given up");
      // The UCS alone is judged from now on: re-rank every round.
      rerank();
    }
    if (summary.tensile_capped && std::abs(r.error_ucs) <= options.tolerance_ucs) break;  // the UCS alone is left
    if (ucs_on_tension) {  // the UCS's own secant against the triangles' sigma_t
      on_tension.push_back({p[1], m[0]});
      double slope = 1.0;
      if (round > first_round_at_phi && std::abs(p[1] - previous_p[1]) > 1e-6)
        slope = std::clamp((m[0] - previous_m[0]) / (p[1] - previous_p[1]), 0.2, 1.5);
      previous_p = p;
      previous_m = m;
      p[1] += std::clamp((goal[0] - m[0]) / slope, -std::log(3.0), std::log(3.0));
      // The UCS rises with sigma_t (c kept): rounds on both sides of the target bracket it, and
      // the next sigma_t is the secant between the nearest two, kept a tenth of the bracket
      // from its ends. Near the point where the specimen stops splitting first the UCS leaps
      // (Navajo sandstone: 155.9 MPa at sigma_t 19.9 MPa, 674 MPa at 27.3), and the clamped
      // secant of the last two rounds would step far outside.
      if (const Bracket b = bracket_of(on_tension, goal[0])) {
        const LogPoint* below = b.below;
        const LogPoint* above = b.above;
        const double width = above->log_sigma_t - below->log_sigma_t;
        p[1] = inside(b, goal[0]);
        // Two rounds in a row on the same side: the secant creeps towards a leap from one end
        // (regula falsi), so the bracket is halved instead (in logarithms).
        const size_t n = on_tension.size();
        if (n >= 2 && (on_tension[n - 1].log_strength < goal[0]) == (on_tension[n - 2].log_strength < goal[0]))
          p[1] = 0.5 * (below->log_sigma_t + above->log_sigma_t);
        // A bracket narrower than 1 % in sigma_t whose ends still differ by more than twice the
        // UCS's tolerance on each side of the target holds a leap, not a root: the target UCS
        // is out of reach at this c (Navajo: 174.9 MPa at 22.79 MPa, 266.1 MPa at 22.95 MPa).
        if (width < std::log(1.01) && goal[0] - below->log_strength > 2.0 * tau_c &&
            above->log_strength - goal[0] > 2.0 * tau_c) {
          summary.notes.push_back("the UCS leaps from " + Format("%.4g", std::exp(below->log_strength) / 1e6) +
                                  " to " + Format("%.4g", std::exp(above->log_strength) / 1e6) +
                                  " MPa between the triangles' sigma_t " +
                                  Format("%.4g", std::exp(below->log_sigma_t) / 1e6) + " and " +
                                  Format("%.4g", std::exp(above->log_sigma_t) / 1e6) + " MPa: " +
                                  Format("%.4g", target.ucs_pa / 1e6) +
                                  " MPa lies in the leap, out of reach; the rounds end");
          break;
        }
      }
      continue;
    }
    previous_p = p;
    previous_m = m;
    // c: the UCS is the triangles' closed form times a specimen factor with a path noise of a
    // few per cent (Nevada Test Site granite: 134.7 and 142.9 MPa at c 45.64 and 45.61 MPa),
    // so the factor is the mean of this angle's last three rounds (in logarithms) and c the
    // one that gives the target with it; a secant through two noisy rounds stepped c 10 %
    // past it. sigma_t: its secant.
    // With a map the factor is the UCS over the map's, and c is solved with the map's UCS / c
    // at the next sigma_t / c (the UCS moves with sigma_t / c where the tension cut-off
    // shares in the failure).
    const double round_log_c = p[0];
    double offset = 0.0;
    {
      const size_t n = std::min<size_t>(3, ucs_offsets.size());
      for (size_t i = ucs_offsets.size() - n; i < ucs_offsets.size(); ++i) offset += ucs_offsets[i] / n;
      p[0] += std::clamp(goal[0] - offset - map_log_ucs(p[0], p[1]) - p[0], -std::log(3.0), std::log(3.0));
    }
    if (!summary.tensile_capped)
      p[1] += std::clamp((goal[1] - m[1]) / slopes[1], -std::log(3.0), std::log(3.0));
    if (map) p[0] = solve_log_c(offset, p[1], round_log_c);
    // The bracket from the rounds at the next c (within 3 %): near the shear limit the
    // Brazilian strength moves with c too (Nevada Test Site granite: 11.58 MPa at c 43.0 MPa,
    // 12.48 MPa at 46.4 MPa, both at triangle sigma_t 17.17 MPa).
    if (!summary.tensile_capped) {
      std::vector<LogPoint> at_c;
      for (const LogPoint& q : brazilian)
        if (std::abs(q.log_c - p[0]) < std::log(1.03)) at_c.push_back(q);
      if (const Bracket b = bracket_of(at_c, goal[1])) p[1] = inside(b, goal[1]);
    }
    if (map) p[0] = solve_log_c(offset, p[1], round_log_c);
  }
  summary.friction_angle_deg = summary.material.strength.friction_angle_deg;
  const LatticeCalibrationRound& best = summary.rounds[summary.best_round - 1];
  summary.converged = std::abs(best.error_ucs) <= options.tolerance_ucs &&
                      (summary.tensile_capped || std::abs(best.error_tensile) <= options.tolerance_tensile) &&
                      std::abs(best.error_youngs) <= options.tolerance_youngs &&
                      std::abs(best.error_poisson) <= options.tolerance_poisson;
  summary.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

std::string LatticeCalibrationSummary::MaterialToml() const {
  std::ostringstream out;
  out.precision(10);
  const LatticeCalibrationRound& b = rounds[best_round - 1];
  out << "[material]\nmodel = \"lattice\"\n";
  if (target.orthotropic) {
    const OrthotropicConstants& o = *target.orthotropic;
    out << "youngs_modulus_1 = " << o.youngs_modulus_1_pa << "\nyoungs_modulus_2 = " << o.youngs_modulus_2_pa
        << "\npoisson_ratio_12 = " << o.poisson_ratio_12 << "\nshear_modulus_12 = " << o.shear_modulus_12_pa
        << "\naxis_angle = " << o.axis_angle_rad * 180.0 / kPi << "\n";
    if (o.youngs_modulus_3_pa > 0.0)
      out << "youngs_modulus_3 = " << o.youngs_modulus_3_pa << "\npoisson_ratio_13 = " << o.poisson_ratio_13
          << "\npoisson_ratio_23 = " << o.poisson_ratio_23 << "\n";
  } else {
    out << "youngs_modulus = " << target.youngs_modulus_pa << "\npoisson_ratio = " << target.poisson_ratio << "\n";
  }
  out << "plane_model = \"plane_strain\"\ntensile_strength = "
      << b.tensile_strength_pa << "\ncohesion = " << b.cohesion_pa << "\nfriction_angle = " << friction_angle_deg
      << "\ndensity = " << target.density_kg_per_m3 << "\n";
  return out.str();
}

std::string LatticeCalibrationSummary::FullReport() const {
  std::ostringstream out;
  char line[400];
  out << "Calibration of the six-spring lattice (2D, plane strain) to '" << target.name << "'\n";
  std::snprintf(line, sizeof line, "  target: E %.5g GPa, nu %.4g, UCS %.4g MPa, sigma_t %.4g MPa\n",
                target.youngs_modulus_pa / 1e9, target.poisson_ratio, target.ucs_pa / 1e6, target.tensile_strength_pa / 1e6);
  out << line;
  if (target.orthotropic) {
    const OrthotropicConstants& o = *target.orthotropic;
    std::snprintf(line, sizeof line,
                  "  orthotropic: E1 %.5g GPa, E2 %.5g GPa, nu12 %.4g, G12 %.5g GPa, axis 1 at %.4g degrees; E and nu "
                  "above are its apparent constants along the loading axis y (plane strain)\n",
                  o.youngs_modulus_1_pa / 1e9, o.youngs_modulus_2_pa / 1e9, o.poisson_ratio_12,
                  o.shear_modulus_12_pa / 1e9, o.axis_angle_rad * 180.0 / kPi);
    out << line;
  }
  out << "  specimens: UCS " << ucs_particles << " particles, Brazilian " << bts_particles << "\n"
      << "  E and nu are the lattice's inputs; the rounds fit the triangles' cohesion and tensile strength"
      << " (friction angle of the result " << friction_angle_deg << " degrees, "
      << (target.friction_angle_deg ? "the target's"
                                    : map_used ? "free: the map's start, lowered if the shear limit caps sigma_t"
                                               : "free: 30 unless the shear limit caps sigma_t")
      << ")\n";
  for (const LatticeCalibrationRound& r : rounds) {
    std::snprintf(line, sizeof line,
                  "  round %d%s: c %.4g MPa, sigma_t %.4g MPa, phi %.3g: UCS %.4g MPa (%+.2f %%), sigma_t %.4g MPa "
                  "(%+.2f %%); E %+.2f %%, nu %+.2f %%; %.0f s\n",
                  r.round, r.round == best_round ? " (best)" : "", r.cohesion_pa / 1e6, r.tensile_strength_pa / 1e6,
                  r.friction_angle_deg,
                  r.ucs_pa / 1e6, 100 * r.error_ucs, r.bts_pa / 1e6, 100 * r.error_tensile, 100 * r.error_youngs,
                  100 * r.error_poisson, r.seconds);
    out << line;
  }
  for (const std::string& note : notes) out << "  note: " << note << "\n";
  out << "  converged: " << (converged ? "yes" : "no") << (tensile_capped ? " (sigma_t given up)" : "") << "; critical time step of the UCS "
      << Format("%.4g", critical_time_step_s) << " s; wall time " << Format("%.1f", wall_seconds) << " s\n";
  return out.str();
}

std::string LatticeCalibrationSummary::BriefReport() const {
  const LatticeCalibrationRound& b = rounds[best_round - 1];
  char line[300];
  std::snprintf(line, sizeof line,
                "2D lattice calibration to '%s': E %+.2f %%, nu %+.2f %%, UCS %+.2f %%, sigma_t %+.2f %% (round %d of "
                "%zu); %s; %.1f s",
                target.name.c_str(), 100 * b.error_youngs, 100 * b.error_poisson, 100 * b.error_ucs,
                100 * b.error_tensile, best_round, rounds.size(), converged ? "converged" : "NOT converged",
                wall_seconds);
  return line;
}

nlohmann::json LatticeCalibrationSummary::ToJson() const {
  nlohmann::json j;
  j["model"] = "lattice";
  j["target"] = TargetMaterialToJson(target);
  j["friction_angle_deg"] = friction_angle_deg;
  j["converged"] = converged;
  j["given_up"] = tensile_capped ? nlohmann::json::array({"sigma_t"}) : nlohmann::json::array();
  j["notes"] = notes;
  j["map"] = {{"used", map_used}};
  if (map_used)
    j["map"].update({{"reachable", map_reachable}, {"ratio_low", map_ratio_low}, {"ratio_high", map_ratio_high}});
  j["best_round"] = best_round;
  j["critical_time_step_s"] = critical_time_step_s;
  j["wall_time_s"] = wall_seconds;
  j["specimens"] = {{"ucs_particles", ucs_particles}, {"bts_particles", bts_particles}};
  for (const LatticeCalibrationRound& r : rounds)
    j["rounds"].push_back({{"round", r.round}, {"cohesion_pa", r.cohesion_pa},
                           {"friction_angle_deg", r.friction_angle_deg},
                           {"tensile_strength_pa", r.tensile_strength_pa}, {"ucs_pa", r.ucs_pa}, {"bts_pa", r.bts_pa},
                           {"youngs_modulus_pa", r.youngs_modulus_pa}, {"poisson_ratio", r.poisson_ratio},
                           {"relative_errors",
                            {{"youngs_modulus", r.error_youngs}, {"poisson_ratio", r.error_poisson},
                             {"ucs", r.error_ucs}, {"tensile_strength", r.error_tensile}}},
                           {"wall_time_s", r.seconds}});
  return j;
}

}  // namespace specimen
