#pragma once
// Options of one run of a simulation, and what it reports: steps, time, the stages that
// ran (and those left out), the energy balance, broken bonds, wall reactions, the
// termination reason. BriefReport() is one line, FullReport() a table, ToJson() the same
// content for machines.

#include <cstddef>
#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "common/progress.h"
#include "solver/energy.h"
#include "solver/time_step.h"

namespace specimen {

struct RunOptions {
  // Upper bound on the number of steps of this run, >= 0; 0: no bound (then duration_s must
  // be given).
  long max_steps = 0;
  // Simulated time of this run [s], >= 0; 0: no bound. Rounded to whole steps.
  double duration_s = 0.0;
  // Static stop, for damped runs: when > 0, the run ends once the largest unbalanced force
  // on a free degree of freedom is at most this fraction of the mean (root mean square)
  // force of the loaded contacts (the "unbalanced force ratio"). Checked every
  // static_check_interval steps, and not before min_steps steps (e.g. the end of a load ramp).
  double static_force_ratio = 0.0;
  int static_check_interval = 10;
  long min_steps = 0;
  // Called every observe_interval steps (> 0) after the step, e.g. to record a curve.
  int observe_interval = 0;
  std::function<void()> observer;
  ProgressCallback progress;  // may be empty

  bool IsValid(std::string* error) const;
};

enum class TerminationReason { kStepLimit, kDuration, kStatic, kDiverged };

const char* TerminationReasonName(TerminationReason reason);

struct WallReport {
  std::string name;
  std::vector<double> point_m;          // current point of the plane
  std::vector<double> force_on_wall_n;  // force the particles exert on the wall
  double normal_reaction_n = 0.0;       // compressive reaction (>= 0 when pushed)
  int touching_particles = 0;
};

struct ConstraintReport {
  std::string name;
  std::vector<double> reaction_force_n;  // sum of the constraint forces on the set's axes
};

struct RunSummary {
  int dimension = 0;
  std::string particle_model;  // "rigid" or "deformable (DDEM): Ep, nu_p, plane model"
  long first_step = 0;
  long steps = 0;  // steps of this run
  double start_time_s = 0.0;
  double end_time_s = 0.0;
  double time_step_given_s = 0.0;  // TimeStepOptions::time_step_s (0: chosen from the limit)
  double time_step_s = 0.0;        // used
  CriticalTimeStepEstimate critical_time_step;
  bool time_step_above_critical = false;
  std::vector<std::string> stages;          // stages that ran, in step order
  std::vector<std::string> omitted_stages;  // optional stages the scene left out
  int particles = 0;
  int contacts = 0;         // contact records (bonds + candidates)
  int loaded_contacts = 0;  // carrying a force at the end
  int bonds_created = 0;
  int packing_pairs_not_bonded = 0;  // listed pairs outside the bond gap tolerance
  int bonds_intact = 0;
  long broken_in_tension = 0;  // since t = 0
  long broken_in_shear = 0;
  long broken_in_tension_this_run = 0;
  long broken_in_shear_this_run = 0;
  long neighbour_searches = 0;          // during this run
  double unbalanced_force_ratio = 0.0;  // at the end
  EnergyBalance energy;
  std::vector<WallReport> walls;
  std::vector<ConstraintReport> fixed_dofs;
  TerminationReason termination = TerminationReason::kStepLimit;
  std::string termination_message;
  double wall_seconds = 0.0;
  double particle_steps_per_second = 0.0;
  std::size_t memory_bytes = 0;  // simulation state (array capacities)

  std::string BriefReport() const;
  std::string FullReport() const;
  nlohmann::json ToJson() const;
};

}  // namespace specimen
