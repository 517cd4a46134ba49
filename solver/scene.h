#pragma once
// What a simulation is asked to do, apart from the packing: the material, the walls, the
// loads and prescribed degrees of freedom, the time step rule, contact detection and the
// divergence guard. Options in (this), RunSummary out (run_summary.h).
//
//   SceneOptions<2> scene;
//   scene.material.normal_stiffness_n_per_m = 7e10;
//   scene.material.density_kg_per_m3 = 2000;
//   scene.point_loads.push_back(top_row_load);
//   Simulation<2> simulation(packing, scene);   // validates, bonds, chooses the stages
//   RunSummary summary = simulation.Run(run);    // throws ComputationError on divergence

#include <string>
#include <vector>

#include "solver/loads.h"
#include "solver/material.h"
#include "solver/walls.h"

namespace specimen {

struct TimeStepOptions {
  // Time step [s], > 0; 0: safety_factor x the critical time step.
  double time_step_s = 0.0;
  // Fraction of the critical time step used when time_step_s = 0, in (0, 1]. The default
  // 0.7 is below 1/sqrt(2), where even the per-particle bound is provably stable
  // (time_step.h; DDEM scenes on that bound further multiply by its strain-lag factor).
  double safety_factor = 0.7;
  // Accept a time_step_s above the critical time step (stability studies). Without it such
  // a step is refused with an InputError naming the limit.
  bool allow_above_critical = false;
  // The critical time step [s] from a sharper analysis (the stability-limit stage); 0: use
  // the per-particle bound of Madan (2.18).
  double critical_time_step_s = 0.0;
  // Take the critical time step from the stability limits (stability_limits.h, the
  // default): the certified 2/omega_max of the assembled network, with the DDEM strain lag,
  // the dashpots at the stability boundary and the walls within the search skin; false: the
  // per-particle bound of time_step.h (cheaper, not a bound for irregular packings). The
  // default step is safety_factor x the critical one. A DDEM scene whose force iteration
  // does not converge, rho(B) >= max_spectral_radius, is refused with an InputError naming
  // rho(B) and the admissible kn/(Ep l), unless allow_above_critical.
  bool from_stability_analysis = true;
  // The largest rho(B) accepted with from_stability_analysis, in (0, 1].
  double max_spectral_radius = 1.0;
};

struct ContactDetectionOptions {
  // A pair of the packing's contact list becomes a bond when its gap satisfies
  // |g0| <= bond_gap_tolerance (ri + rj)/2 (Madan (2.21)); in [0, 1]. Other listed pairs
  // start as unbonded (frictional) contacts.
  double bond_gap_tolerance = 0.05;
  // true: a bond's zero-force gap is its initial gap, so the specimen starts stress-free
  // (Labra 2012 leaves the initial bonds open; docs/solver.md, "Bonds and the contact
  // law"); false: zero, initial gaps and overlaps load the bonds.
  bool stress_free_bonds = true;
  // Search for contacts between particles that are not bonded (after breakage, or when a
  // deformed particle bulges into a neighbour, Madan Fig. 2.4).
  bool detect_new_contacts = true;
  // Search skin relative to the packing's mean radius, in (0, 2]: candidates are pairs with
  // |xj - xi| < ri + rj + skin; the search reruns when anything moved (or, in DDEM,
  // deformed) enough to close the skin. Also the wall-candidate distance.
  double search_skin = 0.2;
};

struct DivergenceOptions {
  // A run stops with ComputationError when the kinetic energy exceeds this factor times the
  // energy supplied so far (initial energy + sum of |work increments|), or the largest
  // contact force exceeds the force sqrt(factor x 2 k_max E_supplied) (the force a spring of
  // the stiffest kind would carry holding factor x all that energy). > 1.
  double energy_growth_factor = 1e6;
};

template <int Dim>
struct SceneOptions {
  MaterialParameters material;
  std::vector<WallOptions<Dim>> walls;
  std::vector<PointLoad<Dim>> point_loads;
  std::vector<FixedDofs<Dim>> fixed_dofs;
  TimeStepOptions time_step;
  ContactDetectionOptions contacts;
  DivergenceOptions divergence;
  // OpenMP threads for the contact and particle passes (loops shorter than 4096 run on one).
  int num_threads = 1;

  // Names the first invalid field, its value and the allowed range. Particle indices are
  // checked against the packing when the Simulation is built.
  bool IsValid(std::string* error) const;
};

}  // namespace specimen
