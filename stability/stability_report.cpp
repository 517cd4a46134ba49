// StabilitySummary: the human report and the JSON (the same content); the one-line report is
// the limits' (solver/stability_limits.cpp).
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/unit_names.h"
#include "stability/stability_analysis.h"

namespace specimen {

namespace {

// JSON has no infinity or NaN: such values are written as null.
nlohmann::json Finite(double value) {
  if (std::isfinite(value)) return value;
  return nullptr;
}

nlohmann::json EigenvalueJson(const EigenvalueReport& e) {
  return {{"ritz_value", e.ritz_value},
          {"certified_upper_bound", Finite(e.certified_upper_bound)},
          {"relative_tolerance", e.relative_tolerance},
          {"residual_norm", e.residual_norm},
          {"iterations", e.iterations},
          {"dimension", e.dimension},
          {"reorthogonalised", e.reorthogonalised},
          {"exact", e.exact},
          {"inner_iterations", e.inner_iterations},
          {"wall_time_s", e.seconds}};
}

nlohmann::json LatticeJson(const LatticeLimits& l) {
  return {{"row", Finite(l.row)}, {"sc", Finite(l.square)}, {"hcp", Finite(l.hexagonal)}};
}

std::string Line(const char* format, ...) __attribute__((format(printf, 1, 2)));
std::string Line(const char* format, ...) {
  char buffer[512];
  va_list arguments;
  va_start(arguments, format);
  std::vsnprintf(buffer, sizeof(buffer), format, arguments);
  va_end(arguments);
  return buffer;
}

std::string EigenvalueLine(const EigenvalueReport& e, const char* unit) {
  return Line(
      "Ritz %.8g, certified <= %.8g %s (eps %.3g%s), residual %.3g, %d Lanczos steps on "
      "%d unknowns%s, %.3f s",
      e.ritz_value, e.certified_upper_bound, unit, e.relative_tolerance, e.exact ? ", exact" : "",
      e.residual_norm, e.iterations, e.dimension, e.reorthogonalised ? " (reorthogonalised)" : "",
      e.seconds);
}

}  // namespace

std::string StabilitySummary::FullReport() const {
  std::ostringstream out;
  const char* length = dimension == 2 ? "l" : "R";
  out << Line(
      "Stability analysis (%dD): %d particles, %d links (%d contacts, %d wall, %d rattler"
      "), %d degrees of freedom (%d prescribed removed)%s\n",
      dimension, particles, links, contact_links, wall_links, rattler_links, degrees_of_freedom,
      fixed_degrees_of_freedom,
      rotation ? ", rotations included" : ", no rotational stiffness (kt = 0)");
  if (bond_radius_ratio > 0.0)
    out << Line("  bonds carry moments: radius ratio %.4g, bending (and 3D twisting) springs on "
                "every contact link\n",
                bond_radius_ratio);
  if (bond_range > 1.0)
    out << Line("  bonds within an interaction range: every pair within %.4g (ri + rj) is a contact link\n",
                bond_range);
  if (rattlers_without_neighbour > 0)
    out << Line("  %d particle(s) without links and without a neighbour within the search skin\n",
                rattlers_without_neighbour);
  out << Line("  kn %.6g N/m, kt %.6g N/m, particles %s", normal_stiffness_n_per_m,
              tangential_stiffness_n_per_m, particle_model.c_str());
  if (deformable)
    out << Line(": Ep %.6g Pa, nu_p %.4g, kn/(Ep %s) %.5g", particle_youngs_modulus_pa,
                particle_poisson_ratio, length, kn_over_ep);
  out << "\n\nCritical time step\n";
  if (mass_scaling.scaled_particles > 0)
    out << "  inertia scaling: " << MassScalingLine(mass_scaling) << "\n";
  out << Line("  per-particle bound 2 sqrt(m/k_eff) (Madan (2.18))  %.6g s  (guaranteed %.6g s)\n",
              per_particle_bound_s, guaranteed_bound_s);
  out << Line("  Gershgorin bound (deterministic)                   %.6g s\n", gershgorin_bound_s);
  out << Line("  2/omega_max, Ritz value (unsafe side)              %.6g s\n",
              dem_time_step_ritz_s);
  out << Line("  2/omega_max, certified (DEM)                       %.6g s\n",
              dem_critical_time_step_s);
  out << "    omega_max^2: " << EigenvalueLine(dem_eigenvalue, "1/s^2") << "\n";
  if (mode_particle >= 0)
    out << Line("    top mode: particle %d (R = %.4g m) holds %.1f %% of it, rotations %.1f %%\n",
                mode_particle, mode_particle_radius_m, 100.0 * mode_particle_share,
                100.0 * mode_rotational_share);
  if (ddem_time_step_available) {
    out << Line(
        "  2/omega_max, certified (DDEM)                      %.6g s  (reduction %.3f %% "
        "against DEM, Ritz values)\n",
        ddem_critical_time_step_s, ddem_reduction_percent);
    out << "    K_eff: " << EigenvalueLine(ddem_eigenvalue, "1/s^2")
        << (ddem_time_step_inner_solves
                ? Line(", %d inner CG iterations\n", ddem_eigenvalue.inner_iterations)
                : std::string(", pencil without inner solves\n"));
  }
  out << Line(
      "  damping factors: dashpots %.4f (the boundary z = -1 with 2c/dt), local damping "
      "%.4f (1/sqrt(1 + alpha)); included above\n",
      dashpot_factor, local_damping_factor);
  if (unilateral_factor != 1.0)
    out << Line(
        "  unilateral wall contacts, weakly damped: x %.3g for impacts (linear limit %.6g s)\n",
        unilateral_factor, linear_critical_time_step_s);
  out << Line("  critical %.6g s (%s)\n  recommended %.6g s (safety factor %.3g)\n",
              critical_time_step_s, critical_time_step_method.c_str(), recommended_time_step_s,
              safety_factor);
  out << "\nDDEM convergence (force iteration, Madan (3.13); docs/stability.md)\n";
  out << Line("  lambda_max(S^) = rho(B) x Ep: %.8g Pa; %s\n", unit_spectral_radius_pa,
              EigenvalueLine(convergence_eigenvalue, "Pa").c_str());
  if (deformable)
    out << Line("  rho(B) = %.6f (Ritz %.6f), required <= %.4g\n", spectral_radius,
                spectral_radius_ritz, max_spectral_radius);
  out << Line(
      "  admissible kn/(Ep %s) at rho(B) = 1: %.5g; at rho(B) = %.4g: %.5g, i.e. Ep >= "
      "%.6g Pa for kn = %.6g N/m\n",
      length, admissible_kn_over_ep, max_spectral_radius, recommended_kn_over_ep,
      smallest_youngs_modulus_pa, normal_stiffness_n_per_m);
  // HCP is a 2D lattice (stability_closed_forms.h): no value in 3D.
  auto hcp = [](double value) { return std::isnan(value) ? std::string("-") : Line("%.4f", value); };
  out << Line("  lattice limits at nu_p = %.4g: row %.4f, SC %.4f, HCP %s\n",
              particle_poisson_ratio, lattice.row, lattice.square, hcp(lattice.hexagonal).c_str());
  if (!sweep.empty()) {
    out << Line("\n  nu_p     admissible  recommended  row      SC       HCP   (kn/(Ep %s))\n",
                length);
    for (const SweepRow& r : sweep)
      out << Line("  %-7.4g  %-10.5g  %-11.5g  %-7.4f  %-7.4f  %-7s\n", r.poisson_ratio,
                  r.admissible_kn_over_ep, r.recommended_kn_over_ep, r.lattice.row,
                  r.lattice.square, hcp(r.lattice.hexagonal).c_str());
    out << Line(
        "  largest: kn/(Ep %s) %.5g at nu_p = %.4g (%.5g at rho(B) = %.4g): the softest "
        "particles this packing allows\n",
        length, sweep_largest_kn_over_ep, sweep_largest_poisson_ratio,
        sweep_largest_recommended_kn_over_ep, max_spectral_radius);
  }
  for (const std::string& warning : warnings) out << "\nwarning: " << warning << "\n";
  out << Line("\nVerdict for the %s time step %.6g s: %s\n",
              judged_time_step_proposed ? "proposed" : "recommended", judged_time_step_s,
              verdict_message.c_str());
  out << Line("  analysis time %.3f s\n", seconds);
  return out.str();
}

nlohmann::json StabilitySummary::ToJson() const {
  nlohmann::json j;
  j["dimension"] = dimension;
  j["scene"] = {{"particles", particles},
                {"links", links},
                {"contact_links", contact_links},
                {"wall_links", wall_links},
                {"rattler_links", rattler_links},
                {"rattlers_without_neighbour", rattlers_without_neighbour},
                {"degrees_of_freedom", degrees_of_freedom},
                {"fixed_degrees_of_freedom", fixed_degrees_of_freedom},
                {"rotation", rotation},
                {PerThickness("normal_stiffness_n_per_m", dimension), normal_stiffness_n_per_m},
                {PerThickness("tangential_stiffness_n_per_m", dimension), tangential_stiffness_n_per_m},
                {"bond_radius_ratio", bond_radius_ratio},
                {"bond_range", bond_range},
                {"particle_model", particle_model},
                {"particle_youngs_modulus_pa",
                 deformable ? nlohmann::json(particle_youngs_modulus_pa) : nlohmann::json(nullptr)},
                {"particle_poisson_ratio", particle_poisson_ratio},
                {"group_length_m", group_length_m}};
  nlohmann::json step;
  step["per_particle_bound_s"] = Finite(per_particle_bound_s);
  step["mass_scaling"] = MassScalingJson(mass_scaling);
  step["guaranteed_bound_s"] = Finite(guaranteed_bound_s);
  step["gershgorin_bound_s"] = Finite(gershgorin_bound_s);
  step["dem_time_step_ritz_s"] = Finite(dem_time_step_ritz_s);
  step["dem_critical_time_step_s"] = Finite(dem_critical_time_step_s);
  step["omega_max_ritz_rad_per_s"] = omega_max_ritz_rad_per_s;
  step["omega_max_certified_rad_per_s"] = omega_max_certified_rad_per_s;
  step["dem_eigenvalue"] = EigenvalueJson(dem_eigenvalue);
  step["mode"] = {{"particle", mode_particle},
                  {"share", mode_particle_share},
                  {"radius_m", mode_particle_radius_m},
                  {"rotational_share", mode_rotational_share}};
  step["ddem_available"] = ddem_time_step_available;
  if (ddem_time_step_available) {
    step["ddem_critical_time_step_s"] = Finite(ddem_critical_time_step_s);
    step["ddem_time_step_ritz_s"] = Finite(ddem_time_step_ritz_s);
    step["ddem_reduction_percent"] = ddem_reduction_percent;
    step["ddem_eigenvalue"] = EigenvalueJson(ddem_eigenvalue);
    step["ddem_inner_solves"] = ddem_time_step_inner_solves;
  }
  step["flutter_possible"] = flutter_possible;
  step["dashpot_factor"] = dashpot_factor;
  step["dashpot_fixed_point_iterations"] = dashpot_fixed_point_iterations;
  step["local_damping_factor"] = local_damping_factor;
  step["linear_critical_time_step_s"] = Finite(linear_critical_time_step_s);
  step["unilateral_contacts"] = unilateral_contacts;
  step["unilateral_factor"] = unilateral_factor;
  step["critical_time_step_s"] = Finite(critical_time_step_s);
  step["method"] = critical_time_step_method;
  step["safety_factor"] = safety_factor;
  step["recommended_time_step_s"] = Finite(recommended_time_step_s);
  j["time_step"] = step;
  nlohmann::json ddem;
  ddem["unit_spectral_radius_pa"] = unit_spectral_radius_pa;
  ddem["eigenvalue"] = EigenvalueJson(convergence_eigenvalue);
  ddem["spectral_radius"] = deformable ? nlohmann::json(spectral_radius) : nlohmann::json(nullptr);
  ddem["spectral_radius_ritz"] =
      deformable ? nlohmann::json(spectral_radius_ritz) : nlohmann::json(nullptr);
  ddem["kn_over_ep"] = deformable ? nlohmann::json(kn_over_ep) : nlohmann::json(nullptr);
  ddem["max_spectral_radius"] = max_spectral_radius;
  ddem["admissible_kn_over_ep"] = Finite(admissible_kn_over_ep);
  ddem["recommended_kn_over_ep"] = Finite(recommended_kn_over_ep);
  ddem["smallest_youngs_modulus_pa"] = smallest_youngs_modulus_pa;
  ddem["lattice_limits"] = LatticeJson(lattice);
  j["ddem_convergence"] = ddem;
  j["verdict"] = {
      {"time_step_s", judged_time_step_s},
      {"time_step_proposed", judged_time_step_proposed},
      {"verdict", verdict},
      {"binding_limit", binding_limit},
      {"margin_percent", margin_percent},
      {"time_step_margin_percent", time_step_margin_percent},
      {"spectral_radius_margin_percent",
       deformable ? nlohmann::json(spectral_radius_margin_percent) : nlohmann::json(nullptr)},
      {"message", verdict_message}};
  j["sweep_largest"] = {{"poisson_ratio", sweep_largest_poisson_ratio},
                        {"admissible_kn_over_ep", sweep_largest_kn_over_ep},
                        {"recommended_kn_over_ep", sweep_largest_recommended_kn_over_ep}};
  j["sweep"] = nlohmann::json::array();
  for (const SweepRow& r : sweep)
    j["sweep"].push_back({{"poisson_ratio", r.poisson_ratio},
                          {"unit_spectral_radius_pa", r.spectral_radius_times_ep_pa},
                          {"admissible_kn_over_ep", Finite(r.admissible_kn_over_ep)},
                          {"recommended_kn_over_ep", Finite(r.recommended_kn_over_ep)},
                          {"lattice_limits", LatticeJson(r.lattice)}});
  j["warnings"] = warnings;
  j["wall_time_s"] = seconds;
  return j;
}

}  // namespace specimen
