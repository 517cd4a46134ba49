#pragma once
// The stability analysis of a bonded (DDEM) scene, as the stability-limit command, the
// calibrator and the benchmark run it: the certified limits of the scene (the critical time
// step, the DDEM convergence bound rho(B), the verdict for a proposed step; what they are and
// how they are computed: solver/stability_limits.h, the engine's time step), and beside them
//  - the closed-form limits of kn/(Ep l) of the row, SC and HCP lattices at the scene's nu_p
//    (stability_closed_forms.h);
//  - optionally, the admissible kn/(Ep l) against nu_p for the packing (a sweep), and its
//    largest value with its nu_p (the softest particles the packing allows, for any kn);
//  - the full report and the JSON (stability_report.cpp).
//
//   StabilityOptions options;
//   options.proposed_time_step_s = 2.9e-7;
//   StabilitySummary summary = AnalyseStability<2>(packing, scene, options);
//   std::cout << summary.FullReport();   // limits, certificates, verdict

#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "generator/packing.h"
#include "solver/scene.h"
#include "solver/stability_limits.h"
#include "stability/stability_closed_forms.h"

namespace specimen {

struct StabilityOptions : StabilityLimitOptions {
  // nu_p values of the sweep of the admissible kn/(Ep l), each in (-1, 0.5); empty: no sweep.
  std::vector<double> sweep_poisson_ratios;

  // Names the first invalid field, its value and the allowed range.
  bool IsValid(std::string* error) const;
};

struct SweepRow {
  double poisson_ratio = 0.0;
  double spectral_radius_times_ep_pa = 0.0;  // lambda_max(S^) certified [Pa]
  double admissible_kn_over_ep = 0.0;        // at rho(B) = 1
  double recommended_kn_over_ep = 0.0;       // at rho(B) = max_spectral_radius
  LatticeLimits lattice;
};

struct StabilitySummary : StabilityLimits {
  // The closed forms at the scene's nu_p, beside the packing's admissible kn/(Ep l).
  LatticeLimits lattice;
  std::vector<SweepRow> sweep;
  // The largest admissible kn/(Ep l) of the sweep (at rho(B) = 1 and at
  // max_spectral_radius) and its nu_p: the softest particles the packing allows, for any
  // kn (an Ep-free choice). 0 without a sweep.
  double sweep_largest_kn_over_ep = 0.0, sweep_largest_recommended_kn_over_ep = 0.0;
  double sweep_largest_poisson_ratio = 0.0;

  std::string FullReport() const;
  nlohmann::json ToJson() const;
};

// The analysis of a scene on a packing. Throws InputError for invalid options, scenes or
// packings (naming the field and its range); ComputationError if an inner solve fails.
template <int Dim>
StabilitySummary AnalyseStability(const Packing<Dim>& packing, const SceneOptions<Dim>& scene,
                                  const StabilityOptions& options);

}  // namespace specimen
