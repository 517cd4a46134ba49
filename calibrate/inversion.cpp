#include "calibrate/inversion.h"

#include <nlopt.hpp>

#include <algorithm>
#include <functional>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "common/error.h"

namespace specimen {
namespace {

Eigen::VectorXd ToEigen(const std::vector<double>& x) {
  return Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size()));
}

int IndexOf(const MapSet& maps, MicroRatio ratio) {
  for (size_t k = 0; k < maps.inputs.size(); ++k)
    if (maps.inputs[k] == ratio) return static_cast<int>(k);
  return -1;
}

// Deterministic, well-spread starting points in the box (a Kronecker / golden-ratio sequence).
std::vector<double> StartPoint(const Eigen::VectorXd& lower, const Eigen::VectorXd& upper, int index) {
  static const double kGenerators[5] = {0.6180339887498949, 0.7548776662466927, 0.5698402909980532,
                                        0.8191725133961645, 0.4142135623730950};
  std::vector<double> x(lower.size());
  for (int k = 0; k < lower.size(); ++k) {
    const double fraction = index == 0 ? 0.5 : std::fmod(0.5 + index * kGenerators[k % 5], 1.0);
    x[k] = lower[k] + fraction * (upper[k] - lower[k]);
  }
  return x;
}

struct Problem {
  const MapSet* maps;
  double target_poisson;
  double target_ratio;
  double poisson_weight;
  double ratio_weight;
  double sign = 1.0;  // -1: maximise the strength ratio instead (reach study)
};

double StrengthRatio(const MapSet& maps, const Eigen::VectorXd& x, Eigen::VectorXd* gradient) {
  const double c = maps.compressive_group.Evaluate(x), t = maps.tensile_group.Evaluate(x);
  if (gradient)
    *gradient = (maps.compressive_group.Gradient(x) * t - c * maps.tensile_group.Gradient(x)) / (t * t);
  return c / t;
}

double Objective(const std::vector<double>& xs, std::vector<double>& grad, void* data) {
  const Problem& p = *static_cast<const Problem*>(data);
  const Eigen::VectorXd x = ToEigen(xs);
  Eigen::VectorXd ratio_gradient;
  const double ratio = StrengthRatio(*p.maps, x, grad.empty() ? nullptr : &ratio_gradient);
  if (p.sign < 0.0) {  // reach study: maximise sigma_c / sigma_t
    if (!grad.empty())
      for (size_t k = 0; k < xs.size(); ++k) grad[k] = -ratio_gradient[k];
    return -ratio;
  }
  const double nu = p.maps->poisson_ratio.Evaluate(x);
  const double e_nu = nu / p.target_poisson - 1.0;
  const double e_ratio = ratio / p.target_ratio - 1.0;
  if (!grad.empty()) {
    const Eigen::VectorXd nu_gradient = p.maps->poisson_ratio.Gradient(x);
    for (size_t k = 0; k < xs.size(); ++k)
      grad[k] = 2.0 * p.poisson_weight * e_nu * nu_gradient[k] / p.target_poisson +
                2.0 * p.ratio_weight * e_ratio * ratio_gradient[k] / p.target_ratio;
  }
  return p.poisson_weight * e_nu * e_nu + p.ratio_weight * e_ratio * e_ratio;
}

struct Constraint {
  const MapSet* maps;
  const InversionOptions* options;
  int compliance_index;
  int poisson_index;
};

// kn/(Ep l) - admissible(nu_p) <= 0.
double StabilityConstraint(const std::vector<double>& xs, std::vector<double>& grad, void* data) {
  const Constraint& c = *static_cast<const Constraint*>(data);
  const MicroRatios r = c.maps->RatiosAt(xs);
  const auto& admissible = c.options->admissible_particle_compliance;
  const double value = r.normal_stiffness_to_particle - admissible(r.particle_poisson_ratio);
  if (!grad.empty()) {
    std::fill(grad.begin(), grad.end(), 0.0);
    grad[c.compliance_index] = 1.0;
    if (c.poisson_index >= 0) {
      const double h = 1e-6;
      grad[c.poisson_index] = -(admissible(r.particle_poisson_ratio + h) -
                                admissible(r.particle_poisson_ratio - h)) / (2 * h);
    }
  }
  return value;
}

