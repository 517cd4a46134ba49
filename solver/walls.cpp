#include "solver/walls.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "solver/scene_state.h"

namespace specimen {

template <int Dim>
bool WallOptions<Dim>::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = "wall \"" + name + "\": " + message;
    return false;
  };
  auto number = [](double v) {
    std::ostringstream out;
    out.precision(6);
    out << v;
    return out.str();
  };
  if (!point.allFinite()) return fail("point is not a finite point");
  if (!normal.allFinite() || !(normal.norm() > 0.0))
    return fail("normal must be a finite, non-zero vector");
  if (!(normal_stiffness_n_per_m > 0.0) || !std::isfinite(normal_stiffness_n_per_m))
    return fail("normal_stiffness_n_per_m = " + number(normal_stiffness_n_per_m) +
                " is not allowed: it must be finite and > 0");
  if (!(tangential_stiffness_n_per_m >= 0.0) || !std::isfinite(tangential_stiffness_n_per_m))
    return fail("tangential_stiffness_n_per_m = " + number(tangential_stiffness_n_per_m) +
                " is not allowed: it must be finite and >= 0");
  if (!(friction_coefficient >= 0.0) || !std::isfinite(friction_coefficient))
    return fail("friction_coefficient = " + number(friction_coefficient) +
                " is not allowed: it must be finite and >= 0");
  if (friction_coefficient > 0.0 && tangential_stiffness_n_per_m == 0.0)
    return fail("friction_coefficient = " + number(friction_coefficient) +
                " needs tangential_stiffness_n_per_m > 0");
  if (!velocity.allFinite()) return fail("velocity is not finite");
  std::string amplitude_error;
  if (!velocity_amplitude.IsValid(&amplitude_error))
    return fail("velocity_amplitude: " + amplitude_error);
  if (!force_amplitude.IsValid(&amplitude_error))
    return fail("force_amplitude: " + amplitude_error);
  if (drive == WallDrive::kForce) {
    if (!(mass_kg > 0.0) || !std::isfinite(mass_kg))
      return fail("mass_kg = " + number(mass_kg) +
                  " is not allowed: a force-driven wall needs a finite mass > 0");
    if (!std::isfinite(applied_force_n)) return fail("applied_force_n is not finite");
  }
  if (drive == WallDrive::kServo) {
    if (!(servo.stress_pa >= 0.0) || !std::isfinite(servo.stress_pa))
      return fail("servo.stress_pa = " + number(servo.stress_pa) +
                  " is not allowed: it must be finite and >= 0");
    if (servo.area_wall_pairs.empty() &&
        (!(servo.reference_area_m2 > 0.0) || !std::isfinite(servo.reference_area_m2)))
      return fail("servo.reference_area_m2 = " + number(servo.reference_area_m2) +
                  " is not allowed: without area_wall_pairs it must be finite and > 0");
    if (!(servo.gain_fraction > 0.0 && servo.gain_fraction <= 1.0))
      return fail("servo.gain_fraction = " + number(servo.gain_fraction) +
                  " is not allowed: it must be in (0, 1]");
    if (!(servo.integral_time_s >= 0.0) || !std::isfinite(servo.integral_time_s))
      return fail("servo.integral_time_s = " + number(servo.integral_time_s) +
                  " is not allowed: it must be finite and >= 0");
    if (!(servo.max_speed_m_per_s > 0.0) || !std::isfinite(servo.max_speed_m_per_s))
      return fail("servo.max_speed_m_per_s = " + number(servo.max_speed_m_per_s) +
                  " is not allowed: it must be finite and > 0");
  }
  return true;
}

template struct WallOptions<2>;
template struct WallOptions<3>;

