#include "stability/stability_analysis.h"

#include <string>

#include "common/error.h"
#include "common/format.h"
#include "solver/stability_network.h"

namespace specimen {

bool StabilityOptions::IsValid(std::string* error) const {
  // The limits' scalar options first, then the sweep, then their Lanczos options.
  StabilityLimitOptions scalars = *this;
  scalars.lanczos = LanczosOptions();
  if (!scalars.IsValid(error)) return false;
  for (const double nu : sweep_poisson_ratios)
    if (!(nu > -1.0 && nu < 0.5)) {
      if (error) *error = "sweep nu_p = " + Number(nu) + " is not allowed: it must be in (-1, 0.5)";
      return false;
    }
  return StabilityLimitOptions::IsValid(error);
}

template <int Dim>
StabilitySummary AnalyseStability(const Packing<Dim>& packing, const SceneOptions<Dim>& scene,
                                  const StabilityOptions& given_options) {
  StabilityOptions options = given_options;
  options.lanczos.num_threads = scene.num_threads;  // as the limits run them
  std::string error;
  if (!options.IsValid(&error)) throw InputError("stability analysis: " + error);
  const MaterialParameters& material = scene.material;
  StabilitySummary s;
  s.lattice = ClosedFormLimits(Dim, material.particle_poisson_ratio, material.plane_model);
  // The sweep of the admissible kn/(Ep l) against nu_p, on the network of the limits.
  auto sweep = [&](const LinearisedNetwork<Dim>& network, const StabilityLimitOptions& in_force) {
    const double kn = material.normal_stiffness_n_per_m;
    const double group_length_m = Dim == 2 ? 1.0 : VolumeMeanRadius<Dim>(packing.radii);
    const size_t count = options.sweep_poisson_ratios.size();
    for (size_t k = 0; k < count; ++k) {
      const double nu = options.sweep_poisson_ratios[k];
      SweepRow row;
      row.poisson_ratio = nu;
      const ParticleCompliance<Dim> compliance(1.0, nu, material.plane_model);
      if (network.link_count() > 0)
        row.spectral_radius_times_ep_pa =
            LargestDdemEigenvalue<Dim>(network, compliance, in_force,
                                       "sweep nu_p = " + Number(nu, 3) + " (" +
                                           std::to_string(k + 1) + "/" + std::to_string(count) +
                                           ")")
                .certified_upper_bound;
      if (row.spectral_radius_times_ep_pa > 0.0) {
        row.admissible_kn_over_ep = kn / (group_length_m * row.spectral_radius_times_ep_pa);
        row.recommended_kn_over_ep = in_force.max_spectral_radius * row.admissible_kn_over_ep;
      }
      row.lattice = ClosedFormLimits(Dim, nu, material.plane_model);
      s.sweep.push_back(row);
      if (row.admissible_kn_over_ep > s.sweep_largest_kn_over_ep) {
        s.sweep_largest_kn_over_ep = row.admissible_kn_over_ep;
        s.sweep_largest_recommended_kn_over_ep = row.recommended_kn_over_ep;
        s.sweep_largest_poisson_ratio = nu;
      }
    }
  };
  static_cast<StabilityLimits&>(s) = AnalyseStabilityLimits<Dim>(
      packing, scene, options,
      options.sweep_poisson_ratios.empty()
          ? std::function<void(const LinearisedNetwork<Dim>&, const StabilityLimitOptions&)>()
          : sweep);
  return s;
}

template StabilitySummary AnalyseStability<2>(const Packing<2>&, const SceneOptions<2>&,
                                              const StabilityOptions&);
template StabilitySummary AnalyseStability<3>(const Packing<3>&, const SceneOptions<3>&,
                                              const StabilityOptions&);

}  // namespace specimen
