#include "solver/simulation.h"

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "common/error.h"
#include "solver/bond_moment.h"
#include "solver/bond_range.h"
#include "solver/scene_state.h"
#include "solver/stability_limits.h"
#include "common/format.h"

namespace specimen {

namespace {

void CheckIndices(const std::vector<int>& particles, int count, const std::string& what) {
  for (size_t k = 0; k < particles.size(); ++k)
    if (particles[k] < 0 || particles[k] >= count)
      throw InputError(what + ": particle index " + std::to_string(particles[k]) + " (entry " +
                       std::to_string(k) + ") is outside [0, " + std::to_string(count - 1) + "]");
}

// sum fn^2/(2 kn) + |ft|^2/(2 kt) (+ the bonds' moment energy, bond_moment.h) over contacts
// and wall contacts.
template <int Dim>
double ContactElasticEnergy(const SceneState<Dim>& s) {
  const ContactArrays<Dim>& c = s.contacts;
  const double kn = s.law.normal_stiffness, kt = s.law.tangential_stiffness;
  double energy = 0.0;
  for (int k = 0; k < c.size(); ++k)
    energy += 0.5 * c.normal_elastic_force[k] * c.normal_elastic_force[k] / kn;
  if (c.has_tangential() && kt > 0.0)
    for (int k = 0; k < c.size(); ++k) energy += 0.5 * c.tangential_force[k].squaredNorm() / kt;
  energy += BondMomentElasticEnergy<Dim>(c, s.particles.radius, s.law.bond_radius_ratio, kn, kt);
  for (const WallState<Dim>& w : s.walls) energy += w.ElasticEnergy();
  return energy;
}

// Merges the sorted candidate pairs into the sorted contact list: bonds stay whatever their
// distance, existing unbonded contacts stay (with their history) while they are candidates,
// new candidates enter as frictional contacts at rest.
template <int Dim>
void MergeCandidates(SceneState<Dim>& s) {
  const ContactArrays<Dim>& old = s.contacts;
  ContactArrays<Dim>& merged = s.contacts_scratch;
  merged.Clear();
  merged.Reserve(old.pair.size() + s.candidate_pairs.size());
  size_t a = 0, b = 0;
  const size_t old_count = old.pair.size(), new_count = s.candidate_pairs.size();
  while (a < old_count || b < new_count) {
    if (b == new_count || (a < old_count && old.pair[a] < s.candidate_pairs[b])) {
      if (old.state[a] == ContactState::kBonded) merged.AppendCopy(old, static_cast<int>(a));
      ++a;
    } else if (a == old_count || s.candidate_pairs[b] < old.pair[a]) {
      const auto [i, j] = s.candidate_pairs[b];
      const Vector<Dim> branch = s.particles.position[j] - s.particles.position[i];
      merged.AppendNew(i, j, ContactState::kFrictional, 0.0, branch.normalized());
      ++b;
    } else {
      merged.AppendCopy(old, static_cast<int>(a));
      ++a;
      ++b;
    }
  }
  std::swap(s.contacts, s.contacts_scratch);
}

}  // namespace

template <int Dim>
struct Simulation<Dim>::StepTotals {
  double max_force_n = 0.0;
  double max_unbalanced_force_n = 0.0;
  double mean_force_n = 0.0;
  int loaded_contacts = 0;
  bool finite = true;
  // Which pass produced a non-finite number (for the divergence message).
  bool contacts_finite = true, walls_finite = true, particles_finite = true;
};

// ---------------------------------------------------------------------------------------
// Construction.

template <int Dim>
Simulation<Dim>::Simulation(const Packing<Dim>& packing, const SceneOptions<Dim>& options)
    : state_(std::make_unique<SceneState<Dim>>()) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  if (!options.material.IsPhysical(Dim == 2 ? 1.0 : VolumeMeanRadius<Dim>(packing.radii), &error))
    throw InputError("material: " + error);
  SceneState<Dim>& s = *state_;
  const MaterialParameters& material = options.material;
  s.material = material;
  s.num_threads = options.num_threads;
  energy_growth_factor_ = options.divergence.energy_growth_factor;

  // 1. Particles at rest at the packing's centres.
  s.particles = BuildParticles<Dim>(packing, material, material.deformable());
  const int count = s.particles.size();
  if (material.deformable())
    s.compliance = ParticleCompliance<Dim>(*material.particle_youngs_modulus_pa,
                                           material.particle_poisson_ratio, material.plane_model);
  for (size_t k = 0; k < options.point_loads.size(); ++k)
    CheckIndices(options.point_loads[k].particles, count,
                 "point load " + std::to_string(k) + " (\"" + options.point_loads[k].name + "\")");
  for (const WallOptions<Dim>& wall : options.walls)
    CheckIndices(wall.jaw_particles, count, "wall \"" + wall.name + "\" jaw_particles");
  for (size_t k = 0; k < options.fixed_dofs.size(); ++k)
    CheckIndices(options.fixed_dofs[k].particles, count,
                 "fixed dofs " + std::to_string(k) + " (\"" + options.fixed_dofs[k].name + "\")");

