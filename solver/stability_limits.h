#pragma once
// The stability limits of a bonded (DDEM) scene: the critical time step and the DDEM
// convergence bound of the actual packing, certified, and a verdict for a proposed time step
// and parameter set. The Simulation takes its time step from them
// (TimeStepOptions::from_stability_analysis, the default), which is why they live beside the
// engine; the stability analysis of the stability-limit command (stability/stability_analysis.h)
// adds the closed-form lattice limits, the sweep over nu_p, the report and the JSON.
//
//   StabilityLimitOptions options;
//   options.proposed_time_step_s = 2.9e-7;
//   StabilityLimits limits = AnalyseStabilityLimits<2>(packing, scene, options);
//   std::cout << limits.BriefReport();   // dt_cr, rho(B), verdict
//
// What is computed (LinearisedNetwork, stability_network.h, is the linear system):
// 1. Critical time step of central differences, undamped: dt_cr = 2 / omega_max (Madan (2.15)),
//    omega_max^2 = lambda_max(M^-1/2 K M^-1/2) with translations, rotations, walls and without
//    the prescribed axes, by Lanczos (stability_lanczos.h). Reported: the Ritz value (a lower
//    bound of omega_max^2), the certified upper bound (Kuczynski-Wozniakowski, failure
//    probability 1e-6), the deterministic Gershgorin bound, and the per-particle bound (the
//    solver's fallback, time_step.h). The step reported as critical uses the certified
//    upper bound, capped by Gershgorin: never on the unsafe side (up to the stated
//    probability), and sharp to the stated tolerance (0.2 % by default).
//    Damping, as the solver integrates it: a lagged dashpot force c v_(n-1/2) is, at the
//    boundary z = -1, a stiffness 2c/dt, so the damped limit is the root of
//    dt^2 lambda_max(M^-1/2 (K + (2/dt) C) M^-1/2) = 4 (secant iterations); for one degree
//    of freedom this is Labra's sqrt(1 + xi^2) - xi, but in an irregular packing a small
//    particle's modal damping ratio is up to sqrt(Z) xi, and the single factor was up to 11 %
//    unsafe in the benchmark (xi = 0.3). Local damping: 1 / sqrt(1 + alpha), exact at z = -1
//    (the damping force of an eigenmode is alpha times its elastic force).
// 2. DDEM convergence: rho(B) of the force iteration (Madan (3.8)-(3.13); docs/stability.md,
//    "DDEM convergence: rho(B)") for the packing, from lambda_max of the Ep-free operator
//    S^ = Ep S: rho(B) = lambda_max(S^) / Ep, and the admissible kn/(Ep l) (2D, l = 1 m;
//    kn/(Ep R_mean) in 3D) = kn / (l lambda_max(S^)) at rho(B) = 1, with its share
//    max_spectral_radius (default 0.95) as the recommended largest kn/(Ep l) and the smallest
//    Ep that keeps rho(B) <= max_spectral_radius (the stability analysis sets the closed-form
//    row, SC and HCP limits beside it).
// 3. DDEM critical time step: the explicit scheme uses the strains of the previous step's
//    forces (Madan (3.17)), f^n = K_c C u^n - L f^(n-1). An oscillation at the stability
//    boundary z = -1 has f^(n-1) = -f^n, so its forces are (I - L)^-1 K_c C u: the effective
//    stiffness is K_eff = C^T (I - L)^-1 K_c C, stiffer than K (L >= 0), and
//    dt_cr(DDEM) = 2 / sqrt(lambda_max(M^-1/2 K_eff M^-1/2)). For a single mode this is exactly
//    the z = -1 root of Madan's row polynomial z^3 + (b - 2 + Omega^2) z^2 + (1 - 2b) z + b
//    (Omega^2 < 4 (1 - b), docs/stability.md, "The DDEM critical time step"), whose other
//    Jury conditions are weaker for 0 <= b < 1. With kt = 0, K_eff = C^T (K_c^-1 - M)^-1 C
//    is symmetric; with tangential springs the tangential forces enter the strain but are
//    not corrected by it (Madan section 2.6), K_eff is not symmetric, and its symmetric part
//    is used: its largest eigenvalue bounds the real eigenvalues of K_eff from above (field
//    of values) and equals them to first order. Without dashpots no inner solve is needed:
//    with A = K_n^1/2 C M^-1/2 the operator of normal springs is A^T (I - S)^-1 A, whose nonzero
//    eigenvalues are those of the pencil A A^T v = lambda (I - S) v on the links, and
//    lambda_max is the fixed point of lambda_max(A A^T + lambda S) = lambda (Newton, then
//    certified). With tangential springs the symmetric part is bounded from above by an
//    operator of the same form on (normal, tangential) link vectors (PencilCriticalStep in
//    the .cpp: it drops a negative semi-definite term; 0-0.2 % lower steps than the
//    symmetric part in tests/stability/stability_extreme_test.cpp, 0.05 % on 50,000 spheres).
//    With dashpots (I - L)^-1 is applied by conjugate gradients on I - S (inner solves).
//    As rho(B) -> 1 the DDEM step falls to zero: the two limits interact (docs/stability.md,
//    "The DDEM critical time step").
//    Dashpots enter as in item 1 (their forces also enter the particle stress).
// 4. Verdict for the proposed (or the recommended) time step: unstable beyond a limit,
//    marginal within time_step_margin of dt_cr or with rho(B) above max_spectral_radius,
//    stable otherwise; the binding limit and its margin in per cent.
//
// What the linear analysis leaves out (reported as warnings, see the benchmark):
//  - DDEM with kt > 0 is not conservative: undamped runs grow slowly (flutter) at any step;
//    the verdict asks for damping (local alpha >= 0.1 held it in 2D and 3D);
//  - walls (and unbonded contacts) act only in compression: contacts that open and close are
//    impacts, and the scheme is then piecewise linear. Central differences on such a system
//    can grow at steps below the linear limit: one particle on a spring k against a wall 10 k
//    (zero preload) grows a millionfold within 4000 steps at 0.42, 0.66, 0.73, 0.81-0.82,
//    0.9-0.92, 0.98 of its closed-contact limit (undamped; with alpha = 0.1 at 0.75, 0.82-0.85,
//    0.95). In packings the top mode of a scene with stiff walls sits on one particle whose
//    wall contact opens and closes (an impact oscillator): the failure threshold is not
//    monotonic in the step and moves by 4-9 % with the press-in. Scenes with wall links are
//    therefore held to DampedUnilateralFactor(damping) x the linear limit (its comment gives
//    the benchmark's figures); no factor is a proof for impacts.

