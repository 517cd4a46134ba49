#include "solver/step_plan.h"

#include <utility>

namespace specimen {

namespace {

// (name, present) in step order; the two mandatory stages are always present.
std::vector<std::pair<std::string, bool>> Stages(const StepPlan& p) {
  return {{"neighbour_search", p.neighbour_search},
          {"contact_forces", true},
          {"ddem_deformed_overlap", p.deformable},
          {"tangential", p.tangential},
          {"bond_moments", p.bond_moments},
          {"dashpots", p.dashpots},
          {"bond_failure", p.breakable},
          {"walls", p.walls},
          {"wall_friction", p.wall_friction},
          {"point_loads", p.point_loads},
          {"particle_update", true},
          {"ddem_particle_strain", p.deformable},
          {"local_damping", p.local_damping},
          {"fixed_dofs", p.fixed_dofs},
          {"rotation", p.rotation}};
}

}  // namespace

std::vector<std::string> StepPlan::StageNames() const {
  std::vector<std::string> names;
  for (const auto& [name, present] : Stages(*this))
    if (present) names.push_back(name);
  return names;
}

std::vector<std::string> StepPlan::OmittedStageNames() const {
  std::vector<std::string> names;
  for (const auto& [name, present] : Stages(*this))
    if (!present) names.push_back(name);
  return names;
}

}  // namespace specimen