struct Optimum {
  std::vector<double> x;
  double value = std::numeric_limits<double>::infinity();
};

Optimum Minimise(const MapSet& maps, Problem problem, const InversionOptions& options) {
  const int n = static_cast<int>(maps.inputs.size());
  const Eigen::VectorXd lower = maps.Lower(), upper = maps.Upper();
  Optimum best;
  Constraint constraint{&maps, &options, IndexOf(maps, MicroRatio::kParticleCompliance),
                        IndexOf(maps, MicroRatio::kParticlePoisson)};
  for (int s = 0; s < std::max(1, options.starts); ++s) {
    nlopt::opt opt(nlopt::LD_SLSQP, static_cast<unsigned>(n));
    opt.set_lower_bounds(std::vector<double>(lower.data(), lower.data() + n));
    opt.set_upper_bounds(std::vector<double>(upper.data(), upper.data() + n));
    opt.set_min_objective(Objective, &problem);
    if (options.admissible_particle_compliance && constraint.compliance_index >= 0)
      opt.add_inequality_constraint(StabilityConstraint, &constraint, 1e-10);
    opt.set_xtol_rel(1e-10);
    opt.set_ftol_abs(1e-16);
    opt.set_maxeval(500);
    std::vector<double> x = StartPoint(lower, upper, s);
    if (constraint.compliance_index >= 0 && options.admissible_particle_compliance) {
      // Start feasible: within the stability bound.
      const MicroRatios r = maps.RatiosAt(x);
      x[constraint.compliance_index] =
          std::min(x[constraint.compliance_index],
                   std::max(lower[constraint.compliance_index],
                            0.5 * options.admissible_particle_compliance(r.particle_poisson_ratio)));
    }
    double value = 0.0;
    try {
      opt.optimize(x, value);
    } catch (const std::exception&) {
      std::vector<double> empty;
      value = Objective(x, empty, &problem);  // roundoff-limited stop: keep the point reached
    }
    if (constraint.compliance_index >= 0 && options.admissible_particle_compliance) {
      std::vector<double> empty;
      if (StabilityConstraint(x, empty, &constraint) > 1e-9) continue;  // infeasible end point
    }
    if (value < best.value) best = {x, value};
  }
  if (best.x.empty()) throw ComputationError("the inversion found no point that satisfies the stability bound");
  return best;
}

std::string Percent(double relative) {
  char text[32];
  std::snprintf(text, sizeof(text), "%+.2f %%", 100.0 * relative);
  return text;
}

}  // namespace

std::string MicroRatioName(MicroRatio ratio) {
  switch (ratio) {
    case MicroRatio::kStiffnessRatio: return "kt/kn";
    case MicroRatio::kStrengthRatio: return "Rt/Rn";
    case MicroRatio::kFriction: return "mu";
    case MicroRatio::kParticleCompliance: return "kn/(Ep l)";
    case MicroRatio::kParticlePoisson: return "nu_p";
  }
  return "?";
}

Eigen::VectorXd MapSet::Lower() const {
  return poisson_ratio.lower().cwiseMin(compressive_group.lower());
}

Eigen::VectorXd MapSet::Upper() const {
  return poisson_ratio.upper().cwiseMax(compressive_group.upper());
}

MicroRatios MapSet::RatiosAt(const std::vector<double>& x) const {
  MicroRatios r = fixed;
  for (size_t k = 0; k < inputs.size(); ++k) {
    switch (inputs[k]) {
      case MicroRatio::kStiffnessRatio: r.tangential_to_normal_stiffness = x[k]; break;
      case MicroRatio::kStrengthRatio: r.shear_to_tensile_strength = x[k]; break;
      case MicroRatio::kFriction: r.friction_coefficient = x[k]; break;
      case MicroRatio::kParticleCompliance: r.normal_stiffness_to_particle = x[k]; break;
      case MicroRatio::kParticlePoisson: r.particle_poisson_ratio = x[k]; break;
    }
  }
  return r;
}

