#pragma once
// The critical time step of the explicit central-difference scheme (Madan (2.14)-(2.18),
// Labra (2.51)-(2.58)).
//
// Bound used: the per-particle (local subsystem) estimate of Madan (2.16)-(2.18),
//     dt_cr = f_d min_i 2 sqrt(m_i / k_eff,i),
//     k_eff,i = sum over the contacts of i of [kn + kt (1 + m_i R_i^2 / J_i)]
//             + sum over the walls i may touch of [k_wall + kt_wall (1 + m_i R_i^2 / J_i)]
//             + sum over the moment-carrying bonds of i of kb m_i / J_i (bond_moment.h),
// the largest eigenvalue of particle i's own stiffness (translation and rotation; a
// tangential spring acts on the contact-point velocity u + R theta, whose "mass" is
// 1/(1/m + R^2/J)) with its neighbours held. m R^2 / J = 2 for discs and 5/2 for spheres.
// A particle without contacts counts one contact (it can touch something). f_d is the product
// of two damping factors:
//  - contact dashpots: sqrt(1 + xi^2) - xi with xi the largest dashpot ratio (Labra (2.53);
//    the same factor holds for the lagged dashpot force c v_{n-1/2} used here);
//  - local damping: 1/sqrt(1 + alpha), alpha = max(alpha_t, alpha_r). In the highest
//    (alternating) mode v_{n-1/2} has the sign of x_n, so Madan's F_d = -alpha |F| v/|v| is
//    -alpha k x_n: the damping adds alpha k to the stiffness of that mode.
//
// What it is worth:
//  - exact for the SC (square) lattice (k_eff = 4 kn: dt_cr = sqrt(m/kn), Madan (3.46)) and
//    for the infinite triangular lattice with central springs (k_eff = 6 kn: 2 sqrt(m/6kn)
//    = the M-point limit omega_max^2 = 6 kn/m, docs/sources.md, section 3, O6);
//  - a rigorous lower bound of the true limit is dt_cr / sqrt(2): with
//    u.K.u = sum_c k_c (b_c.u)^2 <= sum_c 2 k_c (|u_i|^2_c + |u_j|^2_c) (per contact, with the
//    mass-weighted norms above), omega_max^2 <= max_i 2 k_eff,i / m_i (Gershgorin-type);
//  - not a bound for irregular packings: Madan's 4979-disc specimen was stable up to about
//    0.93 of sqrt(m_min / k_max) (Madan (4.30)); DDEM lowered that limit by 1.4 % (Madan
//    section 4.5, Figs. 4.11-4.12) and lowers those of the SC and HCP specimens by 0.15-0.46 %
//    (docs/stability.md, "The DDEM critical time step").
// Hence the default safety factor 0.7 (< 1/sqrt(2)): provably stable for linear undamped
// contacts between rigid particles.
//
// DDEM (deformable particles): the critical time step checked against stays the DEM bound
// above (Madan section 3.5: "the critical time step remains the same for standard and
// deformable DEM", true of the lattices' highest modes, whose alternating contact forces
// cancel in the particle stress). But the explicit strain lag (Madan (3.17)) does lower the
// limit of modes whose forces do not cancel. Two discs, one contact: f_n = -kn h_n - beta
// f_{n-1} with beta = kn sum_p R_p^2 (n.D_p.n) / V_p, and the alternating mode z = -1 needs
// Omega^2 < 4 (1 - beta): dt_cr shrinks by sqrt(1 - beta) (5 % for Madan's two-particle check).
// The default time step is therefore multiplied by the lag factor sqrt(1 - min(beta_est, 0.9)),
// beta_est = max over contacts of kn lambda_max(D) sum_p R_p^2 / V_p (walls: k_wall, one
// particle), an upper estimate of beta (lambda_max(D) >= n.D.n).
//
// The sharp estimate (Lanczos on the assembled system, with the DDEM iteration matrix) is
// the stability limits (stability_limits.h), which the Simulation uses by default
// (TimeStepOptions::from_stability_analysis); this bound is its fallback when that is off,
// and the analysis reports it for comparison. A value can also be passed in as
// TimeStepOptions::critical_time_step_s. Note: the dashpot factor
// above is exact for one degree of freedom only; in an irregular packing a small particle's
// modal damping ratio reaches sqrt(Z) xi, and the stability analysis measured the factor
// 11 % optimistic at xi = 0.3 (tools/bench/stability_bench.py).

#include <array>
#include <string>
#include <vector>

#include "solver/material.h"
#include "solver/particles.h"

namespace specimen {

struct CriticalTimeStepEstimate {
  // The limit a time step is checked against [s].
  double critical_time_step_s = 0.0;
  // Madan (2.18) per-particle bound, times the damping factors [s].
  double per_particle_bound_s = 0.0;
  // per_particle_bound_s / sqrt(2): below it the scheme is provably stable [s].
  double guaranteed_bound_s = 0.0;
  double dashpot_factor = 1.0;        // sqrt(1 + xi^2) - xi
  double local_damping_factor = 1.0;  // 1 / sqrt(1 + alpha)
  // DDEM: beta_est (above) and the lag factor sqrt(1 - min(beta_est, 0.9)) applied to the
  // default time step. 0 and 1 for rigid particles.
  double ddem_ratio_estimate = 0.0;
  double ddem_lag_factor = 1.0;
  int limiting_particle = -1;               // the particle giving the per-particle bound
  double limiting_stiffness_n_per_m = 0.0;  // its k_eff
  std::string method;                       // how critical_time_step_s was obtained
};

// The per-particle bound above. `wall_stiffness` (may be empty) holds, per particle, the sum of
// k_wall + kt_wall (1 + m R^2 / J) of the walls it may touch.
template <int Dim>
CriticalTimeStepEstimate PerParticleCriticalTimeStep(
    const ParticleArrays<Dim>& particles, const std::vector<std::array<int, 2>>& contacts,
    const MaterialParameters& material, const std::vector<double>& wall_stiffness);

// Sets estimate->ddem_ratio_estimate and ddem_lag_factor (above). `wall_stiffness` (may be
// empty) holds, per particle, the sum of the normal stiffnesses of the walls it may touch.
template <int Dim>
void EstimateDdemLagFactor(const ParticleArrays<Dim>& particles,
                           const std::vector<std::array<int, 2>>& contacts, double normal_stiffness,
                           const ParticleCompliance<Dim>& compliance,
                           const std::vector<double>& wall_stiffness,
                           CriticalTimeStepEstimate* estimate);

}  // namespace specimen
