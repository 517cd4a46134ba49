#pragma once
// The DDEM solver core: bonded DEM with optionally deformable particles, in 2D (discs,
// l = 1 m) and 3D (spheres). A Simulation is built once from a Packing and SceneOptions:
// it validates the input, creates the bonds (the packing's contact pairs within the gap
// tolerance), fixes the time step against the critical one, and chooses the stages of the
// step (StepPlan). Run() then advances it; runs can be chained (ramp, hold, unload) and the
// state read in between.
//
//   Simulation<2> simulation(packing, scene);
//   RunOptions run;
//   run.duration_s = 1e-4;
//   RunSummary summary = simulation.Run(run);
//   std::cout << summary.FullReport();
//
// Errors: InputError for bad options or packings (naming the field and its range), a time
// step above the critical one without TimeStepOptions::allow_above_critical; a run that
// diverges (NaN, kinetic energy or contact force growing beyond the energy supplied)
// throws ComputationError naming what grew and the step. The simulation writes no files.

#include <memory>
#include <string>

#include "generator/packing.h"
#include "solver/contact_law.h"
#include "solver/ddem.h"
#include "solver/energy.h"
#include "solver/particle_update.h"
#include "solver/particles.h"
#include "solver/run_summary.h"
#include "solver/scene.h"
#include "solver/scene_state.h"
#include "solver/step_plan.h"
#include "solver/time_step.h"
#include "solver/walls.h"

namespace specimen {

template <int Dim>
class Simulation {
 public:
  Simulation(const Packing<Dim>& packing, const SceneOptions<Dim>& options);
  ~Simulation();
  Simulation(Simulation&&) noexcept;
  Simulation& operator=(Simulation&&) noexcept;
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  // Advances the simulation until a bound of `options` is reached. Throws InputError for
  // invalid options and ComputationError when the run diverges (the summary of the failed
  // run stays available through last_summary()).
  RunSummary Run(const RunOptions& options);
  const RunSummary& last_summary() const { return last_summary_; }

  // --- Scene facts ---
  const StepPlan& plan() const { return plan_; }
  double time_step_s() const;
  const CriticalTimeStepEstimate& critical_time_step() const { return critical_; }
  long step() const;
  double time_s() const;

  // --- State (between runs) ---
  // The state in the packing's order (large scenes are renumbered inside: scene_state.h).
  const SceneState<Dim>& state() const { return external_view_.Get(*state_); }
  const ParticleArrays<Dim>& particles() const;
  const ContactArrays<Dim>& contacts() const;
  int wall_count() const;
  const WallState<Dim>& wall(int index) const;
  // Sum of the constraint forces on the axes that FixedDofs set `set` prescribes [N].
  Vector<Dim> FixedDofsReaction(int set) const;
  // The energy audit at the last evaluated step.
  EnergyBalance Energy() const;
  // DDEM particle stress sigma = D^-1 eps [Pa] (zero for rigid particles).
  SymmetricTensor<Dim> ParticleStress(int particle) const;
  int IntactBondCount() const;

  // --- State changes (between runs) ---
  void SetVelocity(int particle, const Vector<Dim>& velocity);
  void SetAngularVelocity(int particle, const Angular<Dim>& angular_velocity);
  // Replaces the drive of a wall (velocity, force, servo and their amplitudes, e.g. a platen
  // servo-held during consolidation, then driven at a velocity). The wall keeps its current
  // position and normal (those of `options` are ignored). Its stiffnesses and friction must
  // not change (they bound the time step): InputError otherwise, or for invalid options.
  void SetWallOptions(int wall, const WallOptions<Dim>& options);

  // Madan (3.5)-(3.7): the implicit DDEM force iteration at the current positions (ddem.h).
  ForceIterationSummary IterateDeformedContactForces(const ForceIterationOptions& options);

 private:
  struct StepTotals;
  void Step(StepTotals* totals);
  bool SearchNeeded() const;
  void Search();
  [[noreturn]] void Diverged(const std::string& what, RunSummary* summary);
  void FillSummary(RunSummary* summary) const;
  void ChooseStages();

  std::unique_ptr<SceneState<Dim>> state_;
  StepPlan plan_;
  CriticalTimeStepEstimate critical_;
  double energy_growth_factor_ = 1e6;
  // With TimeStepOptions::from_stability_analysis: the analysis' one-line report, quoted
  // when a run diverges.
  std::string stability_note_;
  double stiffest_spring_n_per_m_ = 0.0;
  bool time_step_above_critical_ = false;
  RunSummary last_summary_;
  // Per-run tracking.
  double last_unbalanced_ratio_ = 0.0;
  int last_loaded_contacts_ = 0;
  long searches_at_run_start_ = 0;
  // The stages chosen for the plan (function pointers into the instantiated passes).
  ContactPassFunction<Dim> contact_pass_ = nullptr;
  ParticlePassFunction<Dim> particle_pass_ = nullptr;
  // The packing-order copy the accessors return for a renumbered scene; a change of the
  // state other than a step must call external_view_.Invalidate().
  ExternalView<Dim> external_view_;
};

}  // namespace specimen
