#pragma once
// The bonded contact law: linear elastic, perfectly brittle bonds (Labra 2012 (2.32)-(2.35),
// global constants kn, kt, Rn, Rt), and after breakage a compression-only contact with
// Coulomb friction by radial return (Labra (2.20)-(2.23), (2.36)-(2.37)); contact dashpots
// (Madan (2.33)-(2.37)); in DDEM scenes the normal force acts on the deformed overlap
// (Madan (2.53)-(2.54)). Bonds may carry a moment and fail on the peripheral stress of their
// section (bond_moment.h).
//
// Conventions (docs/solver.md, "Conventions"): n = (xj - xi)/|xj - xi|; gap
// g = |xj - xi| - ri - rj - g0 (g0: the initial gap of a bond created stress-free, else 0);
// the normal force on i is fn n with fn = kn g: tension positive. The stored tangential
// force is the force on i; it grows along the relative tangential velocity of j with respect to i
// (Labra's printed (2.20) has the sign of the force on j, see the errata). Before each
// update it is rotated into the current contact plane (RotateTangentialForce).
//
// Contacts live in flat arrays (ContactArrays). The contact pass is one loop over them,
// instantiated for each combination of the scene's stages (deformable, breakable,
// tangential, bond moments, dashpots) and chosen once before the time loop
// (SelectContactPass).

#include <array>
#include <cstdint>
#include <vector>

#include "solver/vector_algebra.h"

namespace specimen {

template <int Dim>
struct SceneState;
struct StepPlan;

enum class ContactState : std::uint8_t {
  kBonded = 0,           // intact bond: tension and compression, linear
  kBrokenInTension = 1,  // a former bond, broken by fn > Rn: compression and friction only
  kBrokenInShear = 2,    // a former bond, broken by |ft| > Rt: compression and friction only
  kFrictional = 3,       // a pair found by the neighbour search, never bonded
};

const char* ContactStateName(ContactState state);

// The contacts as flat arrays, one entry per pair, sorted by (i, j) with i < j.
template <int Dim>
struct ContactArrays {
  std::vector<std::array<int, 2>> pair;  // (i, j)
  std::vector<ContactState> state;
  // Gap at which the normal force is zero [m]: the bond's initial gap for stress-free bonds,
  // else 0. Kept after breakage, so a broken bond touches where it was bonded.
  std::vector<double> reference_gap;
  std::vector<Vector<Dim>> normal;  // unit normal i -> j at the last evaluation
  // Total force on i at the last evaluation [N] (elastic + dashpots); j receives -force.
  std::vector<Vector<Dim>> force;
  // Elastic normal force fn = kn g [N] (tension positive) at the last evaluation.
  std::vector<double> normal_elastic_force;
  // Elastic tangential (spring) force on i [N], in the plane normal to `normal`. Empty
  // when the scene has no tangential stage (kt = 0).
  std::vector<Vector<Dim>> tangential_force;
  // Moment of a bond on i [N m] (j receives its opposite; bond_moment.h); zero for unbonded
  // contacts. Empty when bonds carry no moment.
  std::vector<Angular<Dim>> bond_moment;

  int size() const { return static_cast<int>(pair.size()); }
  bool has_tangential() const { return tangential_enabled; }
  bool has_bond_moments() const { return moments_enabled; }
  bool tangential_enabled = false;
  bool moments_enabled = false;

  void Clear();
  void Reserve(size_t count);
  // Appends a copy of contact c of `other`.
  void AppendCopy(const ContactArrays& other, int c);
  // Appends a new contact at rest (zero forces).
  void AppendNew(int i, int j, ContactState state, double reference_gap, const Vector<Dim>& normal);
  // Index of the contact (i, j) (either order), or -1. Binary search on the sorted pairs.
  int Find(int i, int j) const;
};

// The constants of the law for one scene.
struct ContactLawConstants {
  double normal_stiffness = 0.0;          // kn [N/m]
  double tangential_stiffness = 0.0;      // kt [N/m]
  double tensile_strength = 0.0;          // Rn [N]
  double shear_strength = 0.0;            // Rt [N]
  double friction = 0.0;                  // mu
  double bond_radius_ratio = 0.0;         // lambda (bond_moment.h)
  double normal_dashpot_ratio = 0.0;      // xi_n
  double tangential_dashpot_ratio = 0.0;  // xi_t
  double time_step = 0.0;                 // dt [s]
};

// What one contact pass adds to the step's bookkeeping.
struct ContactPassTotals {
  double dashpot_dissipation_j = 0.0;   // sum c v_r^2 dt over contacts
  double friction_dissipation_j = 0.0;  // plastic slip work of the radial return
  double breakage_release_j = 0.0;      // elastic energy released by bonds breaking
  double max_force_n = 0.0;             // largest |total contact force|
  double sum_force_squared_n2 = 0.0;    // sum of |total contact force|^2 over contacts
  int loaded_contacts = 0;              // contacts carrying a non-zero force
  int broken_in_tension = 0;
  int broken_in_shear = 0;
  bool finite = true;  // false when a force is NaN or infinite
};

// Rotates a tangential force stored in the plane normal to n_old into the plane normal to
// n_new by the smallest rotation taking n_old to n_new (both unit vectors):
//   ft' = ft - (n_old + n_new) (n_new . ft) / (1 + n_old . n_new),
// which keeps |ft| exactly for ft in the old plane (in 2D it is the rotation by the change of
// angle of n). In 3D the rotation of the pair about the normal (twist) is then added: ft' is
// turned about n_new by twist_angle = dt (w_i + w_j)/2 . n_new, as ft' + twist n_new x ft'
// rescaled to |ft'| (the rotation by atan(twist_angle)), and projected into the new plane.
Vector<2> RotateTangentialForce(const Vector<2>& tangential_force, const Vector<2>& old_normal,
                                const Vector<2>& new_normal, double twist_angle);
Vector<3> RotateTangentialForce(const Vector<3>& tangential_force, const Vector<3>& old_normal,
                                const Vector<3>& new_normal, double twist_angle);

// One pass over all contacts at the current positions (t_n) and half-step velocities:
// stores the new forces in state.contacts and returns the totals.
template <int Dim>
using ContactPassFunction = void (*)(SceneState<Dim>& state, ContactPassTotals* totals);

// The instantiation of the contact pass for the plan's stages.
template <int Dim>
ContactPassFunction<Dim> SelectContactPass(const StepPlan& plan);

}  // namespace specimen
