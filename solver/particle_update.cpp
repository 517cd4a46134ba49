#include "solver/particle_update.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

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

// Running sums M_ab = sum n_a f_b over a particle's contacts, kept in pairs that SSE2 adds
// in one instruction (lane-wise the same IEEE operations as scalar code):
//   2D: (xx, xy) += n_x (f_x, f_y), (yx, yy) += n_y (f_x, f_y);
//   3D: the same for the rows x, y, z against (f_x, f_y), (xz, yz) += (n_x, n_y) f_z, and zz.
// The rigid pass adds the pairs holding off-diagonal products only; the DDEM pass adds all:
// the off-diagonal sums, hence the torques, come out identical in both.
template <int Dim>
struct ProductSums;

template <>
struct ProductSums<2> {
  Eigen::Vector2d x_row = Eigen::Vector2d::Zero(), y_row = Eigen::Vector2d::Zero();
  void AddOffDiagonal(const Vector<2>& n, const Vector<2>& f) {
    x_row += n.x() * f;
    y_row += n.y() * f;
  }
  void AddAll(const Vector<2>& n, const Vector<2>& f) { AddOffDiagonal(n, f); }
  double Axial() const { return x_row.y() - y_row.x(); }
  Eigen::Matrix2d Full() const {
    Eigen::Matrix2d m;
    m << x_row.x(), x_row.y(), y_row.x(), y_row.y();
    return m;
  }
};

template <>
struct ProductSums<3> {
  Eigen::Vector2d x_row = Eigen::Vector2d::Zero();  // (xx, xy)
  Eigen::Vector2d y_row = Eigen::Vector2d::Zero();  // (yx, yy)
  Eigen::Vector2d z_row = Eigen::Vector2d::Zero();  // (zx, zy)
  Eigen::Vector2d z_col = Eigen::Vector2d::Zero();  // (xz, yz)
  double zz = 0.0;
  void AddOffDiagonal(const Vector<3>& n, const Vector<3>& f) {
    const Eigen::Vector2d f_xy = f.head<2>();
    x_row += n.x() * f_xy;
    y_row += n.y() * f_xy;
    z_row += n.z() * f_xy;
    z_col += f.z() * n.head<2>();
  }
  void AddAll(const Vector<3>& n, const Vector<3>& f) {
    AddOffDiagonal(n, f);
    zz += n.z() * f.z();
  }
  // (M_yz - M_zy, M_zx - M_xz, M_xy - M_yx).
  Vector<3> Axial() const {
    return Vector<3>(z_col.y() - z_row.y(), z_row.x() - z_col.x(), x_row.y() - y_row.x());
  }
  Eigen::Matrix3d Full() const {
    Eigen::Matrix3d m;
    m << x_row.x(), x_row.y(), z_col.x(), y_row.x(), y_row.y(), z_col.y(), z_row.x(), z_row.y(), zz;
    return m;
  }
};

// v / |v| for the local damping's direction (Madan (2.7)-(2.8)), 0 for v = 0. A velocity
// decaying towards rest reaches denormal |v|^2, which has lost its digits (and |F|^2/|v|^2
// overflows there, which once made a spin infinite in one step): below 1e-200, v is rescaled
// by its largest component first.
inline double UnitDirection(double v, double /*squared*/) {
  return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0);
}
template <int Rows>
inline Eigen::Matrix<double, Rows, 1> UnitDirection(const Eigen::Matrix<double, Rows, 1>& v,
                                                    double squared) {
  if (squared > 1e-200) return v / std::sqrt(squared);
  const double scale = v.cwiseAbs().maxCoeff();
  if (scale == 0.0) return Eigen::Matrix<double, Rows, 1>::Zero();
  const Eigen::Matrix<double, Rows, 1> w = v / scale;
  return w / w.norm();
}

// The particles the wall and load passes may write to (external_flag), rebuilt after every
// neighbour search (the walls' candidate lists change only there).
template <int Dim>
const std::uint8_t* ExternalFlags(SceneState<Dim>& s) {
  const int count = s.particles.size();
  if (s.external_flag_search != s.searches || static_cast<int>(s.external_flag.size()) != count) {
    s.external_flag.assign(count, 0);
    for (const WallState<Dim>& w : s.walls)
      for (const int q : w.particle) s.external_flag[q] = 1;
    for (const PointLoadState<Dim>& load : s.loads)
      for (const int q : load.load.particles) s.external_flag[q] = 1;
    s.external_flag_search = s.searches;
  }
  return s.external_flag.data();
}

