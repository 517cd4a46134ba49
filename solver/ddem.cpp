#include "solver/ddem.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "solver/particle_update.h"
#include "solver/scene_state.h"
#include "common/format.h"

namespace specimen {

bool ForceIterationOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (max_iterations < 1)
    return fail("max_iterations = " + std::to_string(max_iterations) +
                " is not allowed: it must be >= 1");
  if (!(tolerance > 0.0 && tolerance < 1.0))
    return fail("tolerance = " + Number(tolerance) +
                " is not allowed: it must be in (0, 1)");
  if (!(divergence_factor > 1.0) || !std::isfinite(divergence_factor))
    return fail("divergence_factor = " + Number(divergence_factor) +
                " is not allowed: it must be finite and > 1");
  return true;
}

template <int Dim>
ForceIterationSummary IterateDeformedContactForces(SceneState<Dim>& s,
                                                   const ForceIterationOptions& options) {
  using Matrix = Eigen::Matrix<double, Dim, Dim>;
  std::string error;
  if (!options.IsValid(&error)) throw InputError("force iteration: " + error);
  if (s.particles.strain.empty())
    throw InputError(
        "the DDEM force iteration needs deformable particles "
        "(material.particle_youngs_modulus_pa)");
  ContactArrays<Dim>& c = s.contacts;
  if (options.watched_contact >= c.size())
    throw InputError(
        "force iteration: watched_contact = " + std::to_string(options.watched_contact) +
        " is not a contact (there are " + std::to_string(c.size()) + ")");
  ParticleArrays<Dim>& p = s.particles;
  const int count = p.size();

  // The external surface terms of the particle stress are fixed during the iteration:
  // point loads at the current time at their surface points, wall forces of the last step.
  std::vector<Matrix> external(count, Matrix::Zero());
  for (const PointLoadState<Dim>& state : s.loads) {
    const PointLoad<Dim>& load = state.load;
    if (load.application_direction.squaredNorm() == 0.0) continue;
    const Vector<Dim> force = load.force_n * load.amplitude(s.time_s);
    for (const int q : load.particles)
      external[q].noalias() += p.radius[q] * load.application_direction * force.transpose();
  }
  for (const WallState<Dim>& w : s.walls)
    for (size_t k = 0; k < w.particle.size(); ++k) {
      const int q = w.particle[k];
      const Vector<Dim>& push = w.PushDirection(k);
      const Vector<Dim> force = -w.normal_elastic_force[k] * push + w.tangential_force[k];
      external[q].noalias() += (-p.radius[q] * push) * force.transpose();
    }

  const double kn = s.law.normal_stiffness;
  ForceIterationSummary summary;
  auto watched = [&]() {
    if (options.watched_contact >= 0)
      summary.watched_normal_force_n.push_back(c.normal_elastic_force[options.watched_contact]);
  };
  watched();
  double first_change = 0.0, previous_change = 0.0;
  for (int iteration = 1; iteration <= options.max_iterations; ++iteration) {
    // Madan (3.5): stress from the current forces -> strain -> deformed overlap -> forces.
    for (int q = 0; q < count; ++q)
      p.strain[q] = s.compliance.Strain(ParticleStressFromContacts<Dim>(s, q, external[q]));
    s.deformation_step = -1;  // the contact pass's copy of the strains is stale
    double change = 0.0, largest = 0.0;
    for (int k = 0; k < c.size(); ++k) {
      const int i = c.pair[k][0], j = c.pair[k][1];
      const Vector<Dim> branch = p.position[j] - p.position[i];
      const double distance = branch.norm();
      const Vector<Dim> n = branch / distance;
      // Madan (2.53)-(2.54).
      const double gap = distance - (p.radius[i] + p.radius[j]) - c.reference_gap[k] -
                         p.radius[i] * QuadraticForm(p.strain[i], n) -
                         p.radius[j] * QuadraticForm(p.strain[j], n);
      double fn = kn * gap;
      if (c.state[k] != ContactState::kBonded) fn = std::min(fn, 0.0);
      change = std::max(change, std::abs(fn - c.normal_elastic_force[k]));
      largest = std::max(largest, std::abs(fn));
      c.normal_elastic_force[k] = fn;
      c.normal[k] = n;
      c.force[k] = fn * n;
      if (c.has_tangential()) {
        if (c.state[k] != ContactState::kBonded && fn == 0.0) c.tangential_force[k].setZero();
        c.force[k] += c.tangential_force[k];
      }
    }
    summary.iterations = iteration;
    summary.max_force_n = largest;
    summary.last_change_n = change;
    summary.change_ratio = previous_change > 0.0 ? change / previous_change : 0.0;
    watched();
    if (iteration == 1) first_change = change;
    previous_change = change;
    if (!std::isfinite(change) || change > options.divergence_factor * first_change) {
      summary.diverged = true;
      summary.termination = "diverged: the force change grew by more than " +
                            Number(options.divergence_factor) +
                            " (Madan (3.13): rho(B) > 1)";
      return summary;
    }
    if (change <= options.tolerance * largest) {
      summary.converged = true;
      summary.termination = "converged in " + std::to_string(iteration) + " iterations";
      return summary;
    }
  }
  summary.termination = "the iteration budget ran out before convergence";
  return summary;
}

template <int Dim>
double ParticleElasticEnergy(const SceneState<Dim>& s) {
  const ParticleArrays<Dim>& p = s.particles;
  if (p.strain.empty()) return 0.0;
  double energy = 0.0;
  for (int q = 0; q < p.size(); ++q) {
    const SymmetricTensor<Dim>& strain = p.strain[q];
    if (strain.squaredNorm() == 0.0) continue;
    // Madan (2.61). In plane strain sigma_zz does no work (eps_zz = 0); in plane stress
    // sigma_zz = 0: both leave the in-plane sigma : eps.
    energy += 0.5 * ParticleVolume<Dim>(p.radius[q]) *
              DoubleContraction<Dim>(s.compliance.Stress(strain), strain);
  }
  return energy;
}

template ForceIterationSummary IterateDeformedContactForces<2>(SceneState<2>&,
                                                               const ForceIterationOptions&);
template ForceIterationSummary IterateDeformedContactForces<3>(SceneState<3>&,
                                                               const ForceIterationOptions&);
template double ParticleElasticEnergy<2>(const SceneState<2>&);
template double ParticleElasticEnergy<3>(const SceneState<3>&);

}  // namespace specimen