std::vector<double> MapSet::InputsOf(const MicroRatios& r) const {
  std::vector<double> x;
  for (MicroRatio input : inputs) {
    switch (input) {
      case MicroRatio::kStiffnessRatio: x.push_back(r.tangential_to_normal_stiffness); break;
      case MicroRatio::kStrengthRatio: x.push_back(r.shear_to_tensile_strength); break;
      case MicroRatio::kFriction: x.push_back(r.friction_coefficient); break;
      case MicroRatio::kParticleCompliance: x.push_back(r.normal_stiffness_to_particle); break;
      case MicroRatio::kParticlePoisson: x.push_back(r.particle_poisson_ratio); break;
    }
  }
  return x;
}

InversionResult InvertMaps(const MapSet& maps, const PackingDescriptors& packing,
                           const TargetMaterial& target, const InversionOptions& options) {
  std::string error;
  if (!target.IsValid(&error)) throw InputError(error);
  if (maps.inputs.empty()) throw InputError("the maps have no varying micro ratio to invert");
  Problem problem{&maps, target.poisson_ratio, target.StrengthRatio(), options.poisson_weight,
                  options.strength_ratio_weight};
  if (std::abs(target.poisson_ratio) < 1e-6)
    throw InputError("poisson_ratio = 0 cannot be matched in relative terms; give a small non-zero value");
  const Optimum best = Minimise(maps, problem, options);
  const Eigen::VectorXd x = ToEigen(best.x);

  InversionResult result;
  result.ratios = maps.RatiosAt(best.x);
  const double nu = maps.poisson_ratio.Evaluate(x);
  const double psi_e = maps.elastic_group.Evaluate(x);
  const double psi_c = maps.compressive_group.Evaluate(x);
  const double psi_t = maps.tensile_group.Evaluate(x);
  if (!(psi_e > 0.0) || !(psi_c > 0.0) || !(psi_t > 0.0))
    throw ComputationError("the maps give a non-positive group at the solution; the sweep does not cover it");

  // Scale: E ~ kn, strengths ~ Rn at fixed ratios.
  result.normal_stiffness = NormalStiffnessFromElasticGroup(packing, target.youngs_modulus_pa, psi_e);
  result.tangential_stiffness = result.ratios.tangential_to_normal_stiffness * result.normal_stiffness;
  result.poisson_ratio = nu;
  result.youngs_modulus = target.youngs_modulus_pa;
  const double ratio = psi_c / psi_t;
  result.error_poisson = nu / target.poisson_ratio - 1.0;
  result.poisson_reached = std::abs(result.error_poisson) <= options.relative_tolerance;
  result.strength_ratio_reached = std::abs(ratio / target.StrengthRatio() - 1.0) <= options.relative_tolerance;
  result.honoured = options.honour;
  if (result.strength_ratio_reached || options.honour == HonouredStrength::kCompressive)
    result.bond_tensile_strength = BondStrengthFromStrengthGroup(packing, target.ucs_pa, psi_c);
  else
    result.bond_tensile_strength = BondStrengthFromStrengthGroup(packing, target.tensile_strength_pa, psi_t);
  result.bond_shear_strength = result.ratios.shear_to_tensile_strength * result.bond_tensile_strength;
  const double solid = packing.SolidCoordination() / packing.CharacteristicArea();
  result.ucs = psi_c * result.bond_tensile_strength * solid;
  result.tensile_strength = psi_t * result.bond_tensile_strength * solid;
  result.error_ucs = result.ucs / target.ucs_pa - 1.0;
  result.error_tensile = result.tensile_strength / target.tensile_strength_pa - 1.0;
  if (result.ratios.normal_stiffness_to_particle > 0.0)
    result.particle_youngs_modulus = result.normal_stiffness / result.ratios.normal_stiffness_to_particle;

  if (!result.strength_ratio_reached) {
    Problem reach = problem;
    reach.sign = -1.0;
    const Optimum most = Minimise(maps, reach, options);
    char note[400];
    const bool alone = -most.value >= target.StrengthRatio();
    std::snprintf(note, sizeof(note),
                  "sigma_c / sigma_t = %.3f is not reachable%s: the largest ratio the maps give on this "
                  "packing is %.3f%s; Rn was taken from the %s strength, the other is off by %s",
                  target.StrengthRatio(), alone ? " together with nu" : "", -most.value,
                  alone ? " (at another kt/kn)" : "",
                  result.honoured == HonouredStrength::kCompressive ? "compressive" : "tensile",
                  Percent(result.honoured == HonouredStrength::kCompressive ? result.error_tensile
                                                                            : result.error_ucs).c_str());
    result.notes.push_back(note);
  }
  if (!result.poisson_reached) {
    char note[300];
    std::snprintf(note, sizeof(note),
                  "nu = %.4f is not reachable with these maps (closest %.4f, %s) within the stability bound",
                  target.poisson_ratio, nu, Percent(result.error_poisson).c_str());
    result.notes.push_back(note);
  }
  return result;
}

