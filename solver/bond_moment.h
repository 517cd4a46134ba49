#pragma once
// Moment-carrying bonds: the bond of the contact law (contact_law.h) given a cross-section,
// so that it resists the relative rotation of its particles and fails on the largest stress
// of that section. This is the parallel bond of Potyondy & Cundall (2004), section 2.2, with
// the bond's force stiffnesses equal to the contact's kn and kt (global constants, as the
// rest of the law) and its strengths given as the forces Rn, Rt of the contact bond:
//
//   section:  radius Rb = lambda min(Ri, Rj), lambda = bond_radius_ratio in (0, 1]
//             2D (a strip of unit thickness): A = 2 Rb, I = 2 Rb^3 / 3
//             3D (a disc):                   A = pi Rb^2, I = pi Rb^4 / 4, J = pi Rb^4 / 2
//   stiffness of a beam of that section whose axial stiffness is kn (E A / L = kn):
//             bending  kb = kn I / A   (2D: kn Rb^2 / 3, 3D: kn Rb^2 / 4)
//             twisting kw = kt J / A   (3D only: kt Rb^2 / 2)
//   moment on particle i (j receives -M), incremental like the tangential force
//   (Potyondy & Cundall (2004) eq. 6):
//             M <- rotate(M) + dt [kb (w_rel - (w_rel.n) n) + kw (w_rel.n) n],  w_rel = wj - wi
//             (2D: M <- M + kb (wj - wi) dt)
//   failure on the periphery of the section (Potyondy & Cundall (2004) eq. 9-10 with
//   tension positive, multiplied by A so that the strengths stay forces):
//             tension: fn + |Mb| Rb A / I > Rn    (2D: fn + 3 |M| / Rb, 3D: fn + 4 |Mb| / Rb)
//             shear:   |ft| + |Mt| Rb A / J > Rt  (3D: |ft| + 2 |Mt| / Rb; 2D: |ft|)
//   with Mb the bending part of M (normal to n) and Mt its twisting part (along n).
//
// lambda -> 0 is the contact bond of Labra (2012): no moment, failure on fn and |ft| alone.
// A broken bond carries no moment (no rolling resistance). The moment is a couple: it
// turns the particles but does not enter their stress (a couple's moment tensor is
// antisymmetric), so DDEM strains and the Love-Weber stress are unchanged by it.

#include <algorithm>
#include <cmath>
#include <vector>

#include "solver/contact_law.h"
#include "solver/vector_algebra.h"