#include <functional>
#include <string>
#include <vector>

#include "generator/packing.h"
#include "solver/particles.h"
#include "solver/scene.h"
#include "solver/stability_lanczos.h"

namespace specimen {

template <int Dim>
class LinearisedNetwork;  // stability_network.h

struct StabilityLimitOptions {
  // Time step to judge [s], >= 0; 0: the scene's time_step.time_step_s if given, else the
  // recommended step.
  double proposed_time_step_s = 0.0;
  // Recommended step = safety_factor x the critical one, in (0, 1]. The critical step is
  // certified (not a per-particle estimate), hence a default above the solver's 0.7.
  double safety_factor = 0.9;
  // A time step within this fraction below dt_cr is 'marginal', in [0, 0.5).
  double time_step_margin = 0.05;
  // Scenes with wall contacts (unilateral: they open and close) are held to a factor x the
  // linear critical step (header: impacts), in [0, 1]. 0: automatic, graded by the scene's
  // damping and dimension (DampedUnilateralFactor). An explicit value in (0, 1] wins: it
  // replaces the graded factor for every scene with wall links where the graded factor is
  // below 1 (damping below 0.1 in 2D, 0.3 in 3D); above that no factor is applied.
  double unilateral_contact_factor = 0.0;
  // rho(B) above this is 'marginal' (and sets the recommended kn/(Ep l)), in (0, 1].
  double max_spectral_radius = 0.95;
  // Lanczos certificate of the undamped DEM step and of rho(B) (stability_lanczos.h).
  LanczosOptions lanczos;
  // Relative tolerance of the certificate of the DDEM step (each iteration needs an inner
  // solve), in (0, 0.5).
  double ddem_relative_tolerance = 0.03;
  // Inner solves (I - S) w = r of the DDEM step: relative residual, iteration cap. The
  // certified bound allows for the inexact products (10 tau / (1 - rho(B)) relative).
  double inner_tolerance = 1e-5;
  int inner_max_iterations = 20000;
  // The DDEM step without dashpots is found without inner solves (the pencil, header item
  // 3); true: by the inner solves anyway (for comparison and tests).
  bool ddem_inner_solves = false;
  // Particles whose gap to a wall is below this are linked to it [m]; < 0: those within
  // contacts.bond_gap_tolerance x R (touching). The Simulation passes its search skin (the
  // particles a wall may touch, as its per-particle bound counts them).
  double wall_reach_m = -1.0;
  // The mode shape of omega_max (its most moving particle). Costs one more Lanczos pass when
  // the basis is not stored.
  bool locate_mode = true;
  ProgressCallback progress;  // may be empty