// Adjacency entries between a gather and its prefetch (kAdjacencyPadding in scene_state.h
// pads the entry array by at least this much).
constexpr int kPrefetchEntries = 12;
static_assert(kPrefetchEntries <= kAdjacencyPadding, "the prefetch reads past the adjacency");

template <int Dim, bool kDeformable, bool kDamping, bool kRotation, bool kExternal,
          bool kConstraints, bool kBondMoments>
void ParticlePass(SceneState<Dim>& s, ParticlePassTotals* totals) {
  using Matrix = Eigen::Matrix<double, Dim, Dim>;
  ParticleArrays<Dim>& p = s.particles;
  const ContactArrays<Dim>& c = s.contacts;
  // Raw pointers in locals, so that the stores of the loop never force a reload.
  [[maybe_unused]] const int* const offset = s.adjacency.offset.data();
  [[maybe_unused]] const int* const entry = s.adjacency.entry.data();
  [[maybe_unused]] const Vector<Dim>* const forces = c.force.data();
  [[maybe_unused]] const Vector<Dim>* const normals = c.normal.data();
  [[maybe_unused]] const Angular<Dim>* const bond_moments = c.bond_moment.data();
  [[maybe_unused]] Vector<Dim>* const positions = p.position.data();
  [[maybe_unused]] Vector<Dim>* const velocities = p.velocity.data();
  [[maybe_unused]] Angular<Dim>* const spins = p.angular_velocity.data();
  [[maybe_unused]] double* const angles = p.rotation_angle.data();
  [[maybe_unused]] const double* const radii = p.radius.data();
  [[maybe_unused]] const double* const masses = p.mass.data();
  [[maybe_unused]] const double* const inverse_masses = p.inverse_mass.data();
  [[maybe_unused]] const double* const inverse_inertias = p.inverse_inertia.data();
  [[maybe_unused]] SymmetricTensor<Dim>* const strains = p.strain.data();
  if constexpr (kDeformable) s.deformation.resize(p.strain.size());
  [[maybe_unused]] ContactDeformation<Dim>* const deformations = s.deformation.data();
  [[maybe_unused]] Vector<Dim>* const external_forces = s.external_force.data();
  [[maybe_unused]] Angular<Dim>* const external_torques = s.external_torque.data();
  [[maybe_unused]] Eigen::Matrix<double, Dim, Dim>* const external_moments =
      s.external_moment.data();
  ConstraintTable<Dim>& constraints = s.constraints;
  // The compliance coefficients a - b, b, c (material.h), read off D applied to unit stresses.
  [[maybe_unused]] double normal_minus_coupling = 0.0, coupling = 0.0, shear = 0.0;
  if constexpr (kDeformable) {
    SymmetricTensor<Dim> unit = SymmetricTensor<Dim>::Zero();
    unit[0] = 1.0;
    const SymmetricTensor<Dim> normal_response = s.compliance.Strain(unit);
    unit[0] = 0.0;
    unit[Dim] = 1.0;
    coupling = normal_response[1];
    normal_minus_coupling = normal_response[0] - coupling;
    shear = s.compliance.Strain(unit)[Dim];
  }
  const int count = p.size();
  const double dt = s.time_step_s;
  const double alpha_t = s.material.translational_damping;
  const double alpha_r = s.material.rotational_damping;

  // External actions reach only the walls' candidates and the loaded particles: the loop
  // reads (and clears) the accumulators of those alone, marked in external_flag.
  [[maybe_unused]] const std::uint8_t* external_flags = nullptr;
  if constexpr (kExternal) external_flags = ExternalFlags(s);

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
    // -r n at j, where the force is -f: s x f and s (x) f come out the same at both ends,
    // so r multiplies the sums once.
    Vector<Dim> force = Vector<Dim>::Zero();
    // Sums of the products n_a f_b: the torque is r (n x f) = r (M_yz - M_zy, M_zx - M_xz,
    // M_xy - M_yx) (2D: M_xy - M_yx), the DDEM moment r M. The rigid pass sums only the
    // off-diagonal products, the same way, so that an infinitely stiff DDEM particle turns
    // exactly as a rigid one, and DDEM gets its torque from the moment's sums.
    [[maybe_unused]] ProductSums<Dim> sums;
    // Bond couples (bond_moment.h): M on i, -M on j.
    [[maybe_unused]] Angular<Dim> couple = ZeroAngular<Dim>();
    const int entry_end = offset[q + 1];
    for (int e = offset[q]; e < entry_end; ++e) {
      // The contacts where q is j lie far from its own (they sit with i's): fetch the force
      // and normal of the entry kPrefetchEntries ahead while this one is summed. The
      // adjacency array is padded (RebuildAdjacency), so the read never leaves it.
      {
        const int ahead = entry[e + kPrefetchEntries] >> 1;
        __builtin_prefetch(forces + ahead);
        if constexpr (kDeformable || kRotation) __builtin_prefetch(normals + ahead);
      }
      const int k = entry[e] >> 1;
      const Vector<Dim>& f = forces[k];
      // j receives -f. A multiplication by +-1 (exact), not a branch: the side of a contact
      // end is not predictable.
      const double side = 1.0 - 2.0 * (entry[e] & 1);
      force += side * f;
      if constexpr (kBondMoments) couple += side * bond_moments[k];
      if constexpr (kDeformable)
        sums.AddAll(normals[k], f);
      else if constexpr (kRotation)
        sums.AddOffDiagonal(normals[k], f);
    }
    [[maybe_unused]] Angular<Dim> torque = ZeroAngular<Dim>();
    if constexpr (kRotation) torque = r * sums.Axial();
    if constexpr (kBondMoments) torque += couple;
    // DDEM: the moment sum s (x) f = r M plus the external surface moments.
    [[maybe_unused]] Matrix moment;
    [[maybe_unused]] double moment_scale = r;
    if constexpr (kDeformable) moment = sums.Full();
    if constexpr (kExternal) {
      if (external_flags[q]) {
        force += external_forces[q];
        external_forces[q].setZero();
        if constexpr (kRotation) {
          torque += external_torques[q];
          external_torques[q] = ZeroAngular<Dim>();
        }
        if constexpr (kDeformable) {
          moment = r * moment + external_moments[q];
          moment_scale = 1.0;
          external_moments[q].setZero();
        }
      }
    }

    // 2. DDEM: particle stress (Madan (2.41), (2.44)) and strain (2.46) for the next step.
    // sigma = sym(r M) / V with 1/V = rho / m (no division), then eps = D sigma in the form
    // eps_ii = (a - b) sigma_ii + b tr(sigma), eps_ij = c sigma_ij (material.h).
    if constexpr (kDeformable) {
      const SymmetricTensor<Dim> sym = SymmetricPart(moment);
      // 1/V from the radius, not rho/m: mass scaling (particles.h) changes m, not V.
      const double scale = moment_scale / Volume<Dim>(r);
      double trace = 0.0;
      for (int k = 0; k < Dim; ++k) trace += sym[k];
      SymmetricTensor<Dim> strain;
      for (int k = 0; k < Dim; ++k)
        strain[k] = scale * (normal_minus_coupling * sym[k] + coupling * trace);
      for (int k = Dim; k < kVoigtSize<Dim>; ++k) strain[k] = (scale * shear) * sym[k];
      strains[q] = strain;
      deformations[q].Set(strain, r);
      max_strain_squared = std::max(max_strain_squared, DoubleContraction<Dim>(strain, strain));
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
      damping_force = (-alpha_t * force.norm()) *
                      UnitDirection(free_velocity, free_velocity.squaredNorm());
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
          damping_torque = (-alpha_r * AngularNorm(torque)) *
                           UnitDirection(w_old, AngularDot(w_old, w_old));
        }
        w_new = w_old + (torque + damping_torque) * (dt * inverse_inertia);
        if constexpr (kDamping) damping -= AngularDot(damping_torque, 0.5 * (w_old + w_new)) * dt;
      }
      spins[q] = w_new;
      if constexpr (Dim == 2) angles[q] += w_new * dt;
      // J = m R^2 / 2 (discs), 2/5 m R^2 (spheres), Madan (2.3)-(2.4): no division.
      const double inertia = (Dim == 2 ? 0.5 : 0.4) * m * r * r;
      kinetic += 0.5 * inertia * AngularDot(w_old, w_new);
    }
  }
  if constexpr (kDeformable) s.deformation_step = s.step + 1;  // the step's clock advances next
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
  if constexpr (sizeof...(kFlags) == 6) {
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
  // Bond couples need the rotation stage (ChooseStages turns it on with them).
  const bool flags[6] = {plan.deformable,  plan.local_damping, plan.rotation,
                         plan.external(),  plan.fixed_dofs,    plan.bond_moments && plan.rotation};
  return Select<Dim>(flags, 6);
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
