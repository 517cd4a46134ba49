#include "lab/lab_test.h"

#include <cmath>
#include <sstream>

#include "common/error.h"
#include "lab/lab_runner.h"
#include "lab/lab_specimen.h"
#include "common/format.h"

namespace specimen {
namespace {

// Relative change |b - a| / |a| (0 when a = 0).
double RelativeChange(double a, double b) { return a != 0.0 ? std::abs(b - a) / std::abs(a) : 0.0; }

}  // namespace

const char* LabTestKindName(LabTestKind kind) {
  switch (kind) {
    case LabTestKind::kUniaxialCompression:
      return "ucs";
    case LabTestKind::kBrazilian:
      return "brazilian";
    case LabTestKind::kConfinedCompression:
      return "biaxial";
    case LabTestKind::kIsotropicCompression:
      return "isotropic";
    case LabTestKind::kPureShear:
      return "shear";
  }
  return "?";
}

bool ParseLabTestKind(const std::string& name, LabTestKind* kind) {
  for (const LabTestKind k :
       {LabTestKind::kUniaxialCompression, LabTestKind::kBrazilian,
        LabTestKind::kConfinedCompression, LabTestKind::kIsotropicCompression,
        LabTestKind::kPureShear})
    if (name == LabTestKindName(k)) {
      *kind = k;
      return true;
    }
  return false;
}

bool IsStrengthTest(LabTestKind kind) {
  return kind == LabTestKind::kUniaxialCompression || kind == LabTestKind::kBrazilian ||
         kind == LabTestKind::kConfinedCompression;
}

QuasiStaticCheck CompareAtHalfRate(const LabTestOptions& options, const LabTestResult& result,
                                   const LabTestResult& slow) {
  QuasiStaticCheck q;
  q.performed = true;
  q.half_rate_group = slow.loading_rate_group;
  q.tolerance = options.quasi_static_tolerance;
  switch (options.kind) {
    case LabTestKind::kIsotropicCompression:
      q.modulus_change = RelativeChange(result.bulk_modulus_pa, slow.bulk_modulus_pa);
      break;
    case LabTestKind::kPureShear:
      q.modulus_change = RelativeChange(result.shear_modulus_pa, slow.shear_modulus_pa);
      break;
    case LabTestKind::kBrazilian:
      q.peak_change = RelativeChange(result.peak_stress_pa, slow.peak_stress_pa);
      break;
    default:
      q.modulus_change = RelativeChange(result.elastic.youngs_modulus_in_plane_pa,
                                        slow.elastic.youngs_modulus_in_plane_pa);
      q.peak_change = RelativeChange(result.peak_stress_pa, slow.peak_stress_pa);
  }
  // Without a peak (a strength test at its strain limit) the largest stress is compared.
  q.passed = q.modulus_change <= q.tolerance && q.peak_change <= q.tolerance;
  return q;
}

bool LabTestOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& field, double value, const std::string& range) {
    if (error) *error = field + " = " + Number(value) + " is not allowed: it must be " + range;
    return false;
  };
  auto finite = [](double v) { return std::isfinite(v); };
  if (!(loading_rate_group > 0.0 && loading_rate_group <= 0.01))
    return fail("loading_rate_group", loading_rate_group,
                "in (0, 0.01] (quasi-static loading is far below 0.01)");
  if (!(platen_speed_m_per_s >= 0.0) || !finite(platen_speed_m_per_s))
    return fail("platen_speed_m_per_s", platen_speed_m_per_s, ">= 0 (0: from the rate group)");
  if (!(velocity_ramp_transits >= 0.0) || !finite(velocity_ramp_transits))
    return fail("velocity_ramp_transits", velocity_ramp_transits, ">= 0");
  if (!(pause_kinetic_energy_ratio >= 0.0) || !finite(pause_kinetic_energy_ratio))
    return fail("pause_kinetic_energy_ratio", pause_kinetic_energy_ratio, ">= 0 (0: constant speed)");
  if (!(max_pause_transits > 0.0) || !finite(max_pause_transits))
    return fail("max_pause_transits", max_pause_transits, "> 0");
  if (!(pause_ramp_transits >= 0.0) || !finite(pause_ramp_transits))
    return fail("pause_ramp_transits", pause_ramp_transits, ">= 0");
  if (!(post_peak_stress_fraction > 0.0 && post_peak_stress_fraction < 1.0))
    return fail("post_peak_stress_fraction", post_peak_stress_fraction, "in (0, 1)");
  if (!(strain_limit >= 0.0 && strain_limit < 0.5))
    return fail("strain_limit", strain_limit, "in (0, 0.5), or 0 for automatic");
  if (!(modulus_window_low > 0.0 && modulus_window_low < 1.0))
    return fail("modulus_window_low", modulus_window_low, "in (0, 1)");
  if (!(modulus_window_high > 0.0 && modulus_window_high < 1.0))
    return fail("modulus_window_high", modulus_window_high, "in (0, 1)");
  if (!(modulus_window_low < modulus_window_high))
    return fail("modulus_window_low", modulus_window_low,
                "below modulus_window_high = " + Number(modulus_window_high));
  if (!(linear_portion_low > 0.0 && linear_portion_low < 1.0))
    return fail("linear_portion_low", linear_portion_low, "in (0, 1)");
  if (max_steps < 1) return fail("max_steps", static_cast<double>(max_steps), ">= 1");
  if (sample_interval_steps < 1)
    return fail("sample_interval_steps", sample_interval_steps, ">= 1");
  if (!(strain_boundary_margin >= 0.0) || !finite(strain_boundary_margin))
    return fail("strain_boundary_margin", strain_boundary_margin, ">= 0 (mean radii)");
  if (!(confining_stress_pa >= 0.0) || !finite(confining_stress_pa))
    return fail("confining_stress_pa", confining_stress_pa,
                ">= 0 (compression positive; a confinement cannot pull)");
  if (!(servo_gain_fraction > 0.0 && servo_gain_fraction <= 1.0))
    return fail("servo_gain_fraction", servo_gain_fraction, "in (0, 1]");
  if (!(servo_integral_transits > 0.0) || !finite(servo_integral_transits))
    return fail("servo_integral_transits", servo_integral_transits, "> 0");
  if (!(consolidation_tolerance > 0.0 && consolidation_tolerance < 0.1))
    return fail("consolidation_tolerance", consolidation_tolerance, "in (0, 0.1)");
  if (!(platen_stiffness_ratio > 0.0) || !finite(platen_stiffness_ratio))
    return fail("platen_stiffness_ratio", platen_stiffness_ratio, "> 0");
  if (!(platen_friction >= 0.0) || !finite(platen_friction))
    return fail("platen_friction", platen_friction, ">= 0");
  if (!(loading_arc_deg >= 0.0 && loading_arc_deg <= 60.0))
    return fail("loading_arc_deg", loading_arc_deg, "in [0, 60] (degrees, the jaws' arc 2 alpha; 0: flat platens)");
  if (kind == LabTestKind::kBrazilian && loading_arc_deg > 0.0 && platen_friction > 0.0)
    return fail("platen_friction", platen_friction, "0 with a loading arc (the jaws press radially)");
  if (!(local_damping >= 0.0 && local_damping < 1.0))
    return fail("local_damping", local_damping, "in [0, 1)");
  if (!(dashpot_ratio >= 0.0) || !finite(dashpot_ratio))
    return fail("dashpot_ratio", dashpot_ratio, ">= 0");
  if (!(mass_scaling_budget >= 0.0 && mass_scaling_budget <= 0.05))
    return fail("mass_scaling_budget", mass_scaling_budget, "in [0, 0.05]");
  if (!(time_step_safety_factor > 0.0 && time_step_safety_factor <= 0.95))
    return fail("time_step_safety_factor", time_step_safety_factor, "in (0, 0.95]");
  if (!(quasi_static_tolerance > 0.0) || !finite(quasi_static_tolerance))
    return fail("quasi_static_tolerance", quasi_static_tolerance, "> 0");
  if (num_threads < 1) return fail("num_threads", num_threads, ">= 1");
  return true;
}