  // 2. The stages this scene needs.
  plan_.deformable = material.deformable();
  plan_.breakable = material.breakable();
  plan_.tangential = material.tangential_stiffness_n_per_m > 0.0;
  plan_.bond_moments = material.bonds_carry_moments();
  plan_.dashpots = material.normal_dashpot_ratio > 0.0 ||
                   (plan_.tangential && material.tangential_dashpot_ratio > 0.0);
  plan_.local_damping = material.translational_damping > 0.0 || material.rotational_damping > 0.0;
  plan_.walls = !options.walls.empty();
  for (const auto& w : options.walls) plan_.wall_friction = plan_.wall_friction || w.friction();
  plan_.point_loads = !options.point_loads.empty();
  plan_.fixed_dofs = !options.fixed_dofs.empty();
  plan_.neighbour_search = options.contacts.detect_new_contacts;

  // 3. Bonds: the packing's pairs within the gap tolerance (Madan (2.21)), and the pairs
  // within the interaction range (bond_range.h).
  s.contacts.tangential_enabled = plan_.tangential;
  s.contacts_scratch.tangential_enabled = plan_.tangential;
  s.contacts.moments_enabled = plan_.bond_moments;
  s.contacts_scratch.moments_enabled = plan_.bond_moments;
  for (const auto& pair : packing.contacts)
    if (pair[0] < 0 || pair[0] >= count || pair[1] < 0 || pair[1] >= count || pair[0] == pair[1])
      throw InputError("packing contact (" + std::to_string(pair[0]) + ", " +
                       std::to_string(pair[1]) + ") does not join two distinct particles of [0, " +
                       std::to_string(count - 1) + "]");
  const double bond_range = options.material.bond_range;
  const std::vector<std::array<int, 2>> pairs = BondCandidatePairs(packing, bond_range);
  s.contacts.Reserve(pairs.size());
  for (const auto& [i, j] : pairs) {
    const Vector<Dim> branch = s.particles.position[j] - s.particles.position[i];
    const double distance = branch.norm();
    if (!(distance > 0.0))
      throw InputError("particles " + std::to_string(i) + " and " + std::to_string(j) +
                       " of a packing contact have the same centre");
    const double ri = s.particles.radius[i], rj = s.particles.radius[j];
    const double gap = distance - (ri + rj);  // as the contact law forms it (exact zero force)
    if (std::abs(gap) <= options.contacts.bond_gap_tolerance * 0.5 * (ri + rj) ||
        WithinBondRange(distance, ri, rj, bond_range)) {
      s.contacts.AppendNew(i, j, ContactState::kBonded,
                           options.contacts.stress_free_bonds ? gap : 0.0, branch / distance);
      ++s.bonds_created;
    } else {
      s.contacts.AppendNew(i, j, ContactState::kFrictional, 0.0, branch / distance);
      ++s.packing_pairs_not_bonded;
    }
  }

  // 4. Walls, loads, prescribed degrees of freedom.
  for (const WallOptions<Dim>& o : options.walls) {
    WallState<Dim> w;
    w.options = o;
    w.normal = o.normal.normalized();
    w.point = o.point;
    if (o.conforming()) StartJaw(w, s.particles.position);
    s.walls.push_back(std::move(w));
  }
  for (const PointLoad<Dim>& load : options.point_loads) {
    PointLoadState<Dim> state;
    state.load = load;
    if (load.application_direction.squaredNorm() > 0.0)
      state.load.application_direction.normalize();
    state.surface_displacement.assign(load.particles.size(), Vector<Dim>::Zero());
    s.loads.push_back(std::move(state));
  }
  if (plan_.fixed_dofs) {
    ConstraintTable<Dim>& t = s.constraints;
    t.sets = options.fixed_dofs;
    t.amplitude.assign(t.sets.size(), 1.0);
    t.slot_of_particle.assign(count, -1);
    for (size_t set = 0; set < t.sets.size(); ++set) {
      const FixedDofs<Dim>& f = t.sets[set];
      for (size_t k = 0; k < f.particles.size(); ++k) {
        const int q = f.particles[k];
        int slot = t.slot_of_particle[q];
        if (slot < 0) {
          slot = static_cast<int>(t.particle.size());
          t.slot_of_particle[q] = slot;
          t.particle.push_back(q);
          std::array<int, Dim + 1> free_axes;
          free_axes.fill(-1);
          t.set_of_axis.push_back(free_axes);
          t.velocity.push_back(Vector<Dim>::Zero());
          t.reaction_force.push_back(Vector<Dim>::Zero());
          t.reaction_torque.push_back(ZeroAngular<Dim>());
        }
        const Vector<Dim>& v =
            f.particle_velocities.empty() ? f.velocity : f.particle_velocities[k];
        for (int axis = 0; axis < Dim; ++axis)
          if (f.fix_translation[axis]) {
            t.set_of_axis[slot][axis] = static_cast<int>(set);
            t.velocity[slot][axis] = v[axis];
          }
        if (f.fix_rotation) t.set_of_axis[slot][Dim] = static_cast<int>(set);
      }
    }
  }

