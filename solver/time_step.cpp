#include "solver/time_step.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "solver/bond_moment.h"

namespace specimen {

template <int Dim>
CriticalTimeStepEstimate PerParticleCriticalTimeStep(
    const ParticleArrays<Dim>& particles, const std::vector<std::array<int, 2>>& contacts,
    const MaterialParameters& material, const std::vector<double>& wall_stiffness) {
  const int count = particles.size();
  // m R^2 / J: 2 for discs (J = m R^2 / 2), 5/2 for spheres (J = 2/5 m R^2).
  constexpr double kMassRadiusOverInertia = Dim == 2 ? 2.0 : 2.5;
  const double kn = material.normal_stiffness_n_per_m;
  const double kt = material.tangential_stiffness_n_per_m;
  const double per_contact = kn + kt * (1.0 + kMassRadiusOverInertia);
  std::vector<int> contact_count(count, 0);
  for (const auto& pair : contacts) {
    ++contact_count[pair[0]];
    ++contact_count[pair[1]];
  }
  // A moment-carrying bond adds kb on the rotation of each end: omega^2 = kb / J, i.e.
  // kb (m R^2 / J) / R^2 on the scale of k_eff / m.
  std::vector<double> rotational(material.bonds_carry_moments() ? count : 0, 0.0);
  if (!rotational.empty()) {
    for (const auto& [i, j] : contacts) {
      const double k = BondRotationalStiffness<Dim>(particles.radius[i], particles.radius[j],
                                                    material.bond_radius_ratio, kn, kt);
      rotational[i] += k * kMassRadiusOverInertia / (particles.radius[i] * particles.radius[i]);
      rotational[j] += k * kMassRadiusOverInertia / (particles.radius[j] * particles.radius[j]);
    }
  }
  CriticalTimeStepEstimate estimate;
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < count; ++i) {
    double stiffness = std::max(1, contact_count[i]) * per_contact;
    if (!wall_stiffness.empty()) stiffness += wall_stiffness[i];
    if (!rotational.empty()) stiffness += rotational[i];
    const double step = 2.0 * std::sqrt(particles.mass[i] / stiffness);  // Madan (2.18)
    if (step < best) {
      best = step;
      estimate.limiting_particle = i;
      estimate.limiting_stiffness_n_per_m = stiffness;
    }
  }
  // Labra (2.53): viscous damping lowers the limit.
  double xi = material.normal_dashpot_ratio;
  if (kt > 0.0) xi = std::max(xi, material.tangential_dashpot_ratio);
  estimate.dashpot_factor = std::sqrt(1.0 + xi * xi) - xi;
  // Local damping stiffens the alternating mode by alpha k (time_step.h).
  const double alpha = std::max(material.translational_damping, material.rotational_damping);
  estimate.local_damping_factor = 1.0 / std::sqrt(1.0 + alpha);
  estimate.per_particle_bound_s = best * estimate.dashpot_factor * estimate.local_damping_factor;
  estimate.guaranteed_bound_s = estimate.per_particle_bound_s / std::sqrt(2.0);
  estimate.critical_time_step_s = estimate.per_particle_bound_s;
  estimate.method = "per-particle bound, Madan (2.16)-(2.18)";
  return estimate;
}

template <int Dim>
void EstimateDdemLagFactor(const ParticleArrays<Dim>& particles,
                           const std::vector<std::array<int, 2>>& contacts, double normal_stiffness,
                           const ParticleCompliance<Dim>& compliance,
                           const std::vector<double>& wall_stiffness,
                           CriticalTimeStepEstimate* estimate) {
  const double lambda = compliance.LargestEigenvalue();
  auto weight = [&](int q) {
    const double r = particles.radius[q];
    return r * r / ParticleVolume<Dim>(r);
  };
  double beta = 0.0;
  for (const auto& [i, j] : contacts)
    beta = std::max(beta, normal_stiffness * lambda * (weight(i) + weight(j)));
  for (size_t q = 0; q < wall_stiffness.size(); ++q)
    beta = std::max(beta, wall_stiffness[q] * lambda * weight(static_cast<int>(q)));
  estimate->ddem_ratio_estimate = beta;
  estimate->ddem_lag_factor = std::sqrt(1.0 - std::min(beta, 0.9));
}

template CriticalTimeStepEstimate PerParticleCriticalTimeStep<2>(
    const ParticleArrays<2>&, const std::vector<std::array<int, 2>>&, const MaterialParameters&,
    const std::vector<double>&);
template CriticalTimeStepEstimate PerParticleCriticalTimeStep<3>(
    const ParticleArrays<3>&, const std::vector<std::array<int, 2>>&, const MaterialParameters&,
    const std::vector<double>&);
template void EstimateDdemLagFactor<2>(const ParticleArrays<2>&,
                                       const std::vector<std::array<int, 2>>&, double,
                                       const ParticleCompliance<2>&, const std::vector<double>&,
                                       CriticalTimeStepEstimate*);
template void EstimateDdemLagFactor<3>(const ParticleArrays<3>&,
                                       const std::vector<std::array<int, 2>>&, double,
                                       const ParticleCompliance<3>&, const std::vector<double>&,
                                       CriticalTimeStepEstimate*);

}  // namespace specimen
