#pragma once
// The stages of a time step, chosen once from the scene before the loop, leaving out what a
// given scene does not need (docs/solver.md, "Stage plan"). Each flag selects an
// instantiation of a pass (SelectContactPass, SelectParticlePass) or switches a small pass
// on; nothing tests these flags per contact inside the loops.
//
// A step, in order (stages in brackets exist only when the plan says so):
//   [neighbour_search]  rebuild candidate pairs and wall contacts when anything moved,
//                       or deformed, more than the search skin allows
//   contact_forces      normal law on every contact, with [ddem_deformed_overlap],
//                       [tangential] history and rotation, [bond_moments], [dashpots],
//                       [bond_failure]
//   [walls]             wall contacts, reactions, wall motion
//   [point_loads]       loads on particle sets
//   particle_update     force summation, [ddem_particle_strain] for the next step,
//                       [local_damping], [fixed_dofs], central differences, [rotation]

#include <string>
#include <vector>

namespace specimen {

struct StepPlan {
  bool deformable = false;        // DDEM: strain pass and deformed overlap (Ep given)
  bool breakable = false;         // bond failure check (finite Rn, or finite Rt with kt > 0)
  bool tangential = false;        // tangential spring history (kt > 0)
  bool bond_moments = false;      // bonds carry a moment (bond_radius_ratio > 0, bond_moment.h)
  bool dashpots = false;          // contact dashpots (xi_n > 0, or xi_t > 0 with kt > 0)
  bool local_damping = false;     // non-viscous damping (alpha_t > 0 or alpha_r > 0)
  bool rotation = false;          // rotational degrees of freedom can receive a moment
  bool walls = false;             // at least one wall
  bool wall_friction = false;     // a wall with friction
  bool point_loads = false;       // at least one point load
  bool fixed_dofs = false;        // at least one fixed degree of freedom
  bool neighbour_search = false;  // new contacts are searched for

  bool external() const { return walls || point_loads; }
  // The names of the stages the plan runs, in step order.
  std::vector<std::string> StageNames() const;
  // The names of the optional stages the plan leaves out.
  std::vector<std::string> OmittedStageNames() const;
};

}  // namespace specimen