  // 5. Neighbour search and wall candidates.
  s.search_skin_m = options.contacts.search_skin * VolumeMeanRadius<Dim>(s.particles.radius);
  s.max_radius_m = *std::max_element(s.particles.radius.begin(), s.particles.radius.end());
  const std::vector<std::array<int, 2>> initial_pairs = s.contacts.pair;
  Search();

  // 6. Time step against the critical one.
  constexpr double kMassRadiusOverInertia = Dim == 2 ? 2.0 : 2.5;
  std::vector<double> wall_stiffness;
  stiffest_spring_n_per_m_ =
      std::max(material.normal_stiffness_n_per_m, material.tangential_stiffness_n_per_m);
  if (plan_.walls) {
    wall_stiffness.assign(count, 0.0);
    for (const WallState<Dim>& w : s.walls) {
      const double k = w.options.normal_stiffness_n_per_m +
                       w.options.tangential_stiffness_n_per_m * (1.0 + kMassRadiusOverInertia);
      // A jaw: the spring K w_k on each of its particles bounds K w w^T (walls.h).
      for (size_t j = 0; j < w.particle.size(); ++j)
        wall_stiffness[w.particle[j]] += w.options.conforming() ? w.options.JawStiffness() * w.jaw_weight[j] : k;
      // A jaw's particle k carries the share w_k of K p: a spring of K w_k^2 per its travel.
      for (const double share : w.jaw_weight)
        stiffest_spring_n_per_m_ = std::max(stiffest_spring_n_per_m_, w.options.JawStiffness() * share * share);
      stiffest_spring_n_per_m_ =
          std::max({stiffest_spring_n_per_m_, w.options.normal_stiffness_n_per_m,
                    w.options.tangential_stiffness_n_per_m});
    }
  }
  critical_ =
      PerParticleCriticalTimeStep<Dim>(s.particles, initial_pairs, material, wall_stiffness);
  if (plan_.deformable) {
    std::vector<double> wall_normal_stiffness;
    if (plan_.walls) {
      wall_normal_stiffness.assign(count, 0.0);
      for (const WallState<Dim>& w : s.walls)
        for (size_t j = 0; j < w.particle.size(); ++j)
          wall_normal_stiffness[w.particle[j]] += w.options.conforming()
                                                      ? w.options.JawStiffness() * w.jaw_weight[j]
                                                      : w.options.normal_stiffness_n_per_m;
    }
    EstimateDdemLagFactor<Dim>(s.particles, initial_pairs, material.normal_stiffness_n_per_m,
                               s.compliance, wall_normal_stiffness, &critical_);
  }
  // A force-driven wall is a mass on the springs of the particles it may touch.
  for (const WallState<Dim>& w : s.walls) {
    if (w.options.drive != WallDrive::kForce) continue;
    const double k = std::max<size_t>(1, w.particle.size()) *
                     (w.options.normal_stiffness_n_per_m + w.options.tangential_stiffness_n_per_m);
    const double step = 2.0 * std::sqrt(w.options.mass_kg / k) * critical_.dashpot_factor *
                        critical_.local_damping_factor;
    if (step < critical_.per_particle_bound_s) {
      critical_.per_particle_bound_s = step;
      critical_.guaranteed_bound_s = step / std::sqrt(2.0);
      critical_.critical_time_step_s = step;
      critical_.limiting_particle = -1;
      critical_.limiting_stiffness_n_per_m = k;
      critical_.method += ", limited by the force-driven wall \"" + w.options.name + "\"";
    }
  }
  double analysed_critical_step_s = 0.0;
  if (options.time_step.from_stability_analysis) {
    // The certified limit of the assembled network (stability_limits.h): it includes the
    // DDEM strain lag, so no separate lag factor; and the DDEM convergence check.
    StabilityLimitOptions stability;
    stability.locate_mode = false;
    stability.wall_reach_m = s.search_skin_m;
    stability.max_spectral_radius = options.time_step.max_spectral_radius;
    const StabilityLimits analysis = AnalyseStabilityLimits<Dim>(packing, options, stability);
    if (analysis.deformable &&
        analysis.spectral_radius >= options.time_step.max_spectral_radius &&
        !options.time_step.allow_above_critical)
      throw InputError(
          "the DDEM force iteration does not converge: rho(B) = " +
          Number(analysis.spectral_radius) + " >= time_step.max_spectral_radius = " +
          Number(options.time_step.max_spectral_radius) + " (kn/(Ep l) = " +
          Number(analysis.kn_over_ep) + ", admissible below " +
          Number(analysis.admissible_kn_over_ep * options.time_step.max_spectral_radius) +
          ", i.e. Ep above " +
          Number(analysis.unit_spectral_radius_pa / options.time_step.max_spectral_radius) +
          " Pa); raise Ep or lower kn, or set time_step.allow_above_critical to run anyway");
    critical_.critical_time_step_s = analysis.critical_time_step_s;
    critical_.ddem_lag_factor = 1.0;
    critical_.limiting_particle = -1;  // the per-particle bound's; not the analysis' limit
    critical_.method = "stability analysis: " + analysis.critical_time_step_method;
    stability_note_ = analysis.BriefReport();
    analysed_critical_step_s = analysis.critical_time_step_s;
  }
  if (options.time_step.critical_time_step_s > 0.0) {
    critical_.critical_time_step_s = options.time_step.critical_time_step_s;
    critical_.method = "given (TimeStepOptions::critical_time_step_s)";
  }
  double dt = options.time_step.time_step_s;
  s.time_step_given_s = dt;
  if (dt > 0.0) {
    time_step_above_critical_ = dt > critical_.critical_time_step_s;
    if (time_step_above_critical_ && !options.time_step.allow_above_critical)
      throw InputError("time_step_s = " + Number(dt) + " s is above the critical time step " +
                       Number(critical_.critical_time_step_s) + " s (" + critical_.method +
                       (critical_.limiting_particle >= 0
                            ? ", limiting particle " + std::to_string(critical_.limiting_particle)
                            : std::string()) +
                       "); lower it, or set time_step.allow_above_critical to run anyway");
  } else {
    dt = options.time_step.safety_factor * critical_.critical_time_step_s *
         critical_.ddem_lag_factor;
  }
  s.time_step_s = dt;
  // The analysis judges its own recommended step; a divergence message should quote the
  // step this run takes.
  if (analysed_critical_step_s > 0.0)
    stability_note_ += "; this run's step " + Number(dt) + " s is " +
                       Number(100.0 * dt / analysed_critical_step_s, 3) + " % of dt_cr";
  s.law.normal_stiffness = material.normal_stiffness_n_per_m;
  s.law.tangential_stiffness = material.tangential_stiffness_n_per_m;
  s.law.tensile_strength = material.bond_tensile_strength_n;
  s.law.shear_strength = material.bond_shear_strength_n;
  s.law.friction = material.friction_coefficient;
  s.law.bond_radius_ratio = material.bond_radius_ratio;
  s.law.normal_dashpot_ratio = material.normal_dashpot_ratio;
  s.law.tangential_dashpot_ratio = material.tangential_dashpot_ratio;
  s.law.time_step = dt;