namespace {

// The servo's target force at t_n: stress x the area spanned by the paired walls (WallServo).
template <int Dim>
double ServoTargetForce(const SceneState<Dim>& s, const WallServo& servo) {
  double area = servo.reference_area_m2;
  if (!servo.area_wall_pairs.empty()) {
    area = 1.0;  // 2D: per unit thickness
    for (const auto& [a, b] : servo.area_wall_pairs)
      area *= std::abs((s.walls[b].point - s.walls[a].point).dot(s.walls[a].normal));
  }
  return servo.stress_pa * area;
}

}  // namespace

template <int Dim>
void WallPass(SceneState<Dim>& s, bool deformable, bool rotation, bool dashpots,
              WallPassTotals* totals) {
  const ParticleArrays<Dim>& p = s.particles;
  const double dt = s.time_step_s;
  // Servo targets from the wall positions at t_n, before any wall moves.
  for (WallState<Dim>& w : s.walls)
    if (w.options.drive == WallDrive::kServo)
      w.servo_target_force_n = ServoTargetForce(s, w.options.servo);
  for (WallState<Dim>& w : s.walls) {
    const WallOptions<Dim>& o = w.options;
    const Vector<Dim>& normal = w.normal;
    const double k_wall = o.normal_stiffness_n_per_m, kt_wall = o.tangential_stiffness_n_per_m;
    const bool friction = o.friction();
    const double dashpot =
        dashpots ? 2.0 * s.material.normal_dashpot_ratio * std::sqrt(k_wall) : 0.0;
    Vector<Dim> force_on_wall = Vector<Dim>::Zero();
    int touching = 0;
    const int count = static_cast<int>(w.particle.size());
    for (int k = 0; k < count; ++k) {
      const int q = w.particle[k];
      const double r = p.radius[q];
      double gap = (p.position[q] - w.point).dot(normal) - r;
      // Madan (2.53) with a rigid wall: only the particle's contact point moves.
      if (deformable) gap -= r * QuadraticForm(p.strain[q], normal);
      if (gap >= 0.0) {
        w.normal_elastic_force[k] = 0.0;
        w.tangential_force[k].setZero();
        continue;
      }
      // The contact normal from the particle to the wall is -normal; fn = k gap < 0 pushes
      // the particle along +normal.
      const double fn = k_wall * gap;
      Vector<Dim> force = -fn * normal;
      const Vector<Dim> arm = -r * normal;
      Vector<Dim> relative_velocity = w.velocity - p.velocity[q];
      if (rotation) relative_velocity -= Cross(p.angular_velocity[q], arm);
      if (dashpot > 0.0) {
        const double approach = -relative_velocity.dot(normal);  // along -normal
        double normal_damping = dashpot * std::sqrt(p.mass[q]) * approach;
        normal_damping = std::min(normal_damping, -fn);  // never pulls
        force -= normal_damping * normal;
        totals->dashpot_dissipation_j += normal_damping * approach * dt;
      }
      if (friction) {
        const Vector<Dim> tangential_velocity =
            relative_velocity - relative_velocity.dot(normal) * normal;
        Vector<Dim> ft = w.tangential_force[k] + (kt_wall * dt) * tangential_velocity;
        const double limit = o.friction_coefficient * std::abs(fn);
        const double trial = ft.norm();
        if (trial > limit) {
          totals->friction_dissipation_j += limit * (trial - limit) / kt_wall;
          ft *= limit / trial;
        }
        w.tangential_force[k] = ft;
        force += ft;
      }
      w.normal_elastic_force[k] = fn;
      ++touching;
      s.external_force[q] += force;
      if (rotation) s.external_torque[q] += Cross(arm, force);
      if (deformable) s.external_moment[q].noalias() += arm * force.transpose();
      force_on_wall -= force;
      totals->max_force_n = std::max(totals->max_force_n, force.norm());
    }
    w.force_on_wall = force_on_wall;
    if (!force_on_wall.allFinite()) totals->finite = false;

    // Drive force and its work, trapezoidal over the wall displacement from t_{n-1} to t_n.
    Vector<Dim> drive_force;
    if (o.drive != WallDrive::kForce) {
      drive_force = -force_on_wall;  // a massless wall held on its path
    } else {
      drive_force =
          (o.applied_force_n * o.force_amplitude(s.time_s)) * normal;  // towards the particles
    }
    if (s.step > 0) {
      const double work = 0.5 * (w.previous_drive_force + drive_force).dot(w.velocity * dt);
      w.work_j += work;
      totals->work_j += work;
      totals->supplied_j += std::abs(work);
    }
    w.previous_drive_force = drive_force;

    // Motion to t_{n+1}.
    const Vector<Dim> v_old = w.velocity;
    if (o.drive == WallDrive::kVelocity) {
      w.velocity = o.velocity * o.velocity_amplitude(s.time_s + 0.5 * dt);
    } else if (o.drive == WallDrive::kServo) {
      // WallServo: proportional-integral speed along the normal from the force error.
      const WallServo& servo = o.servo;
      const double error = w.servo_target_force_n - w.NormalReaction();
      const double gain = servo.gain_fraction / (k_wall * std::max(1, touching) * dt);
      double control = error;
      if (servo.integral_time_s > 0.0) {
        const double integral = w.servo_error_integral_n_s + error * dt;
        control += integral / servo.integral_time_s;
        // Anti-windup: the integral only grows while the speed is not at its bound.
        if (std::abs(gain * control) <= servo.max_speed_m_per_s) w.servo_error_integral_n_s = integral;
      }
      const double speed =
          std::clamp(gain * control, -servo.max_speed_m_per_s, servo.max_speed_m_per_s);
      w.velocity = speed * normal;
    } else {
      // Central differences along the normal, with non-viscous damping (Madan (2.7)).
      const double resultant = (drive_force + force_on_wall).dot(normal);
      const double speed = v_old.dot(normal);
      double damping = 0.0;
      if (speed != 0.0)
        damping =
            -s.material.translational_damping * std::abs(resultant) * (speed > 0 ? 1.0 : -1.0);
      const double new_speed = speed + (resultant + damping) * dt / o.mass_kg;
      w.velocity = new_speed * normal;
      totals->kinetic_energy_j += 0.5 * o.mass_kg * speed * new_speed;
      totals->damping_dissipation_j -= damping * 0.5 * (speed + new_speed) * dt;
    }
    w.point += w.velocity * dt;
    w.displacement_since_search += w.velocity.norm() * dt;
  }
}