std::string StepBudgetRefusal(double steps_needed, double strain_limit, double speed_m_per_s, double time_step_s,
                              long max_steps, const std::string& hint) {
  return "the test would need about " + Number(steps_needed) + " steps to reach its strain limit " +
         Number(strain_limit) + " (platen speed " + Number(speed_m_per_s) + " m/s, time step " + Number(time_step_s) +
         " s), more than max_steps = " + std::to_string(max_steps) + ": raise the loading rate or the platen speed" +
         hint;
}

template <int Dim>
LabTestResult RunLabTest(const Packing<Dim>& packing, const MaterialParameters& material,
                         const LabTestOptions& options) {
  // 1. Everything is checked before any work.
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  if (!material.IsValid(&error)) throw InputError("material: " + error);
  const LabSpecimen<Dim> specimen =
      DescribeSpecimen<Dim>(packing, options.kind, options.strain_boundary_margin);
  // Before the rates derived from kn and rho: a density of 1e-300 is a typo, not a wall speed.
  if (!material.IsPhysical(Dim == 2 ? 1.0 : specimen.mean_radius_m, &error)) throw InputError("material: " + error);

  // 2. The material the simulation uses: scaled density, the protocol's damping.
  MaterialParameters used = material;
  if (options.scale_density)  // Labra Tables 4.8, 4.11, section 6.2.2: rho' = rho / (1 - e)
    used.density_kg_per_m3 = material.density_kg_per_m3 / (1.0 - specimen.nominal_porosity);
  used.translational_damping = used.rotational_damping = options.local_damping;
  used.normal_dashpot_ratio = used.tangential_dashpot_ratio = options.dashpot_ratio;
  used.mass_scaling_budget = options.mass_scaling_budget;

  // 3. Rate: V from the group (or given), and the strain limit.
  const double wave_speed = WaveSpeedScale<Dim>(used, specimen.mean_radius_m);
  const double speed = options.platen_speed_m_per_s > 0.0
                           ? options.platen_speed_m_per_s
                           : options.loading_rate_group * wave_speed;
  double strain_limit = options.strain_limit;
  if (strain_limit == 0.0) strain_limit = IsStrengthTest(options.kind) ? 0.02 : 0.001;

  // 4. The test, and at half the rate for the quasi-static check.
  LabTestResult result =
      RunLabTestAtSpeed<Dim>(packing, specimen, used, options, speed, strain_limit);
  if (options.check_quasi_static) {
    LabTestOptions half = options;
    half.check_quasi_static = false;
    half.record_snapshots = false;
    LabTestResult slow = RunLabTestAtSpeed<Dim>(packing, specimen, used, half, 0.5 * speed, strain_limit);
    slow.loading_rate_group = 0.5 * speed / wave_speed;  // (set for `result` below, at 5.)
    result.quasi_static = CompareAtHalfRate(options, result, slow);
    result.wall_seconds += slow.wall_seconds;
  }

  // 5. What the test ran on.
  result.dimension = Dim;
  result.kind = options.kind;
  result.domain = packing.domain.ToShortText();  // for reading; the packing file is exact
  result.particles = packing.size();
  result.porosity = specimen.nominal_porosity;
  result.mean_radius_m = specimen.mean_radius_m;
  result.density_used_kg_per_m3 = used.density_kg_per_m3;
  result.height_m = specimen.height_m;
  result.width_m = specimen.width_m;
  result.thickness_m = specimen.thickness_m;
  result.loading_rate_group = speed / wave_speed;
  result.platen_speed_m_per_s = speed;
  result.strain_rate_per_s = 2.0 * speed / specimen.height_m;
  return result;
}

template LabTestResult RunLabTest<2>(const Packing<2>&, const MaterialParameters&,
                                     const LabTestOptions&);
template LabTestResult RunLabTest<3>(const Packing<3>&, const MaterialParameters&,
                                     const LabTestOptions&);

}  // namespace specimen
