#include "solver/contact_law.h"

#include <algorithm>
#include <cmath>

#include "solver/bond_moment.h"
#include "solver/scene_state.h"
#include "solver/step_plan.h"

namespace specimen {

const char* ContactStateName(ContactState state) {
  switch (state) {
    case ContactState::kBonded:
      return "bonded";
    case ContactState::kBrokenInTension:
      return "broken in tension";
    case ContactState::kBrokenInShear:
      return "broken in shear";
    case ContactState::kFrictional:
      return "frictional";
  }
  return "unknown";
}

// ---------------------------------------------------------------------------------------
// ContactArrays

template <int Dim>
void ContactArrays<Dim>::Clear() {
  pair.clear();
  state.clear();
  reference_gap.clear();
  normal.clear();
  force.clear();
  normal_elastic_force.clear();
  tangential_force.clear();
  bond_moment.clear();
}

template <int Dim>
void ContactArrays<Dim>::Reserve(size_t count) {
  pair.reserve(count);
  state.reserve(count);
  reference_gap.reserve(count);
  normal.reserve(count);
  force.reserve(count);
  normal_elastic_force.reserve(count);
  if (tangential_enabled) tangential_force.reserve(count);
  if (moments_enabled) bond_moment.reserve(count);
}

template <int Dim>
void ContactArrays<Dim>::AppendCopy(const ContactArrays& other, int c) {
  pair.push_back(other.pair[c]);
  state.push_back(other.state[c]);
  reference_gap.push_back(other.reference_gap[c]);
  normal.push_back(other.normal[c]);
  force.push_back(other.force[c]);
  normal_elastic_force.push_back(other.normal_elastic_force[c]);
  if (tangential_enabled) tangential_force.push_back(other.tangential_force[c]);
  if (moments_enabled) bond_moment.push_back(other.bond_moment[c]);
}

template <int Dim>
void ContactArrays<Dim>::AppendNew(int i, int j, ContactState new_state, double gap0,
                                   const Vector<Dim>& unit_normal) {
  pair.push_back({i, j});
  state.push_back(new_state);
  reference_gap.push_back(gap0);
  normal.push_back(unit_normal);
  force.push_back(Vector<Dim>::Zero());
  normal_elastic_force.push_back(0.0);
  if (tangential_enabled) tangential_force.push_back(Vector<Dim>::Zero());
  if (moments_enabled) bond_moment.push_back(ZeroAngular<Dim>());
}

template <int Dim>
int ContactArrays<Dim>::Find(int i, int j) const {
  const std::array<int, 2> key = i < j ? std::array<int, 2>{i, j} : std::array<int, 2>{j, i};
  const auto it = std::lower_bound(pair.begin(), pair.end(), key);
  if (it == pair.end() || *it != key) return -1;
  return static_cast<int>(it - pair.begin());
}

template struct ContactArrays<2>;
template struct ContactArrays<3>;

// ---------------------------------------------------------------------------------------
// Rotation of the stored tangential force into the current contact plane.

Vector<2> RotateTangentialForce(const Vector<2>& tangential_force, const Vector<2>& old_normal,
                                const Vector<2>& new_normal, double /*twist_angle*/) {
  // In 2D the smallest rotation is the turn of the normal: keep the component along the
  // old tangent t = perp(n) and put it on the new tangent.
  return tangential_force.dot(Perpendicular(old_normal)) * Perpendicular(new_normal);
}

namespace {

// The 3D rotation, inlined into the contact pass. The smallest rotation keeps |ft| (ft lies
// in the old plane: the stored force was projected into it); the twist turns the result by
// atan(twist) about n_new, i.e. rotated + twist n x rotated rescaled by 1/sqrt(1 + twist^2),
// the same vector the earlier "add, then rescale to the old magnitude" gave, without the
// long divide-and-square-root chain on the force (an out-of-line call plus that chain cost a
// third of a 3D rigid step). The projection removes the round-off normal component. The
// factors depend on the normals and spins only, so one object turns both the tangential
// force and a bond's bending moment (bond_moment.h).
template <int Dim>
struct ContactPlaneRotation;

template <>
struct ContactPlaneRotation<3> {
  ContactPlaneRotation(const Vector<3>& old_normal, const Vector<3>& new_normal,
                       double twist_angle)
      : from(old_normal), to(new_normal) {
    inverse_one_plus_cosine = 1.0 / (1.0 + old_normal.dot(new_normal));
    twist_cosine = 1.0 / std::sqrt(1.0 + twist_angle * twist_angle);
    twist_sine = twist_angle * twist_cosine;
  }
  // v in the old contact plane -> the new one.
  Vector<3> operator()(const Vector<3>& v) const {
    Vector<3> twisted = Unprojected(v);
    twisted -= twisted.dot(to) * to;
    return twisted;
  }
  // The same without removing the round-off normal component: for a bond's moment, whose
  // parts are separated again along the normal at every step.
  Vector<3> Unprojected(const Vector<3>& v) const {
    const Vector<3> rotated = v - (from + to) * (to.dot(v) * inverse_one_plus_cosine);
    return twist_cosine * rotated + twist_sine * to.cross(rotated);
  }
  const Vector<3>& from;
  const Vector<3>& to;
  double inverse_one_plus_cosine, twist_cosine, twist_sine;
};

template <>
struct ContactPlaneRotation<2> {
  ContactPlaneRotation(const Vector<2>& old_normal, const Vector<2>& new_normal, double /*twist*/)
      : from(Perpendicular(old_normal)), to(Perpendicular(new_normal)) {}
  Vector<2> operator()(const Vector<2>& v) const { return v.dot(from) * to; }
  Vector<2> from, to;
};

// The rotation where the pass's stages use it (tangential history, bond moments), else
// nothing: a scene without either computes no square root or division for it.
struct NoPlaneRotation {};
template <int Dim, bool kNeeded>
inline auto PlaneRotationIf(const Vector<Dim>& old_normal, const Vector<Dim>& new_normal,
                            double twist_angle) {
  if constexpr (kNeeded) {
    return ContactPlaneRotation<Dim>(old_normal, new_normal, twist_angle);
  } else {
    return NoPlaneRotation{};
  }
}

inline Vector<3> RotateTangentialForceInline(const Vector<3>& tangential_force,
                                             const Vector<3>& old_normal,
                                             const Vector<3>& new_normal, double twist_angle) {
  return ContactPlaneRotation<3>(old_normal, new_normal, twist_angle)(tangential_force);
}

}  // namespace

Vector<3> RotateTangentialForce(const Vector<3>& tangential_force, const Vector<3>& old_normal,
                                const Vector<3>& new_normal, double twist_angle) {
  return RotateTangentialForceInline(tangential_force, old_normal, new_normal, twist_angle);
}

// ---------------------------------------------------------------------------------------
// The contact pass.

namespace {

constexpr int kPrefetchDistance = 8;

template <int Dim, bool kDeformable, bool kBreakable, bool kTangential, bool kMoment,
          bool kDashpot>
void ContactPass(SceneState<Dim>& s, ContactPassTotals* totals) {
  const ParticleArrays<Dim>& p = s.particles;
  ContactArrays<Dim>& c = s.contacts;
  const ContactLawConstants& law = s.law;
  const int count = c.size();
  // Raw pointers in locals: the stores below (the state byte may alias anything) then do
  // not force the compiler to reload the arrays' addresses at every contact.
  [[maybe_unused]] const Vector<Dim>* const positions = p.position.data();
  [[maybe_unused]] const Vector<Dim>* const velocities = p.velocity.data();
  [[maybe_unused]] const Angular<Dim>* const spins = p.angular_velocity.data();
  [[maybe_unused]] const double* const radii = p.radius.data();
  [[maybe_unused]] const double* const masses = p.mass.data();
  if constexpr (kDeformable) {
    if (s.deformation_step != s.step) RefreshContactDeformation(s);
  }
  [[maybe_unused]] const ContactDeformation<Dim>* const deformations = s.deformation.data();
  const std::array<int, 2>* const pairs = c.pair.data();
  [[maybe_unused]] ContactState* const states = c.state.data();
  [[maybe_unused]] const double* const reference_gaps = c.reference_gap.data();
  [[maybe_unused]] Vector<Dim>* const normals = c.normal.data();
  [[maybe_unused]] Vector<Dim>* const forces = c.force.data();
  [[maybe_unused]] double* const normal_forces = c.normal_elastic_force.data();
  [[maybe_unused]] Vector<Dim>* const tangential_forces = c.tangential_force.data();
  [[maybe_unused]] Angular<Dim>* const bond_moments = c.bond_moment.data();
  const double kn = law.normal_stiffness, kt = law.tangential_stiffness, dt = law.time_step;
  [[maybe_unused]] const double bond_radius_ratio = law.bond_radius_ratio;
  const double tensile_strength = law.tensile_strength;
  const double shear_strength_squared = law.shear_strength * law.shear_strength;
  const double friction = law.friction;
  // Madan (2.35)-(2.37): c = xi 2 sqrt(m_i m_j k / (m_i + m_j)).
  const double normal_dashpot = 2.0 * law.normal_dashpot_ratio * std::sqrt(kn);
  const double tangential_dashpot = 2.0 * law.tangential_dashpot_ratio * std::sqrt(kt);
  const double inverse_kn = 1.0 / kn;
  const double inverse_kt = kt > 0.0 ? 1.0 / kt : 0.0;

  double dashpot_dissipation = 0.0, friction_dissipation = 0.0, breakage_release = 0.0;
  double max_force_squared = 0.0, sum_force_squared = 0.0;
  int loaded = 0, broken_in_tension = 0, broken_in_shear = 0;

#pragma omp parallel for if (count >= kParallelThreshold) num_threads(s.num_threads) \
    schedule(static) reduction(+ : dashpot_dissipation, friction_dissipation, breakage_release, \
                                   sum_force_squared, loaded, broken_in_tension,              \
                                   broken_in_shear) reduction(max : max_force_squared)
  for (int k = 0; k < count; ++k) {
    if (k + kPrefetchDistance < count) {
      const int ahead = pairs[k + kPrefetchDistance][1];
      __builtin_prefetch(positions + ahead);
      if constexpr (kTangential || kDashpot) __builtin_prefetch(velocities + ahead);
      if constexpr (kTangential || kMoment) __builtin_prefetch(spins + ahead);
      if constexpr (kDeformable) __builtin_prefetch(deformations + ahead);
    }
    const int i = pairs[k][0], j = pairs[k][1];
    const Vector<Dim> branch = positions[j] - positions[i];
    const double distance = branch.norm();
    const Vector<Dim> n = branch * (1.0 / distance);  // one division, not Dim
    const double ri = radii[i], rj = radii[j];
    // ri + rj first: the same digits whichever particle is i (the contact's orientation
    // depends on the numbering), so a stress-free bond starts at exactly zero force.
    double gap = distance - (ri + rj) - reference_gaps[k];
    if constexpr (kDeformable) {
      // Madan (2.53): deformed overlap h_c = h + Ri n.eps_i.n + Rj n.eps_j.n, i.e. the gap
      // shrinks by the normal displacements of the two contact points.
      gap -= NormalDisplacementSum(deformations[i], deformations[j], n);
    }
    ContactState state = states[k];
    if (state != ContactState::kBonded && gap >= 0.0) {
      // An open unbonded contact carries nothing and forgets its tangential history.
      normals[k] = n;
      forces[k].setZero();
      normal_forces[k] = 0.0;
      if constexpr (kTangential) tangential_forces[k].setZero();
      continue;
    }
    // Madan (2.54), Labra (2.9): fn = kn g, tension positive.
    double fn = kn * gap;

    // Relative velocity of the contact point of j with respect to that of i, Madan (2.32),
    // with the arms s_i = ri m and s_j = -rj m. m is the normal at the middle of the step
    // (the displacement increment v dt spans t_{n-1}..t_n): second-order accurate for
    // spinning pairs, where the end normal leaves an O(dt^2) energy drift twice as large.
    [[maybe_unused]] Vector<Dim> relative_velocity;
    [[maybe_unused]] double normal_velocity = 0.0;
    if constexpr (kTangential || kDashpot) {
      relative_velocity = velocities[j] - velocities[i];
      if constexpr (kTangential) {
        // Unnormalised: |m| = cos(theta/2), a second-order difference. w_j x (-rj m) -
        // w_i x (ri m) = -(ri w_i + rj w_j) x m: one cross product.
        const Vector<Dim> mid = 0.5 * (normals[k] + n);
        const Angular<Dim> arm_spin = ri * spins[i] + rj * spins[j];
        relative_velocity -= Cross(arm_spin, mid);
      }
      normal_velocity = relative_velocity.dot(n);  // Madan (2.31)
    }

    [[maybe_unused]] Vector<Dim> tangential_velocity;
    Vector<Dim> ft = Vector<Dim>::Zero();
    [[maybe_unused]] double twist = 0.0;
    if constexpr (Dim == 3 && (kTangential || kMoment))
      twist = 0.5 * dt * (spins[i] + spins[j]).dot(n);
    [[maybe_unused]] const auto turn =
        PlaneRotationIf<Dim, kTangential || kMoment>(normals[k], n, twist);
    if constexpr (kTangential) {
      tangential_velocity = relative_velocity - normal_velocity * n;  // Madan (2.30)
      // Madan (2.28)-(2.29), Labra (2.20) with the sign of the force on i: the stored force
      // rotated into the current plane plus kt v_rt dt.
      ft = turn(tangential_forces[k]) + (kt * dt) * tangential_velocity;
    }

    // The moment of a bond (bond_moment.h): the stored one turned with the pair (its
    // bending part with the contact plane, its twisting part onto the new normal), plus the
    // stiffness times the relative rotation of the step.
    [[maybe_unused]] Angular<Dim> moment = ZeroAngular<Dim>();
    [[maybe_unused]] BondSection<Dim> section;
    if constexpr (kMoment) {
      if (state == ContactState::kBonded) {
        section = BondSectionOf<Dim>(ri, rj, bond_radius_ratio, kn, kt);
        moment = bond_moments[k];
        if constexpr (Dim == 3) {
          const double twisting = moment.dot(normals[k]);
          moment = turn.Unprojected(Vector<3>(moment - twisting * normals[k])) + twisting * n;
        }
        moment += BondMomentIncrement(Angular<Dim>((spins[j] - spins[i]) * dt), n, section);
      }
    }

    [[maybe_unused]] bool broke = false;
    if constexpr (kBreakable) {
      if (state == ContactState::kBonded) {
        // Labra (2.34)-(2.35), Madan (2.38)-(2.39): instantaneous, irreversible failure; a
        // bond with a moment on the peripheral stress of its section (bond_moment.h).
        bool tension = false, shear = false;
        if constexpr (kMoment) {
          const MomentParts parts = SplitMoment(moment, n);
          tension = ExceedsPeripheralTension<Dim>(fn, parts, section, tensile_strength);
          double ft_squared = 0.0;
          if constexpr (kTangential) ft_squared = ft.squaredNorm();
          shear = ExceedsPeripheralShear<Dim>(ft_squared, parts, section, law.shear_strength);
        } else {
          tension = fn > tensile_strength;
          if constexpr (kTangential) shear = ft.squaredNorm() > shear_strength_squared;
        }
        if (tension || shear) {
          double bond_energy = 0.5 * fn * fn * inverse_kn;
          if constexpr (kTangential) bond_energy += 0.5 * ft.squaredNorm() * inverse_kt;
          if constexpr (kMoment) {
            bond_energy += BondMomentEnergy<Dim>(moment, n, section);
            moment = ZeroAngular<Dim>();  // a broken bond carries no moment
          }
          breakage_release += bond_energy;  // the unbonded state's energy is subtracted below
          state = tension ? ContactState::kBrokenInTension : ContactState::kBrokenInShear;
          states[k] = state;
          broke = true;
          if (tension)
            ++broken_in_tension;
          else
            ++broken_in_shear;
        }
      }
    }

    [[maybe_unused]] bool sliding = false;
    if (state != ContactState::kBonded) {
      if (gap >= 0.0) {
        // Only right after a break: the pair is apart, nothing is carried.
        fn = 0.0;
        ft.setZero();
      } else if constexpr (kTangential) {
        // Labra (2.21)-(2.23): Coulomb friction by radial return.
        const double limit = friction * std::abs(fn);
        const double trial = ft.norm();
        if (trial > limit) {
          friction_dissipation += limit * (trial - limit) * inverse_kt;
          ft = trial > 0.0 ? Vector<Dim>(ft * (limit / trial)) : Vector<Dim>::Zero();
          sliding = true;
        }
      }
    }
    if constexpr (kBreakable) {
      // What the broken contact still stores is not released.
      if (broke) {
        double kept = 0.5 * fn * fn * inverse_kn;
        if constexpr (kTangential) kept += 0.5 * ft.squaredNorm() * inverse_kt;
        breakage_release -= kept;
      }
    }

    Vector<Dim> force = fn * n + ft;
    if constexpr (kDashpot) {
      const double mi = masses[i], mj = masses[j];
      const double root_reduced_mass = std::sqrt(mi * mj / (mi + mj));
      double normal_damping = normal_dashpot * root_reduced_mass * normal_velocity;  // (2.33)
      // An unbonded contact never pulls: fn + fnd <= 0.
      if (state != ContactState::kBonded) normal_damping = std::min(normal_damping, -fn);
      force += normal_damping * n;
      dashpot_dissipation += normal_damping * normal_velocity * dt;
      if constexpr (kTangential) {
        if (!sliding) {
          const Vector<Dim> tangential_damping =
              (tangential_dashpot * root_reduced_mass) * tangential_velocity;  // (2.34)
          force += tangential_damping;
          dashpot_dissipation += tangential_damping.dot(tangential_velocity) * dt;
        }
      }
    }

    normals[k] = n;
    forces[k] = force;
    normal_forces[k] = fn;
    if constexpr (kTangential) tangential_forces[k] = ft;
    if constexpr (kMoment) bond_moments[k] = moment;
    const double magnitude_squared = force.squaredNorm();
    max_force_squared = std::max(max_force_squared, magnitude_squared);
    sum_force_squared += magnitude_squared;
    loaded += magnitude_squared > 0.0 ? 1 : 0;
  }
  totals->dashpot_dissipation_j = dashpot_dissipation;
  totals->friction_dissipation_j = friction_dissipation;
  totals->breakage_release_j = breakage_release;
  totals->max_force_n = std::sqrt(max_force_squared);
  totals->sum_force_squared_n2 = sum_force_squared;
  totals->loaded_contacts = loaded;
  totals->broken_in_tension = broken_in_tension;
  totals->broken_in_shear = broken_in_shear;
  totals->finite = std::isfinite(sum_force_squared);
}

template <int Dim, bool kDeformable, bool kBreakable, bool kTangential, bool kMoment>
ContactPassFunction<Dim> SelectDashpot(bool dashpots) {
  if (dashpots) return &ContactPass<Dim, kDeformable, kBreakable, kTangential, kMoment, true>;
  return &ContactPass<Dim, kDeformable, kBreakable, kTangential, kMoment, false>;
}

template <int Dim, bool kDeformable, bool kBreakable, bool kTangential>
ContactPassFunction<Dim> SelectMoment(const StepPlan& plan) {
  if (plan.bond_moments)
    return SelectDashpot<Dim, kDeformable, kBreakable, kTangential, true>(plan.dashpots);
  return SelectDashpot<Dim, kDeformable, kBreakable, kTangential, false>(plan.dashpots);
}

template <int Dim, bool kDeformable, bool kBreakable>
ContactPassFunction<Dim> SelectTangential(const StepPlan& plan) {
  if (plan.tangential) return SelectMoment<Dim, kDeformable, kBreakable, true>(plan);
  return SelectMoment<Dim, kDeformable, kBreakable, false>(plan);
}

template <int Dim, bool kDeformable>
ContactPassFunction<Dim> SelectBreakable(const StepPlan& plan) {
  if (plan.breakable) return SelectTangential<Dim, kDeformable, true>(plan);
  return SelectTangential<Dim, kDeformable, false>(plan);
}

}  // namespace

template <int Dim>
ContactPassFunction<Dim> SelectContactPass(const StepPlan& plan) {
  if (plan.deformable) return SelectBreakable<Dim, true>(plan);
  return SelectBreakable<Dim, false>(plan);
}

template ContactPassFunction<2> SelectContactPass<2>(const StepPlan&);
template ContactPassFunction<3> SelectContactPass<3>(const StepPlan&);

}  // namespace specimen