  // 7. External accumulators and the pass instantiations.
  ChooseStages();
  // 8. Large scenes: particles renumbered along a space-filling curve (scene_state.h).
  ApplySpatialOrder(s);
}

template <int Dim>
Simulation<Dim>::~Simulation() = default;
template <int Dim>
Simulation<Dim>::Simulation(Simulation&&) noexcept = default;
template <int Dim>
Simulation<Dim>& Simulation<Dim>::operator=(Simulation&&) noexcept = default;

template <int Dim>
void Simulation<Dim>::ChooseStages() {
  SceneState<Dim>& s = *state_;
  // Rotation exists when something can apply a moment, or a particle already spins.
  bool rotation = plan_.tangential || plan_.wall_friction || plan_.bond_moments;
  for (const PointLoadState<Dim>& state : s.loads) {
    const PointLoad<Dim>& load = state.load;
    if constexpr (Dim == 2) {
      rotation = rotation || Cross(load.application_direction, load.force_n) != 0.0;
    } else {
      rotation = rotation || Cross(load.application_direction, load.force_n).squaredNorm() > 0.0;
    }
  }
  for (const Angular<Dim>& w : s.particles.angular_velocity)
    if (AngularNorm(w) > 0.0) {
      rotation = true;
      break;
    }
  plan_.rotation = rotation;
  const int count = s.particles.size();
  if (plan_.external()) {
    if (s.external_force.empty()) s.external_force.assign(count, Vector<Dim>::Zero());
    if (plan_.rotation && s.external_torque.empty())
      s.external_torque.assign(count, ZeroAngular<Dim>());
    if (plan_.deformable && s.external_moment.empty())
      s.external_moment.assign(count, Eigen::Matrix<double, Dim, Dim>::Zero());
  }
  contact_pass_ = SelectContactPass<Dim>(plan_);
  particle_pass_ = SelectParticlePass<Dim>(plan_);
}

// ---------------------------------------------------------------------------------------
// Neighbour search.

