#include "solver/scene.h"
#include "common/format.h"

#include <cmath>
#include <sstream>

namespace specimen {

template <int Dim>
bool SceneOptions<Dim>::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  std::string inner;
  if (!material.IsValid(&inner)) return fail("material: " + inner);
  for (const WallOptions<Dim>& wall : walls)
    if (!wall.IsValid(&inner)) return fail(inner);
  for (const WallOptions<Dim>& wall : walls)  // servo areas name other walls
    for (const auto& pair : wall.servo.area_wall_pairs)
      for (const int index : pair)
        if (wall.drive == WallDrive::kServo && (index < 0 || index >= static_cast<int>(walls.size())))
          return fail("wall \"" + wall.name + "\": servo.area_wall_pairs holds the wall index " +
                      std::to_string(index) + ", outside [0, " + std::to_string(walls.size()) + ")");
  for (size_t k = 0; k < point_loads.size(); ++k) {
    const PointLoad<Dim>& load = point_loads[k];
    const std::string what = "point load " + std::to_string(k) + " (\"" + load.name + "\"): ";
    if (!load.force_n.allFinite()) return fail(what + "force_n is not finite");
    if (!load.application_direction.allFinite())
      return fail(what + "application_direction is not finite");
    if (!load.amplitude.IsValid(&inner)) return fail(what + "amplitude: " + inner);
  }
  for (size_t k = 0; k < fixed_dofs.size(); ++k) {
    const FixedDofs<Dim>& f = fixed_dofs[k];
    const std::string what = "fixed dofs " + std::to_string(k) + " (\"" + f.name + "\"): ";
    bool any = f.fix_rotation;
    for (bool axis : f.fix_translation) any = any || axis;
    if (!any) return fail(what + "fixes no degree of freedom");
    if (!f.velocity.allFinite()) return fail(what + "velocity is not finite");
    if (!f.particle_velocities.empty() && f.particle_velocities.size() != f.particles.size())
      return fail(what + "particle_velocities has " + std::to_string(f.particle_velocities.size()) +
                  " entries for " + std::to_string(f.particles.size()) + " particles");
    for (const auto& v : f.particle_velocities)
      if (!v.allFinite()) return fail(what + "a particle velocity is not finite");
    if (!f.amplitude.IsValid(&inner)) return fail(what + "amplitude: " + inner);
  }
  if (!(time_step.time_step_s >= 0.0) || !std::isfinite(time_step.time_step_s))
    return fail("time_step.time_step_s = " + Number(time_step.time_step_s) +
                " is not allowed: it must be > 0 (or 0 for safety_factor x critical)");
  if (!(time_step.safety_factor > 0.0 && time_step.safety_factor <= 1.0))
    return fail("time_step.safety_factor = " + Number(time_step.safety_factor) +
                " is not allowed: it must be in (0, 1]");
  if (!(time_step.critical_time_step_s >= 0.0) || !std::isfinite(time_step.critical_time_step_s))
    return fail("time_step.critical_time_step_s = " + Number(time_step.critical_time_step_s) +
                " is not allowed: it must be > 0 (or 0 for the per-particle bound)");
  if (!(time_step.max_spectral_radius > 0.0 && time_step.max_spectral_radius <= 1.0))
    return fail("time_step.max_spectral_radius = " + Number(time_step.max_spectral_radius) +
                " is not allowed: it must be in (0, 1]");
  if (!(contacts.bond_gap_tolerance >= 0.0 && contacts.bond_gap_tolerance <= 1.0))
    return fail("contacts.bond_gap_tolerance = " + Number(contacts.bond_gap_tolerance) +
                " is not allowed: it must be in [0, 1] (relative to the mean radius of the pair)");
  if (!(contacts.search_skin > 0.0 && contacts.search_skin <= 2.0))
    return fail("contacts.search_skin = " + Number(contacts.search_skin) +
                " is not allowed: it must be in (0, 2] (relative to the mean radius)");
  if (!(divergence.energy_growth_factor > 1.0) || !std::isfinite(divergence.energy_growth_factor))
    return fail("divergence.energy_growth_factor = " + Number(divergence.energy_growth_factor) +
                " is not allowed: it must be finite and > 1");
  if (num_threads < 1)
    return fail("num_threads = " + std::to_string(num_threads) +
                " is not allowed: it must be >= 1");
  return true;
}

template struct SceneOptions<2>;
template struct SceneOptions<3>;

}  // namespace specimen
