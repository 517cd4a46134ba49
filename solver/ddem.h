#pragma once
// DDEM (Madan 2019, sections 2.2-2.7 and 3.1-3.4): deformable particles in the global mode.
//
// In the time step (explicit variant, Madan (3.17)) the DDEM work is split over two passes:
// the particle update forms each particle's stress from the step's contact forces plus the
// external surface forces acting on it (point loads at their surface point, wall
// reactions at the contact point), symmetrised, and its strain eps = D sigma; the next
// step's contact pass corrects every overlap by the strain of both particles,
// h_c = h + Ri n.eps_i.n + Rj n.eps_j.n (2.53). Rigid scenes run neither.
//
// This file adds what is not part of the time step:
//  - the implicit fixed-point iteration of the contact forces at fixed positions,
//    F^(k+1) = F(X, E(F^(k))), F^(0) = the stored forces (Madan (3.5)-(3.7)); its
//    convergence rate is the spectral radius rho(B) of the iteration matrix (3.10)-(3.14),
//    e.g. -2 kn / kp on a row of discs (3.25);
//  - the particle elastic energy 1/2 V sigma : eps (2.61).

#include <string>
#include <vector>

#include "solver/vector_algebra.h"

namespace specimen {

template <int Dim>
struct SceneState;

struct ForceIterationOptions {
  // Iteration budget, > 0.
  int max_iterations = 1000;
  // Converged when max |F^(k) - F^(k-1)| <= tolerance x max |F^(k)| (Madan (3.7)), in (0, 1).
  double tolerance = 1e-12;
  // Diverged when the change grows beyond this factor times the first iteration's, > 1.
  double divergence_factor = 1e6;
  // A contact whose normal force is recorded at every iteration (-1: none).
  int watched_contact = -1;

  bool IsValid(std::string* error) const;
};

struct ForceIterationSummary {
  bool converged = false;
  bool diverged = false;
  int iterations = 0;
  double max_force_n = 0.0;    // max |fn| after the last iteration
  double last_change_n = 0.0;  // max |dF| of the last iteration
  // max |dF^(k)| / max |dF^(k-1)| of the last iteration: the observed contraction rate.
  double change_ratio = 0.0;
  // Normal elastic force of the watched contact: [0] before the first iteration, then one
  // value per iteration.
  std::vector<double> watched_normal_force_n;
  std::string termination;
};

// The implicit iteration on the state's current positions (no motion). Bonded contacts
// follow fn = kn g_c in tension and compression, unbonded ones min(0, kn g_c); tangential
// forces are kept (Madan section 2.6: unaffected by the deformation); point loads at the
// current time and the wall forces of the last step enter the particle stress unchanged. Leaves the
// converged (or last) forces and strains in the state. Throws InputError for rigid
// particles or invalid options.
template <int Dim>
ForceIterationSummary IterateDeformedContactForces(SceneState<Dim>& state,
                                                   const ForceIterationOptions& options);

// sum_p 1/2 V_p sigma_p : eps_p over the particles, with sigma_p = D^-1 eps_p (Madan (2.61)).
// Zero for rigid particles.
template <int Dim>
double ParticleElasticEnergy(const SceneState<Dim>& state);

}  // namespace specimen