template <int Dim>
bool Simulation<Dim>::SearchNeeded() const {
  const SceneState<Dim>& s = *state_;
  const double strain_growth =
      plan_.deformable ? std::max(0.0, s.max_strain - s.strain_margin_at_search) : 0.0;
  // Two particles approach by at most twice the largest displacement; their deformed
  // surfaces bulge by at most R_max |eps| each (Madan (2.52): a surface point moves by eps s).
  if (plan_.neighbour_search &&
      2.0 * s.displacement_since_search_m + 2.0 * s.max_radius_m * strain_growth >= s.search_skin_m)
    return true;
  for (const WallState<Dim>& w : s.walls)
    if (s.displacement_since_search_m + w.displacement_since_search +
            s.max_radius_m * strain_growth >=
        s.search_skin_m)
      return true;
  return false;
}

template <int Dim>
void Simulation<Dim>::Search() {
  SceneState<Dim>& s = *state_;
  const double strain_margin = plan_.deformable ? s.max_strain : 0.0;
  if (plan_.neighbour_search) {
    s.search.FindPairs(s.particles.position, s.particles.radius,
                       s.search_skin_m + 2.0 * s.max_radius_m * strain_margin, &s.candidate_pairs);
    MergeCandidates(s);
  }
  RebuildAdjacency(s);
  if (plan_.walls) RebuildWallCandidates(s, s.search_skin_m + s.max_radius_m * strain_margin);
  s.displacement_since_search_m = 0.0;
  s.strain_margin_at_search = strain_margin;
  ++s.searches;
}

// ---------------------------------------------------------------------------------------
// The step.

template <int Dim>
void Simulation<Dim>::Step(StepTotals* totals) {
  SceneState<Dim>& s = *state_;
  const double dt = s.time_step_s;
  if (SearchNeeded()) Search();

  ContactPassTotals contact;
  contact_pass_(s, &contact);
  WallPassTotals wall;
  if (plan_.walls) WallPass<Dim>(s, plan_.deformable, plan_.rotation, plan_.dashpots, &wall);
  PointLoadWork load;
  if (plan_.point_loads) PointLoadPass<Dim>(s, plan_.deformable, plan_.rotation, &load);
  if (plan_.fixed_dofs)
    for (size_t set = 0; set < s.constraints.sets.size(); ++set)
      s.constraints.amplitude[set] = s.constraints.sets[set].amplitude(s.time_s + 0.5 * dt);
  ParticlePassTotals particle;
  particle_pass_(s, &particle);

  // Bookkeeping.
  EnergyAccumulators& e = s.energy;
  e.load_work_j += load.centre_j + load.deformation_j;
  e.load_deformation_work_j += load.deformation_j;
  e.wall_work_j += wall.work_j;
  e.constraint_work_j += particle.constraint_work_j;
  e.damping_dissipation_j += particle.damping_dissipation_j + wall.damping_dissipation_j;
  e.dashpot_dissipation_j += contact.dashpot_dissipation_j + wall.dashpot_dissipation_j;
  e.friction_dissipation_j += contact.friction_dissipation_j + wall.friction_dissipation_j;
  e.breakage_release_j += contact.breakage_release_j;
  e.supplied_j += load.supplied_j + wall.supplied_j + particle.constraint_supplied_j;
  e.kinetic_j = particle.kinetic_energy_j + wall.kinetic_energy_j;
  if (!e.initial_recorded) {
    e.initial_total_j = e.kinetic_j + ContactElasticEnergy(s) + ParticleElasticEnergy(s);
    e.supplied_j += std::abs(e.initial_total_j);
    e.initial_recorded = true;
  }
  s.broken_in_tension += contact.broken_in_tension;
  s.broken_in_shear += contact.broken_in_shear;
  s.max_strain = particle.max_strain;
  s.displacement_since_search_m += particle.max_speed * dt;
  ++s.step;
  s.time_s = static_cast<double>(s.step) * dt;

  totals->max_force_n = std::max(contact.max_force_n, wall.max_force_n);
  totals->max_unbalanced_force_n = particle.max_unbalanced_force_n;
  totals->loaded_contacts = contact.loaded_contacts;
  totals->mean_force_n = contact.loaded_contacts > 0
                             ? std::sqrt(contact.sum_force_squared_n2 / contact.loaded_contacts)
                             : 0.0;
  totals->finite = contact.finite && wall.finite && particle.finite;
  totals->contacts_finite = contact.finite;
  totals->walls_finite = wall.finite;
  totals->particles_finite = particle.finite;
}

