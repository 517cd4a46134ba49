#include "solver/particles.h"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <numeric>
#include <nlohmann/json.hpp>
#include <string>

#include "common/error.h"
#include "solver/bond_range.h"

namespace specimen {

namespace {

// MassScalingSummary (particles.h). The added mass at a floor t is
// f(t) = sum over bound_i < t of m_i ((t / bound_i)^2 - 1), continuous and increasing; between
// two consecutive sorted bounds it is t^2 S1 - S0 (S1 = sum m_i / bound_i^2, S0 = sum m_i over
// the particles below), so the floor with f(t) = budget x M is found in one sorted sweep.
template <int Dim>
MassScalingSummary ScaleLimitingInertia(const Packing<Dim>& packing,
                                        const MaterialParameters& material,
                                        ParticleArrays<Dim>* p) {
  MassScalingSummary summary;
  summary.budget = material.mass_scaling_budget;
  const int count = p->size();
  if (!(material.mass_scaling_budget > 0.0) || count < 2) return summary;
  constexpr double kMassRadiusOverInertia = Dim == 2 ? 2.0 : 2.5;  // as time_step.cpp
  const double per_contact = material.normal_stiffness_n_per_m +
                             material.tangential_stiffness_n_per_m * (1.0 + kMassRadiusOverInertia);
  if (!(per_contact > 0.0)) return summary;
  std::vector<int> contact_count(count, 0);
  // The packing's pairs, and with an interaction range the pairs within it, as the Simulation
  // bonds them (bond_range.h).
  const std::vector<std::array<int, 2>> pairs =
      material.bond_range > 1.0 ? BondCandidatePairs(packing, material.bond_range) : packing.contacts;
  for (const auto& pair : pairs) {
    if (pair[0] < 0 || pair[1] < 0 || pair[0] >= count || pair[1] >= count) continue;
    ++contact_count[pair[0]];
    ++contact_count[pair[1]];
  }
  // The bound up to the common factor 2 / sqrt(per_contact), which cancels in the ratios.
  std::vector<double> bound(count);
  double total_mass = 0.0;
  for (int i = 0; i < count; ++i) {
    bound[i] = std::sqrt(p->mass[i] / std::max(1, contact_count[i]));
    total_mass += p->mass[i];
  }
  std::vector<int> order(count);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return bound[a] < bound[b] || (bound[a] == bound[b] && a < b); });
  const double allowed = material.mass_scaling_budget * total_mass;
  double s0 = 0.0, s1 = 0.0, floor = bound[order[0]];
  for (int k = 0; k < count; ++k) {
    const int i = order[k];
    s0 += p->mass[i];
    s1 += p->mass[i] / (bound[i] * bound[i]);
    const double t = std::sqrt((allowed + s0) / s1);
    const double next = k + 1 < count ? bound[order[k + 1]] : t;
    if (t <= next) {
      floor = t;
      break;
    }
    floor = next;
  }
  double added = 0.0;
  for (int i = 0; i < count; ++i) {
    if (!(bound[i] < floor)) continue;
    const double factor = (floor / bound[i]) * (floor / bound[i]);
    added += p->mass[i] * (factor - 1.0);
    p->mass[i] *= factor;
    p->inverse_mass[i] /= factor;
    p->inverse_inertia[i] /= factor;
    ++summary.scaled_particles;
    summary.largest_factor = std::max(summary.largest_factor, factor);
  }
  summary.added_mass_share = added / total_mass;
  summary.bound_gain = floor / bound[order[0]];
  return summary;
}

}  // namespace

std::string MassScalingLine(const MassScalingSummary& m) {
  if (m.scaled_particles == 0) return "";
  char text[160];
  std::snprintf(text, sizeof text, "%d particles, mass +%.3g %% (budget %.3g %%), per-particle bound x%.3g",
                m.scaled_particles, 100 * m.added_mass_share, 100 * m.budget, m.bound_gain);
  return text;
}

nlohmann::json MassScalingJson(const MassScalingSummary& m) {
  return {{"budget", m.budget},
          {"scaled_particles", m.scaled_particles},
          {"added_mass_share", m.added_mass_share},
          {"largest_factor", m.largest_factor},
          {"bound_gain", m.bound_gain}};
}

template <int Dim>
ParticleArrays<Dim> BuildParticles(const Packing<Dim>& packing, const MaterialParameters& material,
                                   bool deformable) {
  const int count = packing.size();
  if (static_cast<int>(packing.centres.size()) != count)
    throw InputError("packing has " + std::to_string(packing.centres.size()) + " centres but " +
                     std::to_string(count) + " radii");
  if (count == 0) throw InputError("packing has no particles");
  ParticleArrays<Dim> p;
  p.position = packing.centres;
  p.velocity.assign(count, Vector<Dim>::Zero());
  p.angular_velocity.assign(count, ZeroAngular<Dim>());
  if (Dim == 2) p.rotation_angle.assign(count, 0.0);
  p.radius = packing.radii;
  p.mass.resize(count);
  p.inverse_mass.resize(count);
  p.inverse_inertia.resize(count);
  for (int i = 0; i < count; ++i) {
    const double r = packing.radii[i];
    if (!(r > 0.0) || !std::isfinite(r))
      throw InputError("radius of particle " + std::to_string(i) + " = " + std::to_string(r) +
                       " is not allowed: it must be finite and > 0");
    if (!packing.centres[i].allFinite())
      throw InputError("centre of particle " + std::to_string(i) + " is not a finite point");
    const double m = material.density_kg_per_m3 * ParticleVolume<Dim>(r);  // 2D: per unit thickness
    // Madan (2.3) cylinder J = m R^2 / 2, (2.4) sphere J = 2/5 m R^2.
    const double inertia = (Dim == 2 ? 0.5 : 0.4) * m * r * r;
    p.mass[i] = m;
    p.inverse_mass[i] = 1.0 / m;
    p.inverse_inertia[i] = 1.0 / inertia;
  }
  if (deformable) p.strain.assign(count, SymmetricTensor<Dim>::Zero());
  p.mass_scaling = ScaleLimitingInertia<Dim>(packing, material, &p);
  return p;
}

template ParticleArrays<2> BuildParticles<2>(const Packing<2>&, const MaterialParameters&, bool);
template ParticleArrays<3> BuildParticles<3>(const Packing<3>&, const MaterialParameters&, bool);

}  // namespace specimen
