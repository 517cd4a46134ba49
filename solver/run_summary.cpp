#include "solver/run_summary.h"
#include "common/format.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

namespace specimen {

bool RunOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (max_steps < 0)
    return fail("max_steps = " + std::to_string(max_steps) + " is not allowed: it must be >= 0");
  if (!(duration_s >= 0.0) || !std::isfinite(duration_s))
    return fail("duration_s = " + Number(duration_s) +
                " is not allowed: it must be finite and >= 0");
  if (max_steps == 0 && duration_s == 0.0)
    return fail("a run needs a bound: max_steps > 0 or duration_s > 0");
  if (!(static_force_ratio >= 0.0) || !std::isfinite(static_force_ratio))
    return fail("static_force_ratio = " + Number(static_force_ratio) +
                " is not allowed: it must be finite and >= 0 (0 = no static stop)");
  if (static_check_interval < 1)
    return fail("static_check_interval = " + std::to_string(static_check_interval) +
                " is not allowed: it must be >= 1");
  if (min_steps < 0)
    return fail("min_steps = " + std::to_string(min_steps) + " is not allowed: it must be >= 0");
  if (observe_interval < 0)
    return fail("observe_interval = " + std::to_string(observe_interval) +
                " is not allowed: it must be >= 0");
  return true;
}

const char* TerminationReasonName(TerminationReason reason) {
  switch (reason) {
    case TerminationReason::kStepLimit:
      return "step limit";
    case TerminationReason::kDuration:
      return "duration";
    case TerminationReason::kStatic:
      return "static";
    case TerminationReason::kDiverged:
      return "diverged";
  }
  return "unknown";
}

namespace {

std::string Join(const std::vector<std::string>& names) {
  std::string out;
  for (size_t k = 0; k < names.size(); ++k) out += (k ? ", " : "") + names[k];
  return out.empty() ? "(none)" : out;
}

std::string FormatVector(const std::vector<double>& v) {
  std::ostringstream out;
  out.precision(6);
  out << "(";
  for (size_t k = 0; k < v.size(); ++k) out << (k ? ", " : "") << v[k];
  out << ")";
  return out.str();
}

}  // namespace

std::string RunSummary::BriefReport() const {
  char line[320];
  std::snprintf(line, sizeof(line),
                "%dD run: %ld steps of %.4g s to t = %.6g s, %d particles, %d/%d bonds intact, "
                "energy imbalance %.3g %%, %s",
                dimension, steps, time_step_s, end_time_s, particles, bonds_intact, bonds_created,
                100.0 * energy.RelativeImbalance(), TerminationReasonName(termination));
  return line;
}

std::string RunSummary::FullReport() const {
  std::ostringstream out;
  char line[320];
  std::snprintf(line, sizeof(line), "DDEM solver run (%dD), particles %s\n", dimension,
                particle_model.c_str());
  out << line;
  std::snprintf(line, sizeof(line),
                "  steps %ld (from step %ld), time %.6g -> %.6g s\n"
                "  time step %.6g s (%s); critical %.6g s (%s), per-particle bound %.6g s, "
                "guaranteed %.6g s, limiting particle %d%s\n",
                steps, first_step, start_time_s, end_time_s, time_step_s,
                time_step_given_s > 0.0 ? "given" : "safety factor x critical",
                critical_time_step.critical_time_step_s, critical_time_step.method.c_str(),
                critical_time_step.per_particle_bound_s, critical_time_step.guaranteed_bound_s,
                critical_time_step.limiting_particle,
                time_step_above_critical ? "; ABOVE the critical time step (forced)" : "");
  out << line;
  if (critical_time_step.ddem_lag_factor != 1.0) {
    std::snprintf(
        line, sizeof(line),
        "  DDEM strain-lag factor of the default step %.4f (iteration ratio estimate %.4f)\n",
        critical_time_step.ddem_lag_factor, critical_time_step.ddem_ratio_estimate);
    out << line;
  }
  out << "  stages run: " << Join(stages) << "\n";
  out << "  stages left out: " << Join(omitted_stages) << "\n";
  std::snprintf(line, sizeof(line),
                "  particles %d, contact records %d (%d loaded), neighbour searches %ld\n"
                "  bonds: created %d (%d listed pairs outside the gap tolerance), intact %d; "
                "broken in tension %ld (%ld this run), in shear %ld (%ld this run)\n"
                "  unbalanced force ratio %.3e\n",
                particles, contacts, loaded_contacts, neighbour_searches, bonds_created,
                packing_pairs_not_bonded, bonds_intact, broken_in_tension,
                broken_in_tension_this_run, broken_in_shear, broken_in_shear_this_run,
                unbalanced_force_ratio);
  out << line;
  for (const WallReport& w : walls)
    out << "  wall \"" << w.name << "\": point " << FormatVector(w.point_m) << " m, force on wall "
        << FormatVector(w.force_on_wall_n) << " N, normal reaction " << w.normal_reaction_n
        << " N, " << w.touching_particles << " particles touching\n";
  for (const ConstraintReport& c : fixed_dofs)
    out << "  fixed dofs \"" << c.name << "\": reaction " << FormatVector(c.reaction_force_n)
        << " N\n";
  out << "  energy balance:\n" << energy.Table("    ");
  std::snprintf(line, sizeof(line),
                "  wall time %.3f s, %.3g particle-steps/s, state %.1f bytes per particle\n",
                wall_seconds, particle_steps_per_second,
                particles > 0 ? static_cast<double>(memory_bytes) / particles : 0.0);
  out << line;
  out << "  termination: " << TerminationReasonName(termination) << ": " << termination_message
      << "\n";
  return out.str();
}