template <int Dim>
RunSummary Simulation<Dim>::Run(const RunOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  SceneState<Dim>& s = *state_;
  ChooseStages();
  RunSummary summary;
  summary.first_step = s.step;
  summary.start_time_s = s.time_s;
  const long broken_tension_at_start = s.broken_in_tension;
  const long broken_shear_at_start = s.broken_in_shear;
  searches_at_run_start_ = s.searches;

  long target = options.max_steps > 0 ? options.max_steps : LONG_MAX;
  bool by_duration = false;
  if (options.duration_s > 0.0) {
    const long duration_steps = std::lround(options.duration_s / s.time_step_s);
    if (duration_steps <= target) {
      target = duration_steps;
      by_duration = true;
    }
  }
  const auto start = std::chrono::steady_clock::now();
  const long progress_interval = std::max(1L, target / 100);
  summary.termination = by_duration ? TerminationReason::kDuration : TerminationReason::kStepLimit;
  for (long k = 1; k <= target; ++k) {
    StepTotals t;
    Step(&t);
    last_loaded_contacts_ = t.loaded_contacts;
    last_unbalanced_ratio_ = t.mean_force_n > 0.0 ? t.max_unbalanced_force_n / t.mean_force_n : 0.0;

    // Divergence (docs/solver.md, "Divergence detection": NaN, energy or force growth stops
    // the run, naming the step).
    const double supplied = std::max(s.energy.supplied_j, std::numeric_limits<double>::min());
    if (!t.finite) {
      std::string where;
      const ParticleArrays<Dim>& p = s.particles;
      for (int q = 0; q < p.size() && where.empty(); ++q)
        if (!p.position[q].allFinite() || !p.velocity[q].allFinite())
          where = "the velocity of particle " + std::to_string(s.order.External(q));
        else if (!AngularIsFinite(p.angular_velocity[q]))
          where = "the angular velocity of particle " + std::to_string(s.order.External(q));
      for (int c = 0; c < s.contacts.size() && where.empty(); ++c)
        if (!s.contacts.force[c].allFinite())
          where = "the force of contact " + std::to_string(s.order.External(s.contacts.pair[c][0])) +
                  "-" + std::to_string(s.order.External(s.contacts.pair[c][1]));
      for (const WallState<Dim>& w : s.walls)
        if (where.empty() && !t.walls_finite && !w.force_on_wall.allFinite())
          where = "the reaction of wall \"" + w.options.name + "\"";
      if (where.empty())
        where = !t.particles_finite ? "the kinetic energy or the unbalanced force (a sum over the particles)"
                                    : "a contact or wall force sum";
      Diverged(where + " became NaN or infinite", &summary);
    }
    if (std::abs(s.energy.kinetic_j) > energy_growth_factor_ * supplied)
      Diverged("the kinetic energy grew to " + Number(std::abs(s.energy.kinetic_j)) +
                   " J, more than " + Number(energy_growth_factor_) +
                   " times the energy supplied so far (" + Number(supplied) + " J)",
               &summary);
    const double force_bound =
        std::sqrt(energy_growth_factor_ * 2.0 * stiffest_spring_n_per_m_ * supplied);
    if (t.max_force_n > force_bound)
      Diverged("the largest contact force grew to " + Number(t.max_force_n) + " N, more than " +
                   Number(force_bound) + " N, the force of a spring of stiffness " +
                   Number(stiffest_spring_n_per_m_) + " N/m holding " +
                   Number(energy_growth_factor_) + " times the energy supplied so far (" +
                   Number(supplied) + " J)",
               &summary);

    if (options.static_force_ratio > 0.0 && k >= options.min_steps &&
        k % options.static_check_interval == 0 && t.loaded_contacts > 0 &&
        last_unbalanced_ratio_ <= options.static_force_ratio) {
      summary.termination = TerminationReason::kStatic;
      break;
    }
    if (options.observe_interval > 0 && options.observer && k % options.observe_interval == 0)
      options.observer();
    if (options.progress && k % progress_interval == 0 && target != LONG_MAX)
      options.progress(static_cast<double>(k) / target, "step " + std::to_string(s.step));
  }
  summary.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary.broken_in_tension_this_run = s.broken_in_tension - broken_tension_at_start;
  summary.broken_in_shear_this_run = s.broken_in_shear - broken_shear_at_start;
  FillSummary(&summary);
  switch (summary.termination) {
    case TerminationReason::kStatic:
      summary.termination_message = "static: unbalanced force ratio " +
                                    Number(summary.unbalanced_force_ratio, 3) +
                                    " <= " + Number(options.static_force_ratio, 3);
      break;
    case TerminationReason::kDuration:
      summary.termination_message = "reached the run duration " + Number(options.duration_s) + " s";
      break;
    default:
      summary.termination_message = "reached the step limit " + std::to_string(summary.steps);
  }
  last_summary_ = summary;
  external_view_.RefreshIfHeld(s);
  return summary;
}