namespace specimen {

// The section and stiffnesses of one moment-carrying bond.
template <int Dim>
struct BondSection {
  double radius_m = 0.0;            // Rb
  double bending_stiffness = 0.0;   // kb [N m/rad]
  double twisting_stiffness = 0.0;  // kw [N m/rad], 3D only
};

// kb / (kn Rb^2) and kw / (kt Rb^2): I/A and J/A over Rb^2.
template <int Dim>
constexpr double kBendingFactor = Dim == 2 ? 1.0 / 3.0 : 0.25;
constexpr double kTwistingFactor3d = 0.5;
// Rb A / I and Rb A / J: the levers of the peripheral stresses (tension 3 or 4, shear 2).
template <int Dim>
constexpr double kTensionLever = Dim == 2 ? 3.0 : 4.0;
constexpr double kShearLever3d = 2.0;

template <int Dim>
inline BondSection<Dim> BondSectionOf(double radius_i, double radius_j, double radius_ratio,
                                      double kn, double kt) {
  BondSection<Dim> s;
  const double rb = radius_ratio * std::min(radius_i, radius_j);
  s.radius_m = rb;
  s.bending_stiffness = kBendingFactor<Dim> * kn * rb * rb;
  if constexpr (Dim == 3) s.twisting_stiffness = kTwistingFactor3d * kt * rb * rb;
  return s;
}

// The largest rotational stiffness a bond between these particles adds to one of them (kb in
// 2D; max(kb, kw) in 3D): the input of the per-particle time-step bound (time_step.h).
template <int Dim>
double BondRotationalStiffness(double radius_i, double radius_j, double radius_ratio, double kn,
                               double kt);

// The moment energy of the intact bonds, sum |Mb|^2/(2 kb) + Mt^2/(2 kw) (the energy audit).
template <int Dim>
double BondMomentElasticEnergy(const ContactArrays<Dim>& contacts,
                               const std::vector<double>& radius, double radius_ratio, double kn,
                               double kt);

// The bending and twisting parts of a moment (2D: all of it bends).
inline double BendingPart(double moment, const Vector<2>& /*n*/) { return moment; }
inline double TwistingPart(double /*moment*/, const Vector<2>& /*n*/) { return 0.0; }
inline Vector<3> BendingPart(const Vector<3>& moment, const Vector<3>& n) {
  return moment - moment.dot(n) * n;
}
inline double TwistingPart(const Vector<3>& moment, const Vector<3>& n) { return moment.dot(n); }

// The moment increment of a step, kb dtheta_b + kw dtheta_t, for the relative rotation
// increment (wj - wi) dt.
inline double BondMomentIncrement(double relative_rotation, const Vector<2>& /*n*/,
                                  const BondSection<2>& s) {
  return s.bending_stiffness * relative_rotation;
}
inline Vector<3> BondMomentIncrement(const Vector<3>& relative_rotation, const Vector<3>& n,
                                     const BondSection<3>& s) {
  const double twist = relative_rotation.dot(n);
  return s.bending_stiffness * (relative_rotation - twist * n) + (s.twisting_stiffness * twist) * n;
}

// The sizes of a moment's parts: |Mb|^2 and |Mt| (2D: M^2 and 0).
struct MomentParts {
  double bending_squared = 0.0;
  double twisting = 0.0;
};
inline MomentParts SplitMoment(double moment, const Vector<2>& /*n*/) { return {moment * moment, 0.0}; }
inline MomentParts SplitMoment(const Vector<3>& moment, const Vector<3>& n) {
  const double twist = moment.dot(n);
  return {std::max(0.0, moment.squaredNorm() - twist * twist), std::abs(twist)};
}

// Whether the largest normal stress of the section exceeds the strength:
// fn + |Mb| Rb A / I > Rn, as lever |Mb| > Rb (Rn - fn) (no division, no root: this runs on
// every bond at every step).
template <int Dim>
inline bool ExceedsPeripheralTension(double fn, const MomentParts& m, const BondSection<Dim>& s,
                                     double rn) {
  const double room = s.radius_m * (rn - fn);
  if (!(room > 0.0)) return true;
  constexpr double lever = kTensionLever<Dim>;
  return lever * lever * m.bending_squared > room * room;
}

// Whether the largest shear stress of the section exceeds the strength:
// |ft| + |Mt| Rb A / J > Rt, as Rb |ft| > Rb Rt - lever |Mt| (2D: |ft| > Rt).
template <int Dim>
inline bool ExceedsPeripheralShear(double ft_squared, const MomentParts& m,
                                   const BondSection<Dim>& s, double rt) {
  double room = s.radius_m * rt;
  if constexpr (Dim == 3) room -= kShearLever3d * m.twisting;
  if (!(room > 0.0)) return true;
  return s.radius_m * s.radius_m * ft_squared > room * room;
}

// Elastic energy stored by the moment: |Mb|^2 / (2 kb) + Mt^2 / (2 kw).
template <int Dim>
inline double BondMomentEnergy(const Angular<Dim>& moment, const Vector<Dim>& n,
                               const BondSection<Dim>& s) {
  const Angular<Dim> bending = BendingPart(moment, n);
  double energy = 0.5 * AngularDot(bending, bending) / s.bending_stiffness;
  if constexpr (Dim == 3) {
    const double twist = TwistingPart(moment, n);
    if (s.twisting_stiffness > 0.0) energy += 0.5 * twist * twist / s.twisting_stiffness;
  }
  return energy;
}

// Whether a material with this bond radius ratio carries moments.
inline bool BondsCarryMoments(double radius_ratio) { return radius_ratio > 0.0; }

}  // namespace specimen