  // Names the first invalid field, its value and the allowed range.
  bool IsValid(std::string* error) const;
};

// One Lanczos solve as reported.
struct EigenvalueReport {
  double ritz_value = 0.0;             // lower bound
  double certified_upper_bound = 0.0;  // upper bound (probability 1 - delta)
  double relative_tolerance = 0.0;     // eps
  double residual_norm = 0.0;
  int iterations = 0;
  int dimension = 0;
  bool reorthogonalised = false;
  bool exact = false;
  double seconds = 0.0;
  int inner_iterations = 0;  // DDEM step: total conjugate-gradient iterations
};

struct StabilityLimits {
  // --- Scene ---
  int dimension = 0;
  int particles = 0;
  int links = 0;  // contact + wall + rattler links
  int contact_links = 0, wall_links = 0, rattler_links = 0, rattlers_without_neighbour = 0;
  int degrees_of_freedom = 0, fixed_degrees_of_freedom = 0;
  bool rotation = false;
  double normal_stiffness_n_per_m = 0.0, tangential_stiffness_n_per_m = 0.0;
  // Bond radius ratio lambda: > 0 when bonds carry moments, whose rotational springs the
  // network includes (bond_moment.h).
  double bond_radius_ratio = 0.0;
  double bond_range = 1.0;  // gamma: contact links include the pairs within it (bond_range.h)
  bool deformable = false;
  double particle_youngs_modulus_pa = 0.0;  // 0: rigid
  double particle_poisson_ratio = 0.0;
  std::string particle_model;  // "rigid", "plane strain", "plane stress", "3D isotropic"
  // The length of the Ep-free group kn/(Ep L): l = 1 m in 2D, the volume mean radius in 3D.
  double group_length_m = 1.0;

  // --- Critical time step ---
  // Damping: the factors by which dashpots (the boundary with 2c/dt, against the undamped
  // certified step of the DEM network) and local damping 1/sqrt(1 + alpha) lower the step.
  double dashpot_factor = 1.0, local_damping_factor = 1.0;
  int dashpot_fixed_point_iterations = 0;
  double per_particle_bound_s = 0.0;           // Madan (2.18), the solver's fallback (time_step.h)
  // Inertia scaling of the material (MaterialParameters::mass_scaling_budget): every step
  // above is that of the scaled masses.
  MassScalingSummary mass_scaling;
  double guaranteed_bound_s = 0.0;             // per-particle / sqrt(2)
  double gershgorin_bound_s = 0.0;             // 2/sqrt(Gershgorin), undamped: deterministic, safe
  double omega_max_ritz_rad_per_s = 0.0;       // sqrt(theta)
  double omega_max_certified_rad_per_s = 0.0;  // sqrt(certified upper bound)
  double dem_time_step_ritz_s = 0.0;      // 2/omega_ritz x damping: the sharp estimate (>= true)
  double dem_critical_time_step_s = 0.0;  // 2/omega_certified x damping (<= true)
  EigenvalueReport dem_eigenvalue;
  // The particle moving most in the omega_max mode, its share of the mode's kinetic energy.
  int mode_particle = -1;
  double mode_particle_share = 0.0;
  double mode_particle_radius_m = 0.0;
  double mode_rotational_share = 0.0;  // share of the mode in rotations
  // DDEM step (deformable and rho(B) < 1): certified, with the reduction against DEM.
  double ddem_critical_time_step_s = 0.0;
  double ddem_time_step_ritz_s = 0.0;
  double ddem_reduction_percent = 0.0;  // 100 (1 - ddem / dem)
  EigenvalueReport ddem_eigenvalue;
  bool ddem_time_step_available = false;
  bool ddem_time_step_inner_solves = false;  // false: the pencil (kt = 0, no dashpots)
  // DDEM with tangential springs: the tangential forces enter the particle stress but the
  // strain does not move the contact points tangentially (Madan assumption 5), so the model
  // is not conservative and undamped runs grow slowly (flutter) at any time step.
  bool flutter_possible = false;
  std::string flutter_message;
  // The critical step the scene is held to (DDEM if deformable; times unilateral_factor) and
  // the recommendation.
  double linear_critical_time_step_s = 0.0;  // before the unilateral contact factor
  bool unilateral_contacts = false;          // wall links (they act in compression only)
  double unilateral_factor = 1.0;            // applied (weakly damped scenes with walls)
  double critical_time_step_s = 0.0;
  double safety_factor = 0.0;
  double recommended_time_step_s = 0.0;
  std::string critical_time_step_method;