template <int Dim>
void Simulation<Dim>::Diverged(const std::string& what, RunSummary* summary) {
  const SceneState<Dim>& s = *state_;
  std::string message = "the run diverged at step " + std::to_string(s.step - 1) +
                        " (t = " + Number(s.time_s - s.time_step_s) + " s): " + what + ".";
  if (time_step_above_critical_)
    message += " The time step " + Number(s.time_step_s) + " s is above the critical time step " +
               Number(critical_.critical_time_step_s) + " s (allowed by allow_above_critical).";
  if (plan_.deformable && stability_note_.empty())
    message +=
        " DDEM also needs the force iteration to converge, rho(B) < 1: kn/(Ep l) below "
        "about pi/(4 (1 + nu_p)) (SC lattice, Madan (3.42)) or the HCP limit (3.78).";
  if (!stability_note_.empty()) message += " Stability analysis of the scene: " + stability_note_ + ".";
  summary->termination = TerminationReason::kDiverged;
  summary->termination_message = message;
  FillSummary(summary);
  last_summary_ = *summary;
  throw ComputationError(message);
}

template <int Dim>
void Simulation<Dim>::FillSummary(RunSummary* summary) const {
  const SceneState<Dim>& s = *state_;
  summary->dimension = Dim;
  if (plan_.deformable) {
    const MaterialParameters& m = s.material;
    summary->particle_model = "deformable (DDEM): Ep = " + Number(*m.particle_youngs_modulus_pa) +
                              " Pa, nu_p = " + Number(m.particle_poisson_ratio) +
                              (Dim == 2 ? ", " + PlaneModelName(m.plane_model) : ", 3D isotropic");
  } else {
    summary->particle_model = "rigid";
  }
  summary->time_step_given_s = s.time_step_given_s;
  summary->packing_pairs_not_bonded = s.packing_pairs_not_bonded;
  summary->memory_bytes = MemoryBytes(s);
  summary->steps = s.step - summary->first_step;
  summary->end_time_s = s.time_s;
  summary->time_step_s = s.time_step_s;
  summary->critical_time_step = critical_;
  summary->time_step_above_critical = time_step_above_critical_;
  summary->stages = plan_.StageNames();
  summary->omitted_stages = plan_.OmittedStageNames();
  summary->particles = s.particles.size();
  summary->contacts = s.contacts.size();
  summary->loaded_contacts = last_loaded_contacts_;
  summary->bonds_created = s.bonds_created;
  summary->bonds_intact = IntactBondCount();
  summary->broken_in_tension = s.broken_in_tension;
  summary->broken_in_shear = s.broken_in_shear;
  summary->neighbour_searches = s.searches - searches_at_run_start_;
  summary->unbalanced_force_ratio = last_unbalanced_ratio_;
  summary->energy = Energy();
  summary->walls.clear();
  for (const WallState<Dim>& w : s.walls) {
    WallReport r;
    r.name = w.options.name;
    r.point_m.assign(w.point.data(), w.point.data() + Dim);
    r.force_on_wall_n.assign(w.force_on_wall.data(), w.force_on_wall.data() + Dim);
    r.normal_reaction_n = w.NormalReaction();
    for (double f : w.normal_elastic_force) r.touching_particles += f != 0.0 ? 1 : 0;
    summary->walls.push_back(r);
  }
  summary->fixed_dofs.clear();
  for (size_t set = 0; set < s.constraints.sets.size(); ++set) {
    ConstraintReport r;
    r.name = s.constraints.sets[set].name;
    const Vector<Dim> reaction = FixedDofsReaction(static_cast<int>(set));
    r.reaction_force_n.assign(reaction.data(), reaction.data() + Dim);
    summary->fixed_dofs.push_back(r);
  }
  summary->particle_steps_per_second =
      summary->wall_seconds > 0.0
          ? static_cast<double>(summary->steps) * s.particles.size() / summary->wall_seconds
          : 0.0;
}

// ---------------------------------------------------------------------------------------
// Accessors.

template <int Dim>
double Simulation<Dim>::time_step_s() const {
  return state_->time_step_s;
}
template <int Dim>
long Simulation<Dim>::step() const {
  return state_->step;
}
template <int Dim>
double Simulation<Dim>::time_s() const {
  return state_->time_s;
}
template <int Dim>
const ParticleArrays<Dim>& Simulation<Dim>::particles() const {
  return external_view_.Get(*state_).particles;
}
template <int Dim>
const ContactArrays<Dim>& Simulation<Dim>::contacts() const {
  return external_view_.Get(*state_).contacts;
}
template <int Dim>
int Simulation<Dim>::wall_count() const {
  return static_cast<int>(state_->walls.size());
}
template <int Dim>
const WallState<Dim>& Simulation<Dim>::wall(int index) const {
  if (index < 0 || index >= wall_count())
    throw InputError("wall index " + std::to_string(index) + " is outside [0, " +
                     std::to_string(wall_count() - 1) + "]");
  return external_view_.Get(*state_).walls[index];
}