nlohmann::json InversionResult::ToJson() const {
  nlohmann::json j;
  j["ratios"] = {{"kt_over_kn", ratios.tangential_to_normal_stiffness},
                 {"rt_over_rn", ratios.shear_to_tensile_strength},
                 {"friction", ratios.friction_coefficient},
                 {"kn_over_ep_l", ratios.normal_stiffness_to_particle},
                 {"particle_poisson_ratio", ratios.particle_poisson_ratio}};
  j["parameters"] = {{"normal_stiffness_n_per_m", normal_stiffness},
                     {"tangential_stiffness_n_per_m", tangential_stiffness},
                     {"bond_tensile_strength_n", bond_tensile_strength},
                     {"bond_shear_strength_n", bond_shear_strength},
                     {"particle_youngs_modulus_pa", particle_youngs_modulus}};
  j["predicted"] = {{"youngs_modulus_pa", youngs_modulus}, {"poisson_ratio", poisson_ratio},
                    {"ucs_pa", ucs}, {"tensile_strength_pa", tensile_strength}};
  j["relative_errors"] = {{"youngs_modulus", error_youngs}, {"poisson_ratio", error_poisson},
                          {"ucs", error_ucs}, {"tensile_strength", error_tensile}};
  j["strength_ratio_reached"] = strength_ratio_reached;
  j["poisson_reached"] = poisson_reached;
  j["honoured"] = honoured == HonouredStrength::kCompressive ? "compressive" : "tensile";
  j["notes"] = notes;
  return j;
}

std::string InversionResult::FullReport() const {
  std::ostringstream out;
  char line[200];
  out << "Map inversion\n";
  std::snprintf(line, sizeof(line), "  kt/kn %.5g, Rt/Rn %.5g, mu %.4g, kn/(Ep l) %.5g, nu_p %.4g\n",
                ratios.tangential_to_normal_stiffness, ratios.shear_to_tensile_strength,
                ratios.friction_coefficient, ratios.normal_stiffness_to_particle,
                ratios.particle_poisson_ratio);
  out << line;
  std::snprintf(line, sizeof(line), "  kn %.6g N/m, kt %.6g N/m, Rn %.6g N, Rt %.6g N, Ep %s\n",
                normal_stiffness, tangential_stiffness, bond_tensile_strength, bond_shear_strength,
                particle_youngs_modulus > 0 ? (std::to_string(particle_youngs_modulus) + " Pa").c_str()
                                            : "rigid");
  out << line;
  std::snprintf(line, sizeof(line),
                "  predicted: E %s, nu %s, UCS %s, sigma_t %s (relative to the target)\n",
                Percent(error_youngs).c_str(), Percent(error_poisson).c_str(),
                Percent(error_ucs).c_str(), Percent(error_tensile).c_str());
  out << line;
  for (const auto& note : notes) out << "  note: " << note << "\n";
  return out.str();
}

