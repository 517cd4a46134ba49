#pragma once
// Everything a running simulation holds, as plain arrays: the data the passes (contact
// law, walls, point loads, particle update) read and write. Simulation owns one and is its
// only public face; the struct is exposed to the pass implementations (one file per
// physics) and, read-only, to analysis code through Simulation::state().

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
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

// Scenes with at least this many particles are renumbered along a Hilbert curve at
// construction (ApplySpatialOrder): smaller ones keep the packing's order.
constexpr int kSpatialOrderThreshold = kParallelThreshold;

// The order of the particles inside a simulation. A large packing is renumbered along a
// space-filling (Hilbert) curve, so that neighbours, and their contacts (sorted by pair), sit
// close in memory: the contact and particle passes then read particle data mostly from
// cache. Simulation's accessors present everything in the packing's order (ExternalView);
// indices given to it (loads, fixed dofs, SetVelocity, ...) are the packing's.
struct ParticleOrder {
  // Internal index of packing particle q, and the reverse; both empty: the packing's order.
  std::vector<int> internal_of_external;
  std::vector<int> external_of_internal;

  bool identity() const { return internal_of_external.empty(); }
  int Internal(int external) const {
    return identity() ? external : internal_of_external[external];
  }
  int External(int internal) const {
    return identity() ? internal : external_of_internal[internal];
  }
};

// DDEM: what the contact pass reads of a particle's strain, one cache line (3D) or half of
// one (2D) per particle. For particle q with strain eps and radius r it holds r eps with the
// shear components doubled, in the Voigt order of SymmetricTensor:
//   2D: r (e_xx, e_yy, 2 e_xy), 3D: r (e_xx, e_yy, e_zz, 2 e_yz, 2 e_xz, 2 e_xy),
// so that the normal displacement of the contact point at unit normal n, r n.eps.n
// (Madan (2.53)), is the dot product of it with (n_x^2, n_y^2, [n_z^2,] products of two
// components): ContactDeformation::Normal. The contact gathers one line for j's strain
// instead of the 1.5 lines of a packed 48-byte tensor, and multiplies no radius.
template <int Dim>
struct alignas(Dim == 2 ? 32 : 64) ContactDeformation {
  double d[Dim == 2 ? 4 : 8] = {};

  void Set(const SymmetricTensor<Dim>& strain, double radius) {
    for (int k = 0; k < Dim; ++k) d[k] = radius * strain[k];
    for (int k = Dim; k < kVoigtSize<Dim>; ++k) d[k] = (2.0 * radius) * strain[k];
  }
};

// r_i n.eps_i.n + r_j n.eps_j.n from the two particles' rows.
inline double NormalDisplacementSum(const ContactDeformation<2>& a, const ContactDeformation<2>& b,
                                    const Vector<2>& n) {
  return (a.d[0] + b.d[0]) * (n.x() * n.x()) + (a.d[1] + b.d[1]) * (n.y() * n.y()) +
         (a.d[2] + b.d[2]) * (n.x() * n.y());
}
inline double NormalDisplacementSum(const ContactDeformation<3>& a, const ContactDeformation<3>& b,
                                    const Vector<3>& n) {
  return (a.d[0] + b.d[0]) * (n.x() * n.x()) + (a.d[1] + b.d[1]) * (n.y() * n.y()) +
         (a.d[2] + b.d[2]) * (n.z() * n.z()) + (a.d[3] + b.d[3]) * (n.y() * n.z()) +
         (a.d[4] + b.d[4]) * (n.x() * n.z()) + (a.d[5] + b.d[5]) * (n.x() * n.y());
}

// Particle -> contact adjacency in compressed rows: particle p's contacts are
// entry[offset[p] .. offset[p + 1]), each entry = 2 * contact + side (0: p is the contact's
// i, 1: p is its j), in increasing contact order (deterministic sums).
// The entry array holds kAdjacencyPadding zeros past its last entry, so that a pass may read
// (prefetch) a fixed number of entries ahead without a bounds check.
constexpr int kAdjacencyPadding = 16;

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

