#include "solver/particle_update.h"

#include <algorithm>
#include <cmath>

#include "solver/scene_state.h"
#include "solver/step_plan.h"

namespace specimen {

namespace {

constexpr double kPi = 3.14159265358979323846;

template <int Dim>
inline double Volume(double r) {
  if constexpr (Dim == 2) {
    return kPi * r * r;  // per unit thickness
  } else {
    return 4.0 / 3.0 * kPi * r * r * r;
  }
}

template <int Dim, bool kDeformable, bool kDamping, bool kRotation, bool kExternal,
          bool kConstraints>
void ParticlePass(SceneState<Dim>& s, ParticlePassTotals* totals) {
  using Matrix = Eigen::Matrix<double, Dim, Dim>;
  ParticleArrays<Dim>& p = s.particles;
  const ContactArrays<Dim>& c = s.contacts;
  // Raw pointers in locals, so that the stores of the loop never force a reload.
  [[maybe_unused]] const int* const offset = s.adjacency.offset.data();
  [[maybe_unused]] const int* const entry = s.adjacency.entry.data();
  [[maybe_unused]] const Vector<Dim>* const forces = c.force.data();
  [[maybe_unused]] const Vector<Dim>* const normals = c.normal.data();
  [[maybe_unused]] Vector<Dim>* const positions = p.position.data();
  [[maybe_unused]] Vector<Dim>* const velocities = p.velocity.data();
  [[maybe_unused]] Angular<Dim>* const spins = p.angular_velocity.data();
  [[maybe_unused]] double* const angles = p.rotation_angle.data();
  [[maybe_unused]] const double* const radii = p.radius.data();
  [[maybe_unused]] const double* const masses = p.mass.data();
  [[maybe_unused]] const double* const inverse_masses = p.inverse_mass.data();
  [[maybe_unused]] const double* const inverse_inertias = p.inverse_inertia.data();
  [[maybe_unused]] SymmetricTensor<Dim>* const strains = p.strain.data();
  [[maybe_unused]] Vector<Dim>* const external_forces = s.external_force.data();
  [[maybe_unused]] Angular<Dim>* const external_torques = s.external_torque.data();
  [[maybe_unused]] Eigen::Matrix<double, Dim, Dim>* const external_moments =
      s.external_moment.data();
  ConstraintTable<Dim>& constraints = s.constraints;
  const ParticleCompliance<Dim> compliance = s.compliance;
  const int count = p.size();
  const double dt = s.time_step_s;
  const double alpha_t = s.material.translational_damping;
  const double alpha_r = s.material.rotational_damping;

  double kinetic = 0.0, damping = 0.0, constraint_work = 0.0;
  double constraint_supplied = 0.0;
  double max_speed_squared = 0.0, max_unbalanced_squared = 0.0, max_strain_squared = 0.0;

#pragma omp parallel for if (count >= kParallelThreshold) num_threads(s.num_threads) \
    schedule(static) reduction(+ : kinetic, damping, constraint_work,                    \
                                   constraint_supplied)                                  \
    reduction(max : max_speed_squared, max_unbalanced_squared, max_strain_squared)
  for (int q = 0; q < count; ++q) {
    const double r = radii[q];
    // 1. Forces and moments (Madan (2.5)-(2.6)). The contact arm is s = +r n at i and
    // -r n at j, where the force is -f: s x f and s (x) f come out the same at both ends.
    Vector<Dim> force = Vector<Dim>::Zero();
    [[maybe_unused]] Angular<Dim> torque = ZeroAngular<Dim>();
    [[maybe_unused]] Matrix moment;
    if constexpr (kDeformable) moment.setZero();
    for (int e = offset[q]; e < offset[q + 1]; ++e) {
      const int k = entry[e] >> 1;
      const Vector<Dim>& f = forces[k];
      if (entry[e] & 1)
        force -= f;
      else
        force += f;
      if constexpr (kRotation) torque += r * Cross(normals[k], f);
      if constexpr (kDeformable) moment.noalias() += r * normals[k] * f.transpose();
    }
    if constexpr (kExternal) {
      force += external_forces[q];
      external_forces[q].setZero();
      if constexpr (kRotation) {
        torque += external_torques[q];
        external_torques[q] = ZeroAngular<Dim>();
      }
      if constexpr (kDeformable) {
        moment += external_moments[q];
        external_moments[q].setZero();
      }
    }

    // 2. DDEM: particle stress (Madan (2.41), (2.44)) and strain (2.46) for the next step.
    if constexpr (kDeformable) {
      const SymmetricTensor<Dim> stress = SymmetricPart(moment) / Volume<Dim>(r);
      strains[q] = compliance.Strain(stress);
      max_strain_squared =
          std::max(max_strain_squared, DoubleContraction<Dim>(strains[q], strains[q]));
    }

    // 3. Prescribed axes: the constraint force replaces the resultant on them.
    const double m = masses[q];
    const Vector<Dim> v_old = velocities[q];
    [[maybe_unused]] int slot = -1;
    [[maybe_unused]] Vector<Dim> prescribed = Vector<Dim>::Zero();
    [[maybe_unused]] Vector<Dim> constraint_force = Vector<Dim>::Zero();
    if constexpr (kConstraints) {
      slot = constraints.slot_of_particle[q];
      if (slot >= 0) {
        for (int axis = 0; axis < Dim; ++axis) {
          const int set = constraints.set_of_axis[slot][axis];
          if (set < 0) continue;
          prescribed[axis] = constraints.velocity[slot][axis] * constraints.amplitude[set];
          // The force that takes the axis from v_old to the prescribed velocity.
          constraint_force[axis] = m * (prescribed[axis] - v_old[axis]) / dt - force[axis];
          force[axis] = 0.0;
        }
      }
    }
    max_unbalanced_squared = std::max(max_unbalanced_squared, force.squaredNorm());

    // Madan (2.7): F_d = -alpha_t |F| v / |v|, with the free resultant and v_{n-1/2}.
    Vector<Dim> damping_force = Vector<Dim>::Zero();
    if constexpr (kDamping) {
      Vector<Dim> free_velocity = v_old;
      if constexpr (kConstraints) {
        if (slot >= 0)
          for (int axis = 0; axis < Dim; ++axis)
            if (constraints.set_of_axis[slot][axis] >= 0) free_velocity[axis] = 0.0;
      }
      const double speed = free_velocity.norm();
      if (speed > 0.0) damping_force = (-alpha_t * force.norm() / speed) * free_velocity;
    }

    // 4. Central differences, Madan (2.9)-(2.11).
    Vector<Dim> v_new = v_old + (force + damping_force) * (dt * inverse_masses[q]);
    if constexpr (kConstraints) {
      if (slot >= 0) {
        for (int axis = 0; axis < Dim; ++axis)
          if (constraints.set_of_axis[slot][axis] >= 0) v_new[axis] = prescribed[axis];
        const double work = constraint_force.dot(0.5 * (v_old + v_new)) * dt;
        constraint_work += work;
        constraint_supplied += std::abs(work);
        constraints.reaction_force[slot] = constraint_force;
      }
    }
    velocities[q] = v_new;
    positions[q] += v_new * dt;
    const Vector<Dim> v_mid = 0.5 * (v_old + v_new);
    kinetic += 0.5 * m * v_old.dot(v_new);
    if constexpr (kDamping) damping -= damping_force.dot(v_mid) * dt;
    max_speed_squared = std::max(max_speed_squared, v_new.squaredNorm());

    // Rotation, Madan (2.12)-(2.13) (with J, the thesis prints m) and (2.8).
    if constexpr (kRotation) {
      const Angular<Dim> w_old = spins[q];
      const double inverse_inertia = inverse_inertias[q];
      [[maybe_unused]] bool fixed_rotation = false;
      if constexpr (kConstraints)
        fixed_rotation = slot >= 0 && constraints.set_of_axis[slot][Dim] >= 0;
      Angular<Dim> w_new;
      if (fixed_rotation) {
        if constexpr (kConstraints) {
          const Angular<Dim> reaction = -w_old / (dt * inverse_inertia) - torque;
          constraints.reaction_torque[slot] = reaction;
          const double work = AngularDot(reaction, 0.5 * w_old) * dt;
          constraint_work += work;
          constraint_supplied += std::abs(work);
        }
        w_new = ZeroAngular<Dim>();
      } else {
        Angular<Dim> damping_torque = ZeroAngular<Dim>();
        if constexpr (kDamping) {
          const double spin = AngularNorm(w_old);
          if (spin > 0.0) damping_torque = (-alpha_r * AngularNorm(torque) / spin) * w_old;
        }
        w_new = w_old + (torque + damping_torque) * (dt * inverse_inertia);
        if constexpr (kDamping) damping -= AngularDot(damping_torque, 0.5 * (w_old + w_new)) * dt;
      }
      spins[q] = w_new;
      if constexpr (Dim == 2) angles[q] += w_new * dt;
      const double inertia = 1.0 / inverse_inertia;
      kinetic += 0.5 * inertia * AngularDot(w_old, w_new);
    }
  }
  totals->kinetic_energy_j = kinetic;
  totals->damping_dissipation_j = damping;
  totals->constraint_work_j = constraint_work;
  totals->constraint_supplied_j = constraint_supplied;
  totals->max_speed = std::sqrt(max_speed_squared);
  totals->max_unbalanced_force_n = std::sqrt(max_unbalanced_squared);
  totals->max_strain = std::sqrt(max_strain_squared);
  totals->finite = std::isfinite(kinetic) && std::isfinite(max_unbalanced_squared);
}

// Dispatch on the run-time plan, once: each level fixes one template flag.
template <int Dim, bool... kFlags>
ParticlePassFunction<Dim> Select(const bool* flags, int remaining) {
  if constexpr (sizeof...(kFlags) == 5) {
    (void)flags;
    (void)remaining;
    return &ParticlePass<Dim, kFlags...>;
  } else {
    if (flags[0]) return Select<Dim, kFlags..., true>(flags + 1, remaining - 1);
    return Select<Dim, kFlags..., false>(flags + 1, remaining - 1);
  }
}

}  // namespace

template <int Dim>
ParticlePassFunction<Dim> SelectParticlePass(const StepPlan& plan) {
  const bool flags[5] = {plan.deformable, plan.local_damping, plan.rotation, plan.external(),
                         plan.fixed_dofs};
  return Select<Dim>(flags, 5);
}

template <int Dim>
SymmetricTensor<Dim> ParticleStressFromContacts(const SceneState<Dim>& s, int q,
                                                const Eigen::Matrix<double, Dim, Dim>& moment) {
  Eigen::Matrix<double, Dim, Dim> total = moment;
  const double r = s.particles.radius[q];
  for (int e = s.adjacency.offset[q]; e < s.adjacency.offset[q + 1]; ++e) {
    const int k = s.adjacency.entry[e] >> 1;
    total.noalias() += r * s.contacts.normal[k] * s.contacts.force[k].transpose();
  }
  return SymmetricPart(total) / Volume<Dim>(r);
}

template ParticlePassFunction<2> SelectParticlePass<2>(const StepPlan&);
template ParticlePassFunction<3> SelectParticlePass<3>(const StepPlan&);
template SymmetricTensor<2> ParticleStressFromContacts<2>(const SceneState<2>&, int,
                                                          const Eigen::Matrix2d&);
template SymmetricTensor<3> ParticleStressFromContacts<3>(const SceneState<3>&, int,
                                                          const Eigen::Matrix3d&);

}  // namespace specimen