nlohmann::json RunSummary::ToJson() const {
  nlohmann::json j;
  j["dimension"] = dimension;
  j["particle_model"] = particle_model;
  j["first_step"] = first_step;
  j["steps"] = steps;
  j["start_time_s"] = start_time_s;
  j["end_time_s"] = end_time_s;
  j["time_step_given_s"] = time_step_given_s;
  j["time_step_s"] = time_step_s;
  j["critical_time_step"] = {
      {"critical_time_step_s", critical_time_step.critical_time_step_s},
      {"per_particle_bound_s", critical_time_step.per_particle_bound_s},
      {"guaranteed_bound_s", critical_time_step.guaranteed_bound_s},
      {"dashpot_factor", critical_time_step.dashpot_factor},
      {"local_damping_factor", critical_time_step.local_damping_factor},
      {"ddem_ratio_estimate", critical_time_step.ddem_ratio_estimate},
      {"ddem_lag_factor", critical_time_step.ddem_lag_factor},
      {"limiting_particle", critical_time_step.limiting_particle},
      {"limiting_stiffness_n_per_m", critical_time_step.limiting_stiffness_n_per_m},
      {"method", critical_time_step.method}};
  j["time_step_above_critical"] = time_step_above_critical;
  j["stages"] = stages;
  j["omitted_stages"] = omitted_stages;
  j["particles"] = particles;
  j["contacts"] = contacts;
  j["loaded_contacts"] = loaded_contacts;
  j["bonds_created"] = bonds_created;
  j["packing_pairs_not_bonded"] = packing_pairs_not_bonded;
  j["bonds_intact"] = bonds_intact;
  j["broken_in_tension"] = broken_in_tension;
  j["broken_in_shear"] = broken_in_shear;
  j["broken_in_tension_this_run"] = broken_in_tension_this_run;
  j["broken_in_shear_this_run"] = broken_in_shear_this_run;
  j["neighbour_searches"] = neighbour_searches;
  j["unbalanced_force_ratio"] = unbalanced_force_ratio;
  j["energy"] = energy.ToJson();
  j["walls"] = nlohmann::json::array();
  for (const WallReport& w : walls)
    j["walls"].push_back({{"name", w.name},
                          {"point_m", w.point_m},
                          {"force_on_wall_n", w.force_on_wall_n},
                          {"normal_reaction_n", w.normal_reaction_n},
                          {"touching_particles", w.touching_particles}});
  j["fixed_dofs"] = nlohmann::json::array();
  for (const ConstraintReport& c : fixed_dofs)
    j["fixed_dofs"].push_back({{"name", c.name}, {"reaction_force_n", c.reaction_force_n}});
  j["termination"] = TerminationReasonName(termination);
  j["termination_message"] = termination_message;
  j["wall_seconds"] = wall_seconds;
  j["particle_steps_per_second"] = particle_steps_per_second;
  j["memory_bytes"] = memory_bytes;
  return j;
}

}  // namespace specimen