// Running totals of the energy audit (docs/solver.md, "Energy balance"; Madan (2.55)-(2.61)).
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
  // DDEM: particles.strain in the contact pass's form (ContactDeformation), written by the
  // particle pass next to the strain. Valid while deformation_step == step; anything else
  // that changes the strains (the force iteration, a renumbering) sets deformation_step to
  // -1 and the next contact pass rebuilds it (RefreshContactDeformation).
  std::vector<ContactDeformation<Dim>> deformation;
  long deformation_step = -1;
  ContactArrays<Dim> contacts;
  ContactArrays<Dim> contacts_scratch;  // merge buffer of the neighbour search
  ContactAdjacency adjacency;
  std::vector<int> adjacency_cursor;  // fill buffer of RebuildAdjacency
  // How the arrays are numbered against the packing (identity for small scenes).
  // Per-particle and per-contact arrays added to this struct must also be renumbered by
  // RenumberParticles (scene_state.cpp).
  ParticleOrder order;

  // External actions accumulated by the wall and load passes, read and cleared by the
  // particle update. Empty when the scene has neither walls nor loads; the torque array is
  // empty without rotation, the moment array (sum s (x) F, DDEM stress) for rigid particles.
  std::vector<Vector<Dim>> external_force;
  std::vector<Angular<Dim>> external_torque;
  std::vector<Eigen::Matrix<double, Dim, Dim>> external_moment;
  // 1 for the particles the wall and load passes may write to (the walls' candidates and
  // the loaded particles): the particle update reads and clears the accumulators of those
  // only. Rebuilt by the particle update when `searches` has changed since
  // external_flag_search; a pass that writes elsewhere must reset external_flag_search.
  std::vector<std::uint8_t> external_flag;
  long external_flag_search = -1;

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

// The Hilbert-curve order of `centres` (ties by index): identity (empty) for fewer than
// `threshold` centres or when they already are in that order.
template <int Dim>
ParticleOrder SpatialOrder(const std::vector<Vector<Dim>>& centres,
                           int threshold = kSpatialOrderThreshold);

// Renumbers every per-particle quantity of the state: particle `old` becomes new_of_old[old]
// (a permutation). Contacts get the new indices, i < j again (normal, force and tangential
// force change sign where i and j swap) and are sorted by pair again; the adjacency, the
// walls' candidate lists, loads, prescribed dofs and candidate pairs follow.
// old_contact_of_new (may be null) receives the old index of each contact.
template <int Dim>
void RenumberParticles(SceneState<Dim>& state, const std::vector<int>& new_of_old,
                       std::vector<int>* old_contact_of_new);

// Renumbers a state built in the packing's order along SpatialOrder (state.order records
// it). Called once, at the end of the construction of a Simulation.
template <int Dim>
void ApplySpatialOrder(SceneState<Dim>& state);

// The state in the packing's order, for the accessors of a renumbered Simulation: a copy
// renumbered back, rebuilt when the state has stepped or changed (Invalidate) since. For
// the identity order it is the state itself.
template <int Dim>
class ExternalView {
 public:
  const SceneState<Dim>& Get(const SceneState<Dim>& state) const;
  // The internal index of contact c of the view (contacts() order).
  int InternalContact(const SceneState<Dim>& state, int c) const;
  // After any change of the state that is not a step.
  void Invalidate() { ++changes_; }
  // Rebuilds an existing view now (end of a run), so references handed out stay current.
  void RefreshIfHeld(const SceneState<Dim>& state) const {
    if (view_ && !state.order.identity()) Refresh(state);
  }

 private:
  void Refresh(const SceneState<Dim>& state) const;

  mutable std::unique_ptr<SceneState<Dim>> view_;
  mutable std::vector<int> internal_contact_;  // of each view contact
  mutable long step_ = -1;
  mutable long changes_seen_ = -1;
  long changes_ = 0;
};

// Rebuilds state.deformation from particles.strain (DDEM scenes) and marks it current.
template <int Dim>
void RefreshContactDeformation(SceneState<Dim>& state);

// Rebuilds the particle -> contact adjacency from state.contacts.
template <int Dim>
void RebuildAdjacency(SceneState<Dim>& state);

// Bytes held by the state's arrays (capacities): the memory footprint of a simulation.
template <int Dim>
std::size_t MemoryBytes(const SceneState<Dim>& state);

}  // namespace specimen