template <int Dim>
Vector<Dim> Simulation<Dim>::FixedDofsReaction(int set) const {
  const ConstraintTable<Dim>& t = state_->constraints;
  if (set < 0 || set >= static_cast<int>(t.sets.size()))
    throw InputError("fixed dofs set " + std::to_string(set) + " does not exist");
  Vector<Dim> sum = Vector<Dim>::Zero();
  for (size_t slot = 0; slot < t.particle.size(); ++slot)
    for (int axis = 0; axis < Dim; ++axis)
      if (t.set_of_axis[slot][axis] == set) sum[axis] += t.reaction_force[slot][axis];
  return sum;
}

template <int Dim>
EnergyBalance Simulation<Dim>::Energy() const {
  const SceneState<Dim>& s = *state_;
  const EnergyAccumulators& e = s.energy;
  EnergyBalance b;
  b.kinetic_j = e.kinetic_j;
  b.contact_elastic_j = ContactElasticEnergy(s);
  b.particle_elastic_j = ParticleElasticEnergy(s);
  b.initial_total_j = e.initial_total_j;
  const double pending = PendingDeformationWork(s);
  b.load_work_j = e.load_work_j + pending;
  b.load_deformation_work_j = e.load_deformation_work_j + pending;
  b.wall_work_j = e.wall_work_j;
  b.constraint_work_j = e.constraint_work_j;
  b.damping_dissipation_j = e.damping_dissipation_j;
  b.dashpot_dissipation_j = e.dashpot_dissipation_j;
  b.friction_dissipation_j = e.friction_dissipation_j;
  b.breakage_release_j = e.breakage_release_j;
  return b;
}

template <int Dim>
SymmetricTensor<Dim> Simulation<Dim>::ParticleStress(int particle) const {
  if (particle < 0 || particle >= state_->particles.size())
    throw InputError("particle index " + std::to_string(particle) + " is out of range");
  if (!plan_.deformable) return SymmetricTensor<Dim>::Zero();
  return state_->compliance.Stress(state_->particles.strain[state_->order.Internal(particle)]);
}

template <int Dim>
int Simulation<Dim>::IntactBondCount() const {
  return static_cast<int>(std::count(state_->contacts.state.begin(), state_->contacts.state.end(),
                                     ContactState::kBonded));
}

template <int Dim>
void Simulation<Dim>::SetVelocity(int particle, const Vector<Dim>& velocity) {
  if (particle < 0 || particle >= state_->particles.size() || !velocity.allFinite())
    throw InputError("SetVelocity: particle " + std::to_string(particle) +
                     " is out of range or the velocity is not finite");
  state_->particles.velocity[state_->order.Internal(particle)] = velocity;
  external_view_.Invalidate();
}

template <int Dim>
void Simulation<Dim>::SetAngularVelocity(int particle, const Angular<Dim>& angular_velocity) {
  if (particle < 0 || particle >= state_->particles.size() || !AngularIsFinite(angular_velocity))
    throw InputError("SetAngularVelocity: particle " + std::to_string(particle) +
                     " is out of range or the angular velocity is not finite");
  state_->particles.angular_velocity[state_->order.Internal(particle)] = angular_velocity;
  external_view_.Invalidate();
}

template <int Dim>
void Simulation<Dim>::SetWallOptions(int index, const WallOptions<Dim>& options) {
  wall(index);  // throws for an index out of range
  WallState<Dim>& w = state_->walls[index];
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  const WallOptions<Dim>& old = w.options;
  if (options.normal_stiffness_n_per_m != old.normal_stiffness_n_per_m ||
      options.tangential_stiffness_n_per_m != old.tangential_stiffness_n_per_m ||
      options.friction_coefficient != old.friction_coefficient ||
      (options.drive == WallDrive::kForce) != (old.drive == WallDrive::kForce) ||
      options.jaw_particles != old.jaw_particles || options.jaw_weights != old.jaw_weights ||
      options.jaw_inward != old.jaw_inward)
    throw InputError("SetWallOptions: wall \"" + old.name +
                     "\" may change its drive, but not its stiffnesses, friction, mass "
                     "(force drive) or jaw, which bound the time step");
  for (const auto& pair : options.servo.area_wall_pairs)
    for (const int other : pair) wall(other);  // throws for an index out of range
  w.options = options;
  w.servo_error_integral_n_s = 0.0;
  external_view_.Invalidate();
}

template <int Dim>
ForceIterationSummary Simulation<Dim>::IterateDeformedContactForces(
    const ForceIterationOptions& options) {
  ForceIterationOptions internal = options;  // the watched contact in contacts() order
  if (options.watched_contact >= 0 && options.watched_contact < state_->contacts.size())
    internal.watched_contact = external_view_.InternalContact(*state_, options.watched_contact);
  external_view_.Invalidate();
  return specimen::IterateDeformedContactForces<Dim>(*state_, internal);
}

template class Simulation<2>;
template class Simulation<3>;

}  // namespace specimen
