#pragma once
// Particle state as a structure of arrays: one flat array per quantity, indexed like the
// packing. Masses and inertias follow Madan (2.3)-(2.4): 2D discs of thickness l = 1 m,
// m = rho pi R^2 l, J = m R^2 / 2; 3D spheres, m = 4/3 rho pi R^3, J = 2/5 m R^2.
//
// Time levels (central differences, Madan (2.9)-(2.13)): between steps, positions are at
// t_n and velocities at t_{n-1/2}; a step computes forces at t_n and advances the
// velocities to t_{n+1/2} and the positions to t_{n+1}.

#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "generator/packing.h"
#include "solver/material.h"
#include "solver/vector_algebra.h"

namespace specimen {

// What MaterialParameters::mass_scaling_budget did (BuildParticles). The per-particle
// bound 2 sqrt(m_i / k_eff,i) (Madan (2.18); k_eff,i from the packing's contact list, as
// time_step.h) is raised to a common floor for every particle below it, m_i -> m_i
// (floor / bound_i)^2 (J_i by the same factor), with the floor the highest one whose added
// mass stays within the budget. The true volumes are kept (DDEM stresses use them).
struct MassScalingSummary {
  double budget = 0.0;            // the share of the total mass allowed
  int scaled_particles = 0;       // particles whose inertia was raised
  double added_mass_share = 0.0;  // added mass / true total mass
  double largest_factor = 1.0;    // the largest m_i' / m_i
  // The smallest per-particle bound after / before: the gain in the per-particle time step.
  double bound_gain = 1.0;
};

// "312 particles, mass +1 % (budget 1 %), per-particle bound x2.01"; empty when nothing
// was scaled. And the summary as JSON (budget, scaled_particles, added_mass_share,
// largest_factor, bound_gain).
std::string MassScalingLine(const MassScalingSummary& summary);
nlohmann::json MassScalingJson(const MassScalingSummary& summary);

template <int Dim>
struct ParticleArrays {
  std::vector<Vector<Dim>> position;           // centre [m]
  std::vector<Vector<Dim>> velocity;           // [m/s], at the half step
  std::vector<Angular<Dim>> angular_velocity;  // [rad/s], at the half step
  // 2D: accumulated rotation angle [rad]. 3D: empty; rotations are incremental and the
  // orientation is not tracked (Labra section 2.5: the contact law does not need it).
  std::vector<double> rotation_angle;
  std::vector<double> radius;           // [m]
  std::vector<double> mass;             // [kg]
  std::vector<double> inverse_mass;     // [1/kg]
  std::vector<double> inverse_inertia;  // [1/(kg m^2)]
  MassScalingSummary mass_scaling;      // identity unless the material asks for it
  // DDEM particle strain (Madan (2.46)), from the forces of the last evaluated step; the
  // next step's contact pass reads it. Empty for rigid particles.
  std::vector<SymmetricTensor<Dim>> strain;

  int size() const { return static_cast<int>(radius.size()); }
};

// Particles at rest at the packing's centres, with the material's mass scaling applied (so
// the Simulation and the stability analysis see the same inertia). Throws InputError naming
// the first particle with a radius that is not finite and > 0, or a centre that is not finite.
template <int Dim>
ParticleArrays<Dim> BuildParticles(const Packing<Dim>& packing, const MaterialParameters& material,
                                   bool deformable);

}  // namespace specimen
