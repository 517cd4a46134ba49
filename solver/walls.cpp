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
  if (!conforming() && (!jaw_weights.empty() || !jaw_inward.empty()))
    return fail("jaw_weights and jaw_inward are given without jaw_particles");
  if (conforming()) {
    const size_t n = jaw_particles.size();
    if (jaw_weights.size() != n || jaw_inward.size() != n)
      return fail("jaw_weights and jaw_inward must have one entry per jaw particle (" + std::to_string(n) + ")");
    if (drive != WallDrive::kVelocity || tangential_stiffness_n_per_m > 0.0)
      return fail("a conforming jaw is velocity-driven and frictionless");
    double total = 0.0;
    for (size_t k = 0; k < n; ++k) {
      if (!(jaw_weights[k] > 0.0) || !std::isfinite(jaw_weights[k]))
        return fail("jaw_weights[" + std::to_string(k) + "] = " + number(jaw_weights[k]) + " must be finite and > 0");
      if (!jaw_inward[k].allFinite() || std::abs(jaw_inward[k].norm() - 1.0) > 1e-9)
        return fail("jaw_inward[" + std::to_string(k) + "] must be a unit vector");
      total += jaw_weights[k];
    }
    if (std::abs(total - 1.0) > 1e-9) return fail("jaw_weights sum to " + number(total) + ", not 1");
    // The travel is the motion along the normal: a jaw moves only along it.
    const Vector<Dim> unit = normal / normal.norm();
    if ((velocity - velocity.dot(unit) * unit).norm() > 1e-12 * std::max(1.0, velocity.norm()))
      return fail("a conforming jaw moves along its normal only: velocity must be parallel to it");
    double reach = 0.0;
    for (size_t k = 0; k < n; ++k) reach += jaw_weights[k] * jaw_inward[k].dot(unit);
    if (!(reach > 0.0))
      return fail("the jaw's reach sum w_k n_k . normal = " + number(reach) + " must be > 0 (n_k point into the specimen)");
    std::vector<int> sorted = jaw_particles;
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
      return fail("jaw_particles holds a particle twice");
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

// A conforming jaw's forces at t_n (walls.h): F = K max(p, 0) shared along the n_k.
template <int Dim>
Vector<Dim> JawForces(SceneState<Dim>& s, WallState<Dim>& w, bool deformable, WallPassTotals* totals) {
  const ParticleArrays<Dim>& p = s.particles;
  const int count = static_cast<int>(w.particle.size());
  double penetration = w.jaw_travel_m * w.jaw_reach;
  for (int k = 0; k < count; ++k) {
    const int q = w.particle[k];
    const Vector<Dim>& n = w.jaw_inward[k];
    double approach = n.dot(p.position[q] - w.jaw_reference_centre[k]);
    // The surface point s = -R n moves by eps s: towards the jaw by R n.eps.n.
    if (deformable) approach -= p.radius[q] * QuadraticForm(p.strain[q], n);
    penetration -= w.jaw_weight[k] * approach;
  }
  w.jaw_penetration_m = penetration;
  const double force = w.options.JawStiffness() * std::max(penetration, 0.0);
  Vector<Dim> force_on_wall = Vector<Dim>::Zero();
  for (int k = 0; k < count; ++k) {
    const int q = w.particle[k];
    const double share = force * w.jaw_weight[k];
    w.normal_elastic_force[k] = -share;
    if (share == 0.0) continue;
    const Vector<Dim> f = share * w.jaw_inward[k];
    s.external_force[q] += f;  // along n through the centre: no torque
    if (deformable) s.external_moment[q].noalias() += (-p.radius[q] * w.jaw_inward[k]) * f.transpose();
    force_on_wall -= f;
    totals->max_force_n = std::max(totals->max_force_n, share);
  }
  return force_on_wall;
}

}  // namespace

template <int Dim>
double WallState<Dim>::ElasticEnergy() const {
  if (options.conforming()) {
    const double p = std::max(jaw_penetration_m, 0.0);
    return 0.5 * options.JawStiffness() * p * p;
  }
  const double k_wall = options.normal_stiffness_n_per_m, kt_wall = options.tangential_stiffness_n_per_m;
  double energy = 0.0;
  for (size_t k = 0; k < particle.size(); ++k) {
    energy += 0.5 * normal_elastic_force[k] * normal_elastic_force[k] / k_wall;
    if (kt_wall > 0.0) energy += 0.5 * tangential_force[k].squaredNorm() / kt_wall;
  }
  return energy;
}

template <int Dim>
void StartJaw(WallState<Dim>& w, const std::vector<Vector<Dim>>& centres) {
  const WallOptions<Dim>& o = w.options;
  std::vector<size_t> order(o.jaw_particles.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return o.jaw_particles[a] < o.jaw_particles[b]; });
  w.particle.clear();
  w.jaw_inward.clear();
  w.jaw_weight.clear();
  w.jaw_reference_centre.clear();
  w.jaw_reach = 0.0;
  for (const size_t k : order) {
    w.particle.push_back(o.jaw_particles[k]);
    w.jaw_inward.push_back(o.jaw_inward[k]);
    w.jaw_weight.push_back(o.jaw_weights[k]);
    w.jaw_reference_centre.push_back(centres[o.jaw_particles[k]]);
    w.jaw_reach += o.jaw_weights[k] * o.jaw_inward[k].dot(w.normal);
  }
  w.normal_elastic_force.assign(w.particle.size(), 0.0);
  w.tangential_force.assign(w.particle.size(), Vector<Dim>::Zero());
  w.jaw_travel_m = w.jaw_penetration_m = 0.0;
}

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
    const int count = o.conforming() ? 0 : static_cast<int>(w.particle.size());
    if (o.conforming()) force_on_wall = JawForces(s, w, deformable, totals);
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
    if (o.conforming())
      w.jaw_travel_m += w.velocity.dot(normal) * dt;  // its particles are fixed: no search
    else
      w.displacement_since_search += w.velocity.norm() * dt;
  }
}

template <int Dim>
void RebuildWallCandidates(SceneState<Dim>& s, double skin) {
  const ParticleArrays<Dim>& p = s.particles;
  for (WallState<Dim>& w : s.walls) {
    if (w.options.conforming()) continue;
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
template void StartJaw<2>(WallState<2>&, const std::vector<Vector<2>>&);
template void StartJaw<3>(WallState<3>&, const std::vector<Vector<3>>&);
template struct WallState<2>;
template struct WallState<3>;
template void RebuildWallCandidates<2>(SceneState<2>&, double);
template void RebuildWallCandidates<3>(SceneState<3>&, double);

}  // namespace specimen
