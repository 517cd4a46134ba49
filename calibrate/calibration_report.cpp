// CalibrationSummary's reports: the one-line brief, the full text report and the JSON
// (calibration.h).
#include <cstdio>
#include <sstream>
#include <utility>

#include <nlohmann/json.hpp>

#include "calibrate/calibration.h"
#include "common/unit_names.h"
#include "specimen_version.h"

namespace specimen {
namespace {

std::string Percent(double relative) {
  char text[32];
  std::snprintf(text, sizeof(text), "%+.2f %%", 100.0 * relative);
  return text;
}

std::string Num(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

nlohmann::json RatiosJson(const MicroRatios& r) {
  return {{"kt_over_kn", r.tangential_to_normal_stiffness},
          {"rt_over_rn", r.shear_to_tensile_strength},
          {"friction", r.friction_coefficient},
          {"kn_over_ep_l", r.normal_stiffness_to_particle},
          {"particle_poisson_ratio", r.particle_poisson_ratio}};
}

// The packing descriptors with their units in the names; the stored maps keep the names of
// DescriptorsToJson (dimensionless_groups.h), which old map files are read by.
nlohmann::json DescriptorsReportJson(const PackingDescriptors& d) {
  nlohmann::json j = DescriptorsToJson(d);
  for (const auto& [stored, reported] : {std::pair<const char*, const char*>{"mean_radius", "mean_radius_m"},
                                         {"mean_radius_squared", "mean_radius_squared_m2"},
                                         {"mean_radius_cubed", "mean_radius_cubed_m3"},
                                         {"mean_branch_length", "mean_branch_length_m"},
                                         {"mean_branch_length_squared", "mean_branch_length_squared_m2"}}) {
    j[reported] = j.at(stored);
    j.erase(stored);
  }
  return j;
}

}  // namespace

std::string CalibrationSummary::BriefReport() const {
  char line[480];
  if (rounds.empty()) return "calibration: no strength round run\n";
  if (best_round < 1) {
    std::snprintf(line, sizeof(line),
                  "%dD %s calibration to '%s': no result, every strength round failed (%zu rounds, %zu elastic "
                  "runs); NOT converged; %.1f s",
                  dimension, model_used.c_str(), target.name.c_str(), rounds.size(), solution.elastic_runs.size(),
                  seconds);
    return line;
  }
  const VerificationRound& v = rounds[best_round - 1];
  std::snprintf(line, sizeof(line),
                "%dD %s calibration to '%s': E %s, nu %s, UCS %s, sigma_t %s%s (round %d of %zu, %zu elastic runs); "
                "%s; stability %s; %.1f s",
                dimension, model_used.c_str(), target.name.c_str(), Percent(v.error_youngs).c_str(),
                Percent(v.error_poisson).c_str(), Percent(v.error_ucs).c_str(), Percent(v.error_tensile).c_str(),
                tensile_honoured ? "" : " (given up)", best_round, rounds.size(), solution.elastic_runs.size(),
                converged && !gave_up ? "converged" : (converged ? "converged on what is reachable" : "NOT converged"),
                stability_verdict.c_str(), seconds);
  return line;
}

std::string CalibrationSummary::FullReport() const {
  std::ostringstream out;
  char line[480];
  auto row = [&](const char* label, const std::string& value) {
    std::snprintf(line, sizeof(line), "  %-40s %s\n", label, value.c_str());
    out << line;
  };
  out << "Calibration to material (" << dimension << "D)\n";
  row("target", target.name + " (E " + Num("%.4g GPa", target.youngs_modulus_pa / 1e9) + ", nu " +
                    Num("%.4g", target.poisson_ratio) + ", UCS " + Num("%.4g MPa", target.ucs_pa / 1e6) +
                    ", sigma_t " + Num("%.4g MPa", target.tensile_strength_pa / 1e6) + ", ratio " +
                    Num("%.3f", target.StrengthRatio()) + ")");
  row("model", model_used + " (requested " + model_requested + "; " + model_reason + ")");
  row("UCS specimen", std::to_string(ucs_descriptors.particles) + " particles, porosity " +
                          Num("%.4f", ucs_descriptors.porosity) + ", nc " + Num("%.3f", ucs_descriptors.coordination));
  row("Brazilian specimen", std::to_string(bts_descriptors.particles) + " particles, porosity " +
                                Num("%.4f", bts_descriptors.porosity));
  out << "maps\n";
  row("file", maps_path.empty() ? "(not stored)" : maps_path);
  row("reused", maps_reused ? "yes (built by " + maps.code_version + ", " + maps.created_utc + ")" : "no, built now");
  int ok = 0, anchors = 0;
  for (const SweepPoint& p : maps.points) ok += p.ok ? 1 : 0;
  for (const VerifiedPoint& v : maps.verified) anchors += v.origin == "anchor" ? 1 : 0;
  row("sweep points (succeeded / total)", std::to_string(ok) + " / " + std::to_string(maps.points.size()) + " on " +
                                             std::to_string(maps.ucs_descriptors.particles) + " + " +
                                             std::to_string(maps.bts_descriptors.particles) + " particles");
  row("sweep wall time", Num("%.1f s", maps_reused ? maps.sweep_seconds : sweep_seconds) +
                             (maps_reused ? " (when built)" : "") + ", transfer anchors included");
  row("stored measurements on this specimen", std::to_string(stored_measurements) + " (" + std::to_string(anchors) +
                                                  " transfer anchors), correcting the surfaces");
  row("fit error nu (leave-one-out RMS)", Num("%.4f", maps.maps.poisson_ratio.leave_one_out_rms()));
  auto relative_fit = [&](const ResponseSurface& surface, double SweepPoint::*group) {
    double sum = 0.0;
    int count = 0;
    for (const SweepPoint& p : maps.points)
      if (p.ok) sum += std::abs(p.*group), ++count;
    return Num("%.2f %%", count > 0 && sum > 0 ? 100.0 * surface.leave_one_out_rms() * count / sum : 0.0);
  };
  row("fit error Psi_E / Psi_c / Psi_t (rel.)",
      relative_fit(maps.maps.elastic_group, &SweepPoint::elastic_group) + " / " +
          relative_fit(maps.maps.compressive_group, &SweepPoint::compressive_group) + " / " +
          relative_fit(maps.maps.tensile_group, &SweepPoint::tensile_group));
  out << "reach (measured on the UCS specimen before any strength test)\n";
  // The model used as it was assessed then; what the rounds changed follows.
  const bool ddem_used = model_used == "ddem";
  const CalibrationReach& rigid_before = !ddem_used && reach_before_rounds.assessed ? reach_before_rounds : rigid_reach;
  const CalibrationReach& ddem_before = ddem_used && reach_before_rounds.assessed ? reach_before_rounds : deformable_reach;
  if (rigid_before.assessed) out << "  rigid: " << rigid_before.Describe(target) << "\n";
  if (ddem_before.assessed)
    out << "  DDEM (kn/(Ep l) <= " << Num("%.4g", admissible_particle_compliance)
        << "): " << ddem_before.Describe(target) << "\n";
  if (reach_before_rounds.assessed && reach_before_rounds.given_up != solution.reach.given_up)
    out << "  after the strength rounds: " << solution.reach.Describe(target) << "\n";
  out << "elastic stage (intact specimen: linear portion of a UCS with unbreakable bonds)\n";
  for (const ElasticRun& r : solution.elastic_runs) {
    std::snprintf(line, sizeof(line), "  %-6s kt/kn %.5g, kn/(Ep l) %.4g, kn %.5g N/m: E %.5g GPa, nu %.5f (%.1f s)\n",
                  r.purpose.c_str(), r.query.ratios.tangential_to_normal_stiffness,
                  r.query.ratios.normal_stiffness_to_particle, r.query.normal_stiffness,
                  r.measured.youngs_modulus_pa / 1e9, r.measured.poisson_ratio, r.measured.seconds);
    out << line;
  }
  out << "strength rounds (UCS and Brazilian; E, nu of the round's elastic set)\n";
  for (const VerificationRound& v : rounds) {
    if (v.failed) {
      // The whole set, so that the failed run can be repeated with run-test.
      const MaterialParameters& m = v.material;
      std::snprintf(line, sizeof(line),
                    "  round %d FAILED: Rt/Rn %.4g, Rn %.5g N (kn %.6g N/m, kt %.6g N/m, Rt %.6g N%s); %.0f s\n",
                    v.round, v.ratios.shear_to_tensile_strength, m.bond_tensile_strength_n, m.normal_stiffness_n_per_m,
                    m.tangential_stiffness_n_per_m, m.bond_shear_strength_n,
                    m.particle_youngs_modulus_pa ? (", Ep " + Num("%.6g", *m.particle_youngs_modulus_pa) + " Pa, nu_p " +
                                                    Num("%.4g", m.particle_poisson_ratio)).c_str()
                                                 : "",
                    v.seconds);
      out << line << "           " << v.failure << "\n";
      if (!v.correction.empty()) out << "           next: " << v.correction << "\n";
      continue;
    }
    std::snprintf(line, sizeof(line),
                  "  round %d%s: Rt/Rn %.4g, Rn %.5g N: UCS %.4g MPa (%s), sigma_t %.4g MPa (%s), ratio %.3f; "
                  "E %s, nu %s; %.0f s\n",
                  v.round, v.round == best_round ? " (best)" : "", v.ratios.shear_to_tensile_strength,
                  v.material.bond_tensile_strength_n, v.ucs_pa / 1e6, Percent(v.error_ucs).c_str(),
                  v.tensile_strength_pa / 1e6, Percent(v.error_tensile).c_str(), v.ucs_pa / v.tensile_strength_pa,
                  Percent(v.error_youngs).c_str(), Percent(v.error_poisson).c_str(), v.seconds);
    out << line;
    std::snprintf(line, sizeof(line), "           predicted UCS %.4g MPa, sigma_t %.4g MPa; secants over 1-50 %% of its peak: "
                  "E %.4g GPa, nu %.4f\n",
                  v.predicted_ucs_pa / 1e6, v.predicted_tensile_strength_pa / 1e6, v.own_peak_youngs_modulus_pa / 1e9,
                  v.own_peak_poisson_ratio);
    out << line;
    if (!v.correction.empty()) out << "           next: " << v.correction << "\n";
  }
  if (!rounds.empty() && best_round < 1)
    out << "  no result: every strength round failed, so no set was measured against the target\n";
  if (best_round >= 1) {
    const VerificationRound& v = rounds[best_round - 1];
    std::snprintf(line, sizeof(line), "  %-10s %14s %14s %10s\n", "", "target", "achieved", "error");
    out << line;
    auto compare = [&](const char* name, double t, double a, double e, const char* unit, double scale, bool kept) {
      std::snprintf(line, sizeof(line), "  %-10s %10.4g %-3s %10.4g %-3s %10s%s\n", name, t / scale, unit, a / scale,
                    unit, Percent(e).c_str(), kept ? "" : "  (given up)");
      out << line;
    };
    auto kept = [&](const char* name) {
      for (const std::string& g : solution.reach.given_up)
        if (g == name) return false;
      return true;
    };
    compare("E", target.youngs_modulus_pa, v.youngs_modulus_pa, v.error_youngs, "GPa", 1e9, true);
    compare("nu", target.poisson_ratio, v.poisson_ratio, v.error_poisson, "", 1.0, kept("nu"));
    compare("UCS", target.ucs_pa, v.ucs_pa, v.error_ucs, "MPa", 1e6, kept("UCS"));
    compare("sigma_t", target.tensile_strength_pa, v.tensile_strength_pa, v.error_tensile, "MPa", 1e6,
            kept("sigma_t"));
  }
  row("transfer error of the map specimens", "E " + Percent(solution.transfer_youngs) + ", nu " +
                                                 Percent(solution.transfer_poisson) + ", UCS " +
                                                 Percent(solution.transfer_ucs) + ", sigma_t " +
                                                 Percent(solution.transfer_tensile) + " (first runs against the fitted surfaces)");
  row("first prediction, corrected surfaces", "UCS " + Percent(solution.corrected_error_ucs) + ", sigma_t " +
                                                  Percent(solution.corrected_error_tensile));
  row("converged", converged ? (gave_up ? "yes, on every property kept" : "yes") : "no");
  out << "parameters\n";
  row("kn, kt [N/m]", Num("%.6g", material.normal_stiffness_n_per_m) + ", " + Num("%.6g", material.tangential_stiffness_n_per_m));
  row("Rn, Rt [N]", best_round >= 1 ? Num("%.6g", material.bond_tensile_strength_n) + ", " +
                                          Num("%.6g", material.bond_shear_strength_n)
                                    : "none (no strength round measured)");
  row("mu", Num("%.4g", material.friction_coefficient));
  row("Ep [Pa], nu_p", material.particle_youngs_modulus_pa ? Num("%.6g", *material.particle_youngs_modulus_pa) + ", " +
                                                                 Num("%.4g", material.particle_poisson_ratio)
                                                           : "rigid particles");
  row("density [kg/m^3]", Num("%.6g", material.density_kg_per_m3) +
                              (best_round >= 1 ? " (scaled in the tests: " +
                                                     Num("%.6g", final_ucs.density_used_kg_per_m3) + ")"
                                               : ""));
  out << "stability (UCS specimen, final set)\n";
  if (stability_judged) {
    row("verdict", stability_verdict + " (binding: " + stability_binding_limit + ", margin " +
                       Num("%.1f %%", stability_margin_percent) + ")");
    row("time step used / critical", Num("%.4g s", time_step_s) + " / " + Num("%.4g s", critical_time_step_s));
    if (material.particle_youngs_modulus_pa) row("rho(B)", Num("%.4f", spectral_radius));
  } else {
    row("verdict", stability_verdict + ": " + stability_message);
  }
  for (const std::string& note : notes) out << "  note: " << note << "\n";
  row("wall time", Num("%.1f s", seconds));
  return out.str();
}

nlohmann::json CalibrationSummary::ToJson() const {
  nlohmann::json j;
  j["dimension"] = dimension;
  j["target"] = TargetMaterialToJson(target);
  j["model"] = {{"requested", model_requested}, {"used", model_used}, {"reason", model_reason}};
  j["specimens"] = {{"ucs", DescriptorsReportJson(ucs_descriptors)}, {"bts", DescriptorsReportJson(bts_descriptors)}};
  int anchors = 0;
  for (const VerifiedPoint& v : maps.verified) anchors += v.origin == "anchor" ? 1 : 0;
  j["maps"] = {{"file", maps_path},
               {"reused", maps_reused},
               {"code_version", maps.code_version},
               {"created_utc", maps.created_utc},
               {"sweep_points", maps.points.size()},
               {"sweep_wall_time_s", sweep_seconds},
               {"transfer_anchors", anchors},
               {"stored_measurements_used", stored_measurements},
               {"fit_leave_one_out_rms",
                {{"poisson_ratio", maps.maps.poisson_ratio.leave_one_out_rms()},
                 {"elastic_group", maps.maps.elastic_group.leave_one_out_rms()},
                 {"compressive_group", maps.maps.compressive_group.leave_one_out_rms()},
                 {"tensile_group", maps.maps.tensile_group.leave_one_out_rms()}}},
               {"admissible_kn_over_ep_l", admissible_particle_compliance}};
  j["reach"] = {{"rigid", rigid_reach.assessed ? rigid_reach.ToJson() : nlohmann::json()},
                {"ddem", deformable_reach.assessed ? deformable_reach.ToJson() : nlohmann::json()},
                {"used", solution.reach.ToJson()},
                {"before_rounds", reach_before_rounds.assessed ? reach_before_rounds.ToJson() : nlohmann::json()}};
  j["elastic_runs"] = nlohmann::json::array();
  for (const ElasticRun& r : solution.elastic_runs)
    j["elastic_runs"].push_back({{"purpose", r.purpose},
                                 {"ratios", RatiosJson(r.query.ratios)},
                                 {PerThickness("kn_n_per_m", dimension), r.query.normal_stiffness},
                                 {"youngs_modulus_pa", r.measured.youngs_modulus_pa},
                                 {"poisson_ratio", r.measured.poisson_ratio},
                                 {"wall_time_s", r.measured.seconds}});
  j["verification"] = nlohmann::json::array();
  // A failed round measured no strength: those fields are null, `failure` says why.
  auto measured = [](const VerificationRound& v, double value) {
    return v.failed ? nlohmann::json() : nlohmann::json(value);
  };
  for (const VerificationRound& v : rounds) {
    j["verification"].push_back({{"round", v.round},
                                 {"failed", v.failed},
                                 {"failure", v.failure},
                                 {"best", v.round == best_round},
                                 {"accepted", v.accepted},
                                 {"ratios", RatiosJson(v.ratios)},
                                 {PerThickness("kn_n_per_m", dimension), v.material.normal_stiffness_n_per_m},
                                 {PerThickness("kt_n_per_m", dimension), v.material.tangential_stiffness_n_per_m},
                                 {PerThickness("rn_n", dimension), v.material.bond_tensile_strength_n},
                                 {PerThickness("rt_n", dimension), v.material.bond_shear_strength_n},
                                 {"youngs_modulus_pa", v.youngs_modulus_pa},
                                 {"poisson_ratio", v.poisson_ratio},
                                 {"own_peak_secants", {{"youngs_modulus_pa", measured(v, v.own_peak_youngs_modulus_pa)},
                                                       {"poisson_ratio", measured(v, v.own_peak_poisson_ratio)}}},
                                 {"ucs_pa", measured(v, v.ucs_pa)},
                                 {"tensile_strength_pa", measured(v, v.tensile_strength_pa)},
                                 {"predicted", {{"ucs_pa", v.predicted_ucs_pa},
                                                {"tensile_strength_pa", v.predicted_tensile_strength_pa}}},
                                 {"relative_errors",
                                  {{"youngs_modulus", v.error_youngs},
                                   {"poisson_ratio", v.error_poisson},
                                   {"ucs", measured(v, v.error_ucs)},
                                   {"tensile_strength", measured(v, v.error_tensile)}}},
                                 {"wall_time_s", v.seconds},
                                 {"next", v.correction}});
    if (v.material.particle_youngs_modulus_pa) {
      j["verification"].back()["particle_youngs_modulus_pa"] = *v.material.particle_youngs_modulus_pa;
      j["verification"].back()["particle_poisson_ratio"] = v.material.particle_poisson_ratio;
    }
  }
  j["transfer_error"] = {{"youngs_modulus", solution.transfer_youngs},
                         {"poisson_ratio", solution.transfer_poisson},
                         {"ucs", solution.transfer_ucs},
                         {"tensile_strength", solution.transfer_tensile},
                         {"first_prediction_corrected",
                          {{"ucs", solution.corrected_error_ucs}, {"tensile_strength", solution.corrected_error_tensile}}}};
  j["best_round"] = best_round;  // 0: every round failed, no result
  j["converged"] = converged;
  j["tensile_honoured"] = tensile_honoured;
  j["given_up"] = solution.reach.given_up;
  j["replans"] = solution.replans;
  nlohmann::json parameters = {{PerThickness("normal_stiffness_n_per_m", dimension), material.normal_stiffness_n_per_m},
                               {PerThickness("tangential_stiffness_n_per_m", dimension), material.tangential_stiffness_n_per_m},
                               {PerThickness("bond_tensile_strength_n", dimension), material.bond_tensile_strength_n},
                               {PerThickness("bond_shear_strength_n", dimension), material.bond_shear_strength_n},
                               {"friction_coefficient", material.friction_coefficient},
                               {"density_kg_per_m3", material.density_kg_per_m3}};
  if (material.particle_youngs_modulus_pa) {
    parameters["particle_youngs_modulus_pa"] = *material.particle_youngs_modulus_pa;
    parameters["particle_poisson_ratio"] = material.particle_poisson_ratio;
  }
  j["parameters"] = parameters;
  // Not judged: no numbers (null, not 0); the message says why.
  auto judged = [&](double value) { return stability_judged ? nlohmann::json(value) : nlohmann::json(); };
  j["stability"] = {{"verdict", stability_verdict},
                    {"binding_limit", stability_binding_limit},
                    {"margin_percent", judged(stability_margin_percent)},
                    {"message", stability_message},
                    {"critical_time_step_s", judged(critical_time_step_s)},
                    {"time_step_s", judged(time_step_s)},
                    {"spectral_radius", material.particle_youngs_modulus_pa ? judged(spectral_radius)
                                                                            : nlohmann::json()}};
  j["notes"] = notes;
  j["wall_time_s"] = seconds;
  j["code_version"] = kVersion;
  return j;
}

}  // namespace specimen