template <int Dim>
void RebuildWallCandidates(SceneState<Dim>& s, double skin) {
  const ParticleArrays<Dim>& p = s.particles;
  for (WallState<Dim>& w : s.walls) {
    w.scratch_particle.clear();
    w.scratch_normal_force.clear();
    w.scratch_tangential_force.clear();
    size_t old = 0;
    for (int q = 0; q < p.size(); ++q) {
      const double distance = (p.position[q] - w.point).dot(w.normal) - p.radius[q];
      while (old < w.particle.size() && w.particle[old] < q) ++old;
      const bool was_candidate = old < w.particle.size() && w.particle[old] == q;
      if (distance >= skin) continue;
      w.scratch_particle.push_back(q);
      w.scratch_normal_force.push_back(was_candidate ? w.normal_elastic_force[old] : 0.0);
      w.scratch_tangential_force.push_back(was_candidate ? w.tangential_force[old]
                                                         : Vector<Dim>::Zero());
    }
    std::swap(w.particle, w.scratch_particle);
    std::swap(w.normal_elastic_force, w.scratch_normal_force);
    std::swap(w.tangential_force, w.scratch_tangential_force);
    w.displacement_since_search = 0.0;
  }
}

template void WallPass<2>(SceneState<2>&, bool, bool, bool, WallPassTotals*);
template void WallPass<3>(SceneState<3>&, bool, bool, bool, WallPassTotals*);
template void RebuildWallCandidates<2>(SceneState<2>&, double);
template void RebuildWallCandidates<3>(SceneState<3>&, double);

}  // namespace specimen
