#pragma once
// Prescribed loading of particles: time amplitudes, point loads on particle sets, and
// fixed (or velocity-prescribed) degrees of freedom.
//
// A point load acts at a point of the particle surface, s = R d (d a unit direction, e.g.
// the pole d = +e_y of a top-row particle in Madan's SC test). It adds the force and the
// moment s x F to the particle and, in a DDEM scene, the surface traction term s (x) F to
// the particle stress (Madan section 2.3: "the averaging formula should also include
// reaction forces and other external surface forces").

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "solver/vector_algebra.h"

namespace specimen {

template <int Dim>
struct SceneState;

// A piecewise-linear factor of time: (time [s], factor) points in non-decreasing time, the
// factor constant before the first and after the last point. Two points at the same time
// make a jump (the later one applies from that time on). No points: constantly 1.
struct Amplitude {
  std::vector<std::pair<double, double>> points;

  double operator()(double time_s) const;
  // 0 -> 1 linearly over [0, ramp_time_s], then 1.
  static Amplitude Ramp(double ramp_time_s);
  // 1 on [0, until_s), then 0.
  static Amplitude Until(double until_s);
  bool IsValid(std::string* error) const;
};

template <int Dim>
struct PointLoad {
  std::string name;            // for reports, e.g. "top row"
  std::vector<int> particles;  // particle indices of the packing
  // Force on each particle [N] (2D: per unit thickness), times amplitude(t).
  Vector<Dim> force_n = Vector<Dim>::Zero();
  // Unit vector from the centre to the loaded surface point: s = R d. Zero: the force
  // acts at the centre (no moment, and no contribution to the DDEM particle stress).
  Vector<Dim> application_direction = Vector<Dim>::Zero();
  Amplitude amplitude;
};

template <int Dim>
struct FixedDofs {
  std::string name;            // for reports, e.g. "middle column"
  std::vector<int> particles;  // particle indices of the packing
  // Which translational axes are prescribed.
  std::array<bool, Dim> fix_translation{};
  // Rotation held at zero angular velocity.
  bool fix_rotation = false;
  // Velocity [m/s] of the prescribed axes, times amplitude(t): zero holds them in place.
  Vector<Dim> velocity = Vector<Dim>::Zero();
  // If not empty: one velocity per particle, replacing `velocity` (e.g. an affine field).
  std::vector<Vector<Dim>> particle_velocities;
  Amplitude amplitude;
};

// A point load during a run, with the bookkeeping of its work through the particle
// deformation (DDEM): the loaded surface point moves with the centre and by eps s (Madan
// (2.52)), and the load works on both.
template <int Dim>
struct PointLoadState {
  PointLoad<Dim> load;  // application_direction normalised
  // Per particle: eps s at the last accounting, and the amplitude then.
  std::vector<Vector<Dim>> surface_displacement;
  double accounted_amplitude = 0.0;
};

// The load work of one step.
struct PointLoadWork {
  double centre_j = 0.0;       // on the centre displacement
  double deformation_j = 0.0;  // on the deformation displacement eps s of the load point (DDEM)
  double supplied_j = 0.0;     // sum of |increments|
};

// Adds the point loads at t_n to the particles' external force, moment and (DDEM) surface
// moment accumulators, and their work:
//  - on the centres, trapezoidal over the last step: (F(t_{n-1}) + F(t_n))/2 . v_{n-1/2} dt,
//    and for a load at a surface point on a rotating particle its moment's
//    (s x F(t_{n-1}) + s x F(t_n))/2 . w_{n-1/2} dt;
//  - DDEM, on the deformation of the load point: trapezoidal over the strain change of the
//    previous step, (F_then + F(t_{n-1}))/2 . (eps_{n-1} - eps_then) s (the strain of t_{n-1}
//    is the latest known; PendingDeformationWork() adds the last increment for reports).
template <int Dim>
void PointLoadPass(SceneState<Dim>& state, bool deformable, bool rotation, PointLoadWork* work);

// The deformation work not yet accounted by PointLoadPass, up to the strain of the last
// evaluated step (t_{n-1} after n steps).
template <int Dim>
double PendingDeformationWork(const SceneState<Dim>& state);

}  // namespace specimen
