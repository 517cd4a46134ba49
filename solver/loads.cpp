#include "solver/loads.h"

#include <cmath>

#include "solver/scene_state.h"

namespace specimen {

double Amplitude::operator()(double time_s) const {
  if (points.empty()) return 1.0;
  if (time_s < points.front().first) return points.front().second;
  // Last point at or before time_s: with duplicated times the later one applies.
  size_t k = 0;
  while (k + 1 < points.size() && points[k + 1].first <= time_s) ++k;
  if (k + 1 == points.size()) return points.back().second;
  const auto& [t0, f0] = points[k];
  const auto& [t1, f1] = points[k + 1];
  return f0 + (f1 - f0) * (time_s - t0) / (t1 - t0);
}

Amplitude Amplitude::Ramp(double ramp_time_s) {
  Amplitude a;
  a.points = {{0.0, 0.0}, {ramp_time_s, 1.0}};
  return a;
}

Amplitude Amplitude::Until(double until_s) {
  Amplitude a;
  a.points = {{0.0, 1.0}, {until_s, 1.0}, {until_s, 0.0}};
  return a;
}

bool Amplitude::IsValid(std::string* error) const {
  for (size_t k = 0; k < points.size(); ++k) {
    if (!std::isfinite(points[k].first) || !std::isfinite(points[k].second)) {
      if (error) *error = "amplitude point " + std::to_string(k) + " is not finite";
      return false;
    }
    if (k > 0 && points[k].first < points[k - 1].first) {
      if (error)
        *error = "amplitude times must not decrease: point " + std::to_string(k) + " at " +
                 std::to_string(points[k].first) + " s comes after " +
                 std::to_string(points[k - 1].first) + " s";
      return false;
    }
  }
  return true;
}

template <int Dim>
void PointLoadPass(SceneState<Dim>& s, bool deformable, bool rotation, PointLoadWork* work) {
  const ParticleArrays<Dim>& p = s.particles;
  const double dt = s.time_step_s;
  for (PointLoadState<Dim>& state : s.loads) {
    const PointLoad<Dim>& load = state.load;
    const double amplitude = load.amplitude(s.time_s);
    const Vector<Dim> force = load.force_n * amplitude;
    const double previous_amplitude = s.step > 0 ? load.amplitude(s.time_s - dt) : amplitude;
    const Vector<Dim> previous = load.force_n * previous_amplitude;
    const bool at_surface = load.application_direction.squaredNorm() > 0.0;
    // Deformation work over the previous step: the force then and at t_{n-1}.
    const Vector<Dim> deformation_force =
        0.5 * (state.accounted_amplitude + previous_amplitude) * load.force_n;
    for (size_t k = 0; k < load.particles.size(); ++k) {
      const int q = load.particles[k];
      s.external_force[q] += force;
      if (at_surface) {
        const Vector<Dim> arm = p.radius[q] * load.application_direction;
        if (rotation) s.external_torque[q] += Cross(arm, force);
        if (deformable) {
          s.external_moment[q].noalias() += arm * force.transpose();
          // Madan (2.52): the load point moves by eps s with the particle's global mode.
          const Vector<Dim> displacement = FullMatrix(p.strain[q]) * arm;
          const double increment =
              deformation_force.dot(displacement - state.surface_displacement[k]);
          work->deformation_j += increment;
          work->supplied_j += std::abs(increment);
          state.surface_displacement[k] = displacement;
        }
      }
      if (s.step > 0) {
        double increment = 0.5 * (previous + force).dot(p.velocity[q]) * dt;
        // The moment of an eccentric load works on the particle's rotation (the arm is fixed
        // in space: the load is applied at the point of direction d whatever the spin).
        if (at_surface && rotation) {
          const Vector<Dim> arm = p.radius[q] * load.application_direction;
          increment += 0.5 * AngularDot(Cross(arm, Vector<Dim>(previous + force)),
                                        p.angular_velocity[q]) * dt;
        }
        work->centre_j += increment;
        work->supplied_j += std::abs(increment);
      }
    }
    state.accounted_amplitude = previous_amplitude;
  }
}

template <int Dim>
double PendingDeformationWork(const SceneState<Dim>& s) {
  if (s.particles.strain.empty() || s.step == 0) return 0.0;
  double work = 0.0;
  // After n steps the strain array holds eps_{n-1}, the strain of t_{n-1} = time_s - dt.
  for (const PointLoadState<Dim>& state : s.loads) {
    const PointLoad<Dim>& load = state.load;
    if (load.application_direction.squaredNorm() == 0.0) continue;
    const double amplitude = load.amplitude(s.time_s - s.time_step_s);
    const Vector<Dim> force = 0.5 * (state.accounted_amplitude + amplitude) * load.force_n;
    for (size_t k = 0; k < load.particles.size(); ++k) {
      const int q = load.particles[k];
      const Vector<Dim> arm = s.particles.radius[q] * load.application_direction;
      work += force.dot(FullMatrix(s.particles.strain[q]) * arm - state.surface_displacement[k]);
    }
  }
  return work;
}

template void PointLoadPass<2>(SceneState<2>&, bool, bool, PointLoadWork*);
template void PointLoadPass<3>(SceneState<3>&, bool, bool, PointLoadWork*);
template double PendingDeformationWork<2>(const SceneState<2>&);
template double PendingDeformationWork<3>(const SceneState<3>&);

}  // namespace specimen