  // --- DDEM convergence ---
  double unit_spectral_radius_pa = 0.0;  // lambda_max(S^) certified: rho(B) = this / Ep
  EigenvalueReport convergence_eigenvalue;
  double spectral_radius = 0.0;             // rho(B) certified upper bound (deformable)
  double spectral_radius_ritz = 0.0;        // its Ritz value (lower bound)
  double max_spectral_radius = 0.0;         // required bound
  double admissible_kn_over_ep = 0.0;       // rho(B) = 1
  double recommended_kn_over_ep = 0.0;      // rho(B) = max_spectral_radius
  double smallest_youngs_modulus_pa = 0.0;  // Ep giving rho(B) = max_spectral_radius
  double kn_over_ep = 0.0;  // of the scene (deformable)

  // --- Verdict ---
  double judged_time_step_s = 0.0;
  bool judged_time_step_proposed = false;  // false: the recommended step
  std::string verdict;                     // "stable", "marginal", "unstable"
  std::string binding_limit;               // the limit with the smallest margin
  double margin_percent = 0.0;
  std::string verdict_message;
  double time_step_margin_percent = 0.0;
  double spectral_radius_margin_percent = 0.0;  // 100 (1 - rho(B)), deformable only

  // What the linear analysis does not cover in this scene (each one sentence).
  std::vector<std::string> warnings;
  double seconds = 0.0;

  // One line: dt_cr, the recommended step, rho(B) and the admissible kn/(Ep l), the verdict.
  std::string BriefReport() const;
};

// Factor on the linear critical step for scenes with wall links (header: impacts), from the
// damping (the largest of local alpha and the dashpot ratios) and the dimension:
//   2D: 0.85 below 0.05, 0.94 below 0.1, else 1;
//   3D: 0.85 below 0.05, 0.92 below 0.1, 0.96 below 0.3, else 1.
// Measured (tools/bench/stability_bench.md, worst of three press-ins, chatter counted as
// failure): 2D first failures at 0.89, 0.99 and none up to 1.02 of the linear limit for alpha
// 0, 0.05, 0.1 (the earlier uniform 0.9 was unsafe undamped); 3D at 0.94, 0.93 and 0.97. The
// virtual laboratory's damping (0.7) gets no factor. A benchmark figure, not a proof.
double DampedUnilateralFactor(double damping, int dimension);

// The limits of a scene on a packing. Throws InputError for invalid options, scenes or
// packings (naming the field and its range); ComputationError if an inner solve fails.
// `more`, when given, is called last with the linearised network and the options in force
// (their thread count set from the scene), before the time is taken: the stability analysis
// computes its sweep there, on the same network.
template <int Dim>
StabilityLimits AnalyseStabilityLimits(
    const Packing<Dim>& packing, const SceneOptions<Dim>& scene,
    const StabilityLimitOptions& options,
    const std::function<void(const LinearisedNetwork<Dim>&, const StabilityLimitOptions&)>& more =
        nullptr);

// lambda_max(S^) of the network's DDEM operator for `compliance` (Ep = 1: rho(B) x Ep), by the
// certified Lanczos iteration of `options`, labelled `label` in the progress display.
template <int Dim>
LanczosResult LargestDdemEigenvalue(const LinearisedNetwork<Dim>& network,
                                    const ParticleCompliance<Dim>& compliance,
                                    const StabilityLimitOptions& options, const std::string& label);

}  // namespace specimen