namespace {

// A measured quantity of a verification round and the ratios it was measured at.
struct MeasuredRound {
  MicroRatios ratios;
  double value = 0.0;
};

// One lever of a verification correction: moves `field` of c->next to remove `share` of the
// last round's error in a measured quantity (Newton step along that input); returns the
// share the box did not let it remove (0: all of it). The slope is the secant of the last two
// rounds when only this input moved between them and it agrees in sign with the maps'
// `map_slope` (at the current point), else the maps' slope; a step is at most half the box.
double MoveLever(const MapSet& maps, const std::vector<MeasuredRound>& history, double target,
                 double share, MicroRatio input, double MicroRatios::*field,
                 const std::function<double(const Eigen::VectorXd& x, int k)>& map_slope,
                 PoissonCorrection* c) {
  int k = -1;
  for (size_t i = 0; i < maps.inputs.size(); ++i)
    if (maps.inputs[i] == input) k = static_cast<int>(i);
  if (k < 0) return share;
  auto at = [&](const MicroRatios& r) {
    const std::vector<double> x = maps.InputsOf(r);
    return Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size())).eval();
  };
  const MeasuredRound& now = history.back();
  double slope = map_slope(at(c->next), k);
  if (history.size() >= 2) {
    const MeasuredRound& before = history[history.size() - 2];
    const Eigen::VectorXd moved = at(now.ratios) - at(before.ratios);
    bool only_this = std::abs(moved[k]) > 1e-6;
    for (Eigen::Index i = 0; i < moved.size(); ++i)
      if (i != k && std::abs(moved[i]) > 1e-9) only_this = false;
    if (only_this) {
      const double secant = (now.value - before.value) / moved[k];
      if (secant * slope > 0.0) slope = secant;
    }
  }
  if (std::abs(slope) <= 1e-9) return share;
  const Eigen::VectorXd lower = maps.Lower(), upper = maps.Upper();
  const double half_box = 0.5 * (upper[k] - lower[k]);
  const double step = std::clamp(share * (target - now.value) / slope, -half_box, half_box);
  const double from = c->next.*field;
  std::vector<double> x = maps.InputsOf(c->next);
  x[k] = std::clamp(x[k] + step, lower[k], upper[k]);
  c->next = maps.RatiosAt(x);
  const double taken = c->next.*field - from;
  std::ostringstream what;
  what << MicroRatioName(input) << " " << from << " -> " << c->next.*field << "; ";
  c->what += what.str();
  return share * std::clamp(1.0 - taken / step, 0.0, 1.0);
}

}  // namespace

PoissonCorrection CorrectPoisson(const MapSet& maps, const std::vector<PoissonRound>& history,
                                 double target_poisson) {
  if (history.empty()) throw std::invalid_argument("CorrectPoisson: no round to correct");
  std::vector<MeasuredRound> measured;
  for (const PoissonRound& r : history) measured.push_back({r.ratios, r.poisson_ratio});
  auto slope = [&](const Eigen::VectorXd& x, int k) { return maps.poisson_ratio.Gradient(x)[k]; };
  PoissonCorrection c;
  c.next = history.back().ratios;
  const double left = MoveLever(maps, measured, target_poisson, 1.0, MicroRatio::kStiffnessRatio,
                                &MicroRatios::tangential_to_normal_stiffness, slope, &c);
  c.unremoved_share = left;
  if (left > 0.5)
    c.unremoved_share = MoveLever(maps, measured, target_poisson, left, MicroRatio::kParticleCompliance,
                                  &MicroRatios::normal_stiffness_to_particle, slope, &c);
  return c;
}

PoissonCorrection CorrectStrengthRatio(const MapSet& maps, const MicroRatios& next,
                                       const std::vector<StrengthRatioRound>& history,
                                       double target_ratio) {
  if (history.empty()) throw std::invalid_argument("CorrectStrengthRatio: no round to correct");
  if (!(target_ratio > 0.0)) throw std::invalid_argument("CorrectStrengthRatio: target ratio <= 0");
  // In logarithms: the ratio of the two strength groups differs from sigma_c / sigma_t by the
  // specimens' descriptors only (a constant factor), so d ln(ratio) is the maps'.
  std::vector<MeasuredRound> measured;
  for (const StrengthRatioRound& r : history) measured.push_back({r.ratios, std::log(r.strength_ratio)});
  auto slope = [&](const Eigen::VectorXd& x, int k) {
    return maps.compressive_group.Gradient(x)[k] / maps.compressive_group.Evaluate(x) -
           maps.tensile_group.Gradient(x)[k] / maps.tensile_group.Evaluate(x);
  };
  PoissonCorrection c;
  c.next = next;
  c.unremoved_share = MoveLever(maps, measured, std::log(target_ratio), 1.0, MicroRatio::kStrengthRatio,
                                &MicroRatios::shear_to_tensile_strength, slope, &c);
  return c;
}

}  // namespace specimen
