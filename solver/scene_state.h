#pragma once
// Everything a running simulation holds, as plain arrays: the data the passes (contact
// law, walls, point loads, particle update) read and write. Simulation owns one and is its
// only public face; the struct is exposed to the pass implementations (one file per
// physics) and, read-only, to analysis code through Simulation::state().

#include <Eigen/Core>
#include <array>
#include <vector>

#include "solver/contact_law.h"
#include "solver/loads.h"
#include "solver/material.h"
#include "solver/neighbour_search.h"
#include "solver/particles.h"
#include "solver/walls.h"

namespace specimen {

// Loops shorter than this run on one thread: the fork/join cost of a parallel region
// (microseconds) exceeds the work of a small lattice test.
constexpr int kParallelThreshold = 4096;

// Particle -> contact adjacency in compressed rows: particle p's contacts are
// entry[offset[p] .. offset[p + 1]), each entry = 2 * contact + side (0: p is the contact's
// i, 1: p is its j), in increasing contact order (deterministic sums).
struct ContactAdjacency {
  std::vector<int> offset;
  std::vector<int> entry;
};

// Prescribed degrees of freedom, compacted: only constrained particles have a slot.
template <int Dim>
struct ConstraintTable {
  std::vector<int> slot_of_particle;  // -1: free (size N; empty without constraints)
  std::vector<int> particle;          // per slot
  // Per slot and axis (Dim translations, then rotation): the FixedDofs set prescribing it, -1 free.
  std::vector<std::array<int, Dim + 1>> set_of_axis;
  std::vector<Vector<Dim>> velocity;          // per slot: prescribed velocity before amplitude
  std::vector<Vector<Dim>> reaction_force;    // per slot: constraint force of the last step
  std::vector<Angular<Dim>> reaction_torque;  // per slot
  std::vector<FixedDofs<Dim>> sets;
  std::vector<double> amplitude;  // per set, at the current half step t_{n+1/2}
};

// Running totals of the energy audit (design.md; Madan (2.55)-(2.61)).
struct EnergyAccumulators {
  double load_work_j = 0.0;              // point loads, on the centres and (DDEM) the deformation
  double load_deformation_work_j = 0.0;  // the part through the deformation of the load point
  double wall_work_j = 0.0;              // wall drives
  double constraint_work_j = 0.0;        // prescribed velocities
  double damping_dissipation_j = 0.0;
  double dashpot_dissipation_j = 0.0;
  double friction_dissipation_j = 0.0;
  double breakage_release_j = 0.0;
  // Sum of |work increments|: the energy supplied, the scale of the divergence check.
  double supplied_j = 0.0;
  double initial_total_j = 0.0;  // kinetic + elastic at the first step
  bool initial_recorded = false;
  double kinetic_j = 0.0;  // at the last step, 1/2 m v_{n-1/2} . v_{n+1/2}
};

template <int Dim>
struct SceneState {
  // Constants.
  MaterialParameters material;
  ContactLawConstants law;
  ParticleCompliance<Dim> compliance;
  double time_step_s = 0.0;
  int num_threads = 1;

  // Clock: the next step evaluates forces at time_s = step * time_step_s.
  long step = 0;
  double time_s = 0.0;

  ParticleArrays<Dim> particles;
  ContactArrays<Dim> contacts;
  ContactArrays<Dim> contacts_scratch;  // merge buffer of the neighbour search
  ContactAdjacency adjacency;
  std::vector<int> adjacency_cursor;  // fill buffer of RebuildAdjacency

  // External actions accumulated by the wall and load passes, read and cleared by the
  // particle update. Empty when the scene has neither walls nor loads; the torque array is
  // empty without rotation, the moment array (sum s (x) F, DDEM stress) for rigid particles.
  std::vector<Vector<Dim>> external_force;
  std::vector<Angular<Dim>> external_torque;
  std::vector<Eigen::Matrix<double, Dim, Dim>> external_moment;

  std::vector<WallState<Dim>> walls;
  std::vector<PointLoadState<Dim>> loads;
  ConstraintTable<Dim> constraints;

  // Neighbour search.
  CandidateSearch<Dim> search;
  std::vector<std::array<int, 2>> candidate_pairs;
  double search_skin_m = 0.0;
  double max_radius_m = 0.0;
  double displacement_since_search_m = 0.0;  // sum over steps of the largest displacement
  double strain_margin_at_search = 0.0;      // largest |eps| when the search last ran
  double max_strain = 0.0;                   // largest |eps| of the last step
  long searches = 0;

  EnergyAccumulators energy;
  long broken_in_tension = 0;
  long broken_in_shear = 0;
  int bonds_created = 0;
  int packing_pairs_not_bonded = 0;
  double time_step_given_s = 0.0;
};

// Rebuilds the particle -> contact adjacency from state.contacts.
template <int Dim>
void RebuildAdjacency(SceneState<Dim>& state);

// Bytes held by the state's arrays (capacities): the memory footprint of a simulation.
template <int Dim>
std::size_t MemoryBytes(const SceneState<Dim>& state);

}  // namespace specimen
