#pragma once
// The particle update: one loop over the particles that
//  1. sums the contact forces and moments of the step, and the couples of bonds that carry
//     one (bond_moment.h) (gathered through the particle -> contact adjacency, so the loop is
//     race-free and its sums deterministic) and the external actions of walls and point
//     loads (Madan (2.5)-(2.6));
//  2. DDEM: forms the particle stress from those forces, symmetrised (Madan (2.41),
//     (2.44)-(2.45)), and the strain eps = D sigma (2.46)-(2.49) that the next step's
//     contact pass reads (the explicit variant of Madan (3.17));
//  3. applies non-viscous local damping (Madan (2.7)-(2.8)) and prescribed degrees of
//     freedom;
//  4. advances velocities and positions by central differences (Madan (2.9)-(2.13)):
//     v_{n+1/2} = v_{n-1/2} + a_n dt, x_{n+1} = x_n + v_{n+1/2} dt; 2D angles likewise.
// Instantiated per combination of stages and chosen once (SelectParticlePass).

#include "solver/vector_algebra.h"

namespace specimen {

template <int Dim>
struct SceneState;
struct StepPlan;

struct ParticlePassTotals {
  // Kinetic energy at t_n in the central-difference form 1/2 m v_{n-1/2} . v_{n+1/2}, which
  // closes the discrete energy balance exactly for linear springs (energy audit). It keeps
  // pace with the work terms, so the divergence check compares it with the energy supplied.
  double kinetic_energy_j = 0.0;
  double damping_dissipation_j = 0.0;   // local damping, F_d . (v_- + v_+)/2 dt
  double constraint_work_j = 0.0;       // work of the prescribed-velocity reactions
  double constraint_supplied_j = 0.0;   // sum of |constraint work| per particle
  double max_speed = 0.0;               // largest |v_{n+1/2}| [m/s]
  double max_unbalanced_force_n = 0.0;  // largest |sum of forces| on free axes
  double max_strain = 0.0;              // largest Frobenius norm of a particle strain
  bool finite = true;
};

template <int Dim>
using ParticlePassFunction = void (*)(SceneState<Dim>& state, ParticlePassTotals* totals);

template <int Dim>
ParticlePassFunction<Dim> SelectParticlePass(const StepPlan& plan);

// The particle stress sigma_p = sym(sum s (x) f) / V_p of Madan (2.41), (2.44), from the
// contact forces stored in state.contacts plus `moment` (external surface terms). Used by
// the DDEM force iteration; the time step computes it inside the particle pass.
template <int Dim>
SymmetricTensor<Dim> ParticleStressFromContacts(const SceneState<Dim>& state, int particle,
                                                const Eigen::Matrix<double, Dim, Dim>& moment);

}  // namespace specimen
