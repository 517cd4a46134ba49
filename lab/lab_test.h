#pragma once
// The virtual laboratory: uniaxial compression (UCS), Brazilian (BTS), confined biaxial,
// isotropic compression and pure shear tests on a bonded specimen, with the homogenised
// stress and strain, the elastic constants, strengths, broken bonds and energy balance.
// Options in (LabTestOptions), LabTestResult out (BriefReport, FullReport, ToJson). This is
// what the `run-test` command runs and what the calibrator calls, thousands of times.
//
//   LabTestOptions options;                       // UCS at the default (quasi-static) rate
//   LabTestResult result = RunLabTest<2>(packing, material, options);
//   std::cout << result.FullReport();             // E, nu (in-plane and plane strain), UCS
//
// The tests (Labra 2012 sections 4.2.2 and 4.3; Madan 2019 section 4.5):
//  - kUniaxialCompression: a rectangle (2D), cylinder or box (3D) between two rigid,
//    frictionless platens (walls placed at the extreme particles, stiffness kn), each moving
//    towards the other at the speed V; through the peak until the axial stress has fallen to
//    post_peak_stress_fraction of it.
//  - kBrazilian: a disc (2D) or cylinder (3D, axis z) between flat platens normal to y;
//    sigma_t = 2 F / (pi D t) with F the peak platen force, t = 1 m in 2D (Labra (4.38));
//    or between jaws with a loading arc (loading_arc_deg): sigma_t = k 2 F / (pi D t).
//  - kConfinedCompression (biaxial (a)): a rectangle (box) whose lateral walls are
//    servo-controlled (WallServo) to confining_stress_pa: first every wall holds it
//    (consolidation), then the platens move at V; peak axial stress = strength at that
//    confinement. RunConfinedEnvelope (lab_envelope.h) runs several and fits Mohr-Coulomb.
//  - kIsotropicCompression (biaxial (b)): four (six) walls moving inwards at the same strain
//    rate; K = d sigma_mean / d eps_vol (Madan (4.33)-(4.35): 2D sigma_h = (sxx + syy)/2,
//    eps_vol = exx + eyy; 3D sigma_m = tr sigma / 3).
//  - kPureShear (biaxial (c)): Madan's kinematic boundary conditions (section 4.5): the
//    boundary particles move on the simple-shear field v_x = gamma_dot (y - y_bottom)
//    (bottom fixed, top at v, sides linear in height), zero vertical (and, in 3D, y)
//    velocity, rotations free; G = d sigma_xy / (2 d eps_xy) (4.36). In 3D the shear is x-z.
//
// Measurement (lab/lab_measurement.h): stress by the branch-vector average with the
// wall contacts (homogenisation.h SpecimenStress) over V = the current wall-to-wall volume
// (platen gap x the specimen's lateral extent from its domain; confined and isotropic
// tests: the product of the wall gaps; pure shear: the triangulated region of the centres,
// where its boundary forces act); strain by Bagi's method (homogenisation_strain.h) and
// from the platen displacement; secant E, nu over [modulus_window_low,
// modulus_window_high] x peak (Labra: 1-50 %), in 2D both the in-plane E', nu' and the
// plane-strain E = E'(1 - nu^2), nu = nu'/(1 + nu') (docs/lab.md, "Measurement"; Labra's
// (4.33) is wrong, docs/sources.md, "Errata").
//
// What E and nu mean (measured; tests/lab/lab_oracles_test.cpp):
//  - Strain region. The outer particle layers of a generated specimen are more compliant
//    than its interior (fewer contacts at the domain's sides; the platen-side layer carries
//    the platen load through few contacts). Over the whole convex hull of the centres E' of
//    a 1,544-disc specimen is 7-15 % below its interior value and nu' 0.02-0.05 above it;
//    5,000 discs: 2 % and 0.005. The interior (default margin 4 mean radii) is free of that
//    size effect and matches the uniform-strain (Voigt) estimate with the interior contact
//    density within 1.3 % for E' and +0.002..+0.022 for nu' (kt/kn 1.25..0), the regular
//    hexagonal lattice's closed forms within 0.3 %, and K, G of the isotropic and pure shear
//    tests within 1.5 % (Madan section 4.5; check A14 of docs/sources.md).
//  - Damage in the window. With Labra's parameters (kt/kn = 0.2, Rt/Rn = 10) bonds start to
//    break in tension, across the loading axis, at 40-45 % of the peak: 800 of 14,800 bonds
//    are broken at 50 % of it (5,000 discs), and the 1-50 % secant nu' is 0.40-0.58 (plane
//    strain 0.28-0.37) while the elastic range (1-30 %, no bond broken) gives nu' = 0.254,
//    plane strain 0.203 = the Voigt value 0.250 / 0.200 within 2 %, and E' = 19.4 GPa
//    (plane strain 18.6 GPa). The excess Poisson ratio is damage, not measurement: choose a
//    window below the damage onset (ElasticConstantsMeasured::broken_bonds_in_window says
//    whether the window holds any) when the elastic constants are wanted. Labra's own
//    specimen started to lose stiffness at 65 of 126 MPa (51 %), just above his window.
//
// Loading rate (Labra (4.20)): the group V / sqrt(kn / rho) in 2D (kn per unit thickness),
// V / sqrt(kn / (rho r_mean)) in 3D, V the speed of each platen; sqrt(kn / rho) is the
// scale of the wave speed, so the group is the axial strain added per wave transit of the
// specimen over two. Below the damage onset the response is quasi-static at the default
// 5e-5 (E within 0.1 % of its value at half the rate). A bonded specimen then fails
// progressively, and at constant speed its damage lags the load (each cascade redistributes
// over several transits): the peak keeps rising with the rate. The quasi-static guard
// (pause_* options) therefore holds the platens from the first broken bond of a cascade
// until it has run out, so damage grows at fixed displacement and the curve is the same at
// any rate (5,000 discs, Labra's parameters: stresses at equal strain within 0.5 % at
// 5e-5 and 2.5e-5 up to 95 % of the peak; E' within 0.1 %). The peak itself is the onset of
// the final runaway cascade on a still-rising curve and is path dependent: runs at the same
// rate differing only in sample_interval (so in where the holds fall) give peaks 0.3-1.2 %
// apart (6 runs: 58.4-59.5 MPa, std 0.8 %), so a 1 % check_quasi_static on a 5,000-disc
// specimen can fail on noise alone; the default passed it (0.95 %). The holds cost about
// 85 % of the steps (a 5,000-disc UCS: 250,000 steps instead of 70,000 at constant speed;
// 10,000 discs: 400 s of CPU against about 70 s without pause_on_breakage, which then
// changes the peak by ~7 % per halving of the rate).
//
// Labra's 2D verification (data/scenes/labra_verification_2d.toml: his parameters on 30,382
// discs, porosity 9.25 %, nc 5.82, r_mean 0.154 mm): E 17.19 GPa, nu 0.204 (1-50 %; elastic
// range 17.26 GPa, 0.201), UCS 83.0 MPa, against his 18.63 GPa, 0.2009, 126.4 MPa. E' is
// 7 % below this packing's Voigt estimate (1 % for the 5,000- and 10,000-disc packings of
// the same generator: the 30,000-disc one has more 3- and 4-contact particles), and the
// strength does not scale with Rn / r_mean across resolutions: sigma_c r_mean^(1/2) / Rn is
// closer to constant (5,064 discs 59 MPa at Rn 4962 N; 10,044 discs 104 MPa at Rn 8656 N).
//
// Damping belongs to the protocol, not the material: local non-viscous damping
// alpha_t = alpha_r = local_damping (0.7, PFC's default: Labra 2012, section 2.4, gives no
// value) and contact dashpots at dashpot_ratio of critical replace the material's damping
// fields. The dashpot ratio is small (0.1): at quasi-static rates the viscous forces are
// below 1e-4 of the elastic ones, and each 0.1 costs about 10 % of the time step (Labra
// (2.53)).
//
// Inertia scaling (mass_scaling_budget, default 0.01; particles.h MassScalingSummary): the
// time step is set by the lightest, stiffest particles, a few small ones of a polydisperse
// packing. Their inertia is raised to a common per-particle bound, adding at most 1 % to the
// total mass (PFC's density scaling, restricted to the particles that limit the step); the
// critical step is then the certified analysis of the scaled masses. Quasi-static results do
// not depend on inertia. Measured (Labra's 2D parameters, rate group 5e-5; bench-out/lab):
//  - elastic UCS, 1,544 discs, no breakage: E' -0.06 %, nu' -0.0001 at a 2 % budget
//    (tests/lab/lab_oracles_test.cpp);
//  - UCS, 5,064 discs: critical step x1.30, steps 237,800 -> 197,200; peak 138.4 -> 135.8 MPa.
//    The half-rate check passed with scaling (peak within 0.15 %) and failed without it: the
//    unscaled peak was 138.4 MPa at 5e-5 and 135.9 MPa at 2.5e-5, the scaled value;
//  - UCS, 10,044 discs: critical step x1.51, steps 422,400 -> 285,800; E 18.45 -> 18.47 GPa,
//    nu 0.209 -> 0.209, peak 104.1 -> 102.8 MPa;
//  - Brazilian, 4,928 discs: critical step x1.53, steps 50,000 -> 34,800, sigma_t 8.21 ->
//    8.18 MPa;
//  - 3D UCS, 5,000 spheres (data/scenes/example_ucs_3d.toml): critical step x2.29, steps
//    115,800 -> 56,400; peak 31.42 / 31.12 MPa unscaled at 5e-5 / 2.5e-5, 31.05 / 31.40 MPa
//    scaled; E 6.98 / 6.97 against 6.95 / 6.95 GPa.
// The peaks move within the path dependence of the final cascade (header comment, "Loading
// rate"). 0 gives every particle its true mass.
//
// Errors: InputError before any work for invalid options, a packing whose domain is not
// the test's shape (a Brazilian test on a rectangle) or that does not fill its domain
// (particles missing along a side, porosity above 0.6); ComputationError when the
// simulation diverges or the confining servo cannot reach its stress. A strength test
// that reaches strain_limit without a peak is not an error: the result says so
// (peak_reached = false, termination kStrainLimit) and the caller decides.

#include <Eigen/Core>
#include <array>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "common/progress.h"
#include "generator/packing.h"
#include "solver/contact_law.h"
#include "solver/energy.h"
#include "solver/material.h"
#include "solver/particles.h"

namespace specimen {

enum class LabTestKind {
  kUniaxialCompression,   // "ucs"
  kBrazilian,             // "brazilian"
  kConfinedCompression,   // "biaxial"
  kIsotropicCompression,  // "isotropic"
  kPureShear,             // "shear"
};

// "ucs", "brazilian", "biaxial", "isotropic", "shear".
const char* LabTestKindName(LabTestKind kind);
// Parses the names above; false for anything else.
bool ParseLabTestKind(const std::string& name, LabTestKind* kind);
// Strength tests run through a peak; the modulus tests (isotropic, shear) to strain_limit.
bool IsStrengthTest(LabTestKind kind);

// The message of a test refused by its step budget (LabTestOptions::max_steps) before the first
// step, for the bonded and the lattice tests; `hint` says what else to check.
std::string StepBudgetRefusal(double steps_needed, double strain_limit, double speed_m_per_s, double time_step_s,
                              long max_steps, const std::string& hint);

struct LabTestOptions {
  LabTestKind kind = LabTestKind::kUniaxialCompression;

  // --- Loading rate ---
  // Loading-rate group (header comment), > 0 and <= 0.01. Used when platen_speed_m_per_s = 0.
  double loading_rate_group = 5e-5;
  // The speed V of each platen [m/s]; > 0 overrides the group, 0 = from the group. Isotropic
  // test: the walls along the loading axis move at V, the others at the same strain rate;
  // pure shear: the top boundary moves at 2 V relative to the bottom (same strain rate as
  // a UCS of that height).
  double platen_speed_m_per_s = 0.0;
  // The drive accelerates linearly to V over this many wave transits H / sqrt(kn/rho) (3D:
  // sqrt(kn/(rho r_mean))) of the specimen, >= 0: no shock wave at the start.
  double velocity_ramp_transits = 4.0;
  // Quasi-static guard of the strength tests (UCS, BTS, biaxial; header comment "Loading
  // rate"), after the initial ramp. The platens stop (decelerating over pause_ramp_transits)
  // as soon as a bond breaks (looked for every quarter sample interval; the state there is
  // recorded as a sample) or the kinetic energy of the particles exceeds
  // pause_kinetic_energy_ratio x that of the affine compression at V, 1/2 M V^2 / 3; they
  // resume once a whole sample interval passes without a broken bond and with the kinetic
  // energy below the affine one, or after max_pause_transits wave transits (a fragment
  // flying off keeps its energy). The pauses together may take at most four times the time
  // the platens need to reach the strain limit at V; then the platens move on at V (the
  // termination message says so): a test never stalls. pause_kinetic_energy_ratio >= 0;
  // 0 = no guard (constant speed).
  double pause_kinetic_energy_ratio = 3.0;
  double max_pause_transits = 20.0;  // > 0
  // Hold on fresh breakage (else on the kinetic energy alone, the behaviour before the quasi-static
  // holds: about 3 % peak changes per halving of the rate).
  bool pause_on_breakage = true;
  // The platens decelerate and accelerate over this many wave transits (at least one sample
  // interval), >= 0: a sudden stop or start of the platens sends a stress wave of ~rho c V.
  double pause_ramp_transits = 0.25;

  // --- When to stop ---
  // A strength test stops once the control stress (axial stress, BTS platen force, biaxial
  // deviator) has fallen to this fraction of its peak, in (0, 1).
  double post_peak_stress_fraction = 0.5;
  // Strain at which the test stops [-], > 0 and < 0.5; 0: automatic, 0.02 for strength tests
  // (then reported as "no peak"), 0.001 for the isotropic and shear tests. Axial platen
  // strain (UCS, biaxial, isotropic), platen displacement / D (BTS), eps_xy imposed (shear).
  double strain_limit = 0.0;
  // Step budget of one test, >= 1: a test that would need more steps to reach its strain
  // limit at V is refused before the first step (a typo in kn or kt, or a tiny platen speed,
  // can ask for billions), and a test that passes it (pauses included) stops with an error.
  long max_steps = 20000000;

  // --- Measurement ---
  // Secant window, fractions of the peak control stress (of the largest one when there is
  // no peak), 0 < low < high < 1 (Labra section 4.3.1: 1-50 %).
  double modulus_window_low = 0.01;
  double modulus_window_high = 0.5;
  // The linear portion of a compression test (LabTestResult::linear_elastic, the ISRM
  // average modulus of the intact specimen): samples before the first broken bond with a
  // control stress of at least this fraction of the largest among them, in (0, 1). Below 0.2
  // the start-up of the drive still shows in the lateral strain (5,064 discs: nu 0.2032 over
  // 10-100 % of a 5e-4 strain against 0.2012 from 20 % of 1e-3 to 2e-3 strains).
  double linear_portion_low = 0.2;
  // Steps between samples of the curve (stress, strain, broken bonds, energy), >= 1.
  int sample_interval_steps = 200;
  // Bagi strain over the cells whose vertices are at least this many mean radii inside the
  // specimen's domain, >= 0; 0 = every cell (the convex hull of the centres, Labra). Rattlers
  // (fewer than Dim contacts) are always left out. The default leaves out the outer two
  // particle layers, whose compliance is a boundary effect that shrinks with r/L (header
  // comment, "Measurement"): the interior gives the material's E and nu.
  double strain_boundary_margin = 4.0;

  // --- Confined biaxial ---
  // Confining stress sigma_3 [Pa], compression positive, >= 0 (kConfinedCompression).
  double confining_stress_pa = 0.0;
  // Servo of the lateral walls (walls.h WallServo): gain fraction in (0, 1], integral time in
  // wave transits (> 0), and the tolerance of the consolidation (relative, in (0, 0.1)).
  double servo_gain_fraction = 0.2;
  double servo_integral_transits = 2.0;
  double consolidation_tolerance = 0.005;

  // --- Specimen ---
  // Labra's density scaling rho' = rho / (1 - e) with e the packing's nominal porosity, so
  // the particles carry the mass of the solid they represent.
  bool scale_density = false;
  // Platen (wall) normal stiffness relative to kn, > 0, and platen friction >= 0 (0:
  // frictionless, the uniform stress state E and nu assume).
  double platen_stiffness_ratio = 1.0;
  double platen_friction = 0.0;
  // Brazilian test (other kinds do not use it: a protocol is shared by the UCS and the
  // Brazilian test): the jaws' loading arc 2 alpha [degrees], in [0, 60]; 0: flat platens.
  // Over an arc each jaw presses the disc's surface particles within alpha of its pole with a
  // uniform radial pressure (brazilian_jaws.h), and sigma_t = k 2 F / (pi D t) with Hondros's
  // k. Frictionless (platen_friction must be 0); a disc (2D) or cylinder (3D) only.
  double loading_arc_deg = 0.0;

  // --- Damping (replaces the material's damping fields, header comment) ---
  double local_damping = 0.7;  // alpha_t = alpha_r, in [0, 1)
  double dashpot_ratio = 0.1;  // xi_n = xi_t, >= 0
  // Inertia scaling of the particles that limit the time step (MaterialParameters::
  // mass_scaling_budget, replaces the material's field): the share of the total mass that
  // may be added to them, in [0, 0.05]; 0 = true masses. Header comment "Inertia scaling".
  double mass_scaling_budget = 0.01;
  // Time step as this fraction of the certified critical step of the stability analysis
  // (TimeStepOptions::safety_factor), in (0, 0.95]. The certificate covers the bonded
  // network as generated; the margin below 1 is for what it does not: contacts that close
  // during the test (after breakage, post-peak) and the geometry's change under load.
  // Measured at 0.9 (Labra's parameters): 1.23-1.26x fewer steps, E unchanged, the peak
  // -0.24 % on 5,064 discs but -3.5 % on 10,044 (beyond the path noise): the cascades'
  // dynamics may feel the step, hence the default.
  double time_step_safety_factor = 0.7;

  // --- Checks and outputs ---
  // Repeat the test at half the rate and flag whether E or the peak change by more than
  // quasi_static_tolerance (relative, > 0): triples the cost.
  bool check_quasi_static = false;
  double quasi_static_tolerance = 0.01;
  // Keep the particle state at the peak and at the end (positions, bond states) for VTU.
  bool record_snapshots = false;
  int num_threads = 1;        // OpenMP threads of the solver passes, >= 1
  ProgressCallback progress;  // may be empty

  // Names the first invalid field, its value and the allowed range.
  bool IsValid(std::string* error) const;
};

// One sample of the curve. Tensors are 3 x 3 (2D: the xy block, zeros elsewhere), tension
// positive; the scalar "control" quantities are positive in compression (docs/lab.md,
// "Measurement", signs).
struct LabCurvePoint {
  long step = 0;
  double time_s = 0.0;
  Eigen::Matrix3d stress_pa = Eigen::Matrix3d::Zero();  // SpecimenStress over the volume below
  Eigen::Matrix3d strain = Eigen::Matrix3d::Zero();     // Bagi, from the reference state
  double volume_m3 = 0.0;                               // the stress volume used
  // Platen (or boundary) strain: axial shortening over the initial gap (UCS, biaxial,
  // isotropic: along the loading axis), platen approach over D (BTS), imposed eps_xy (shear).
  double boundary_strain = 0.0;
  // The control quantity of the test (compression positive): axial stress (UCS), deviator
  // sigma_1 - sigma_3 (biaxial), mean platen force per unit thickness in 2D [N/m] or N in 3D
  // (BTS), mean stress (isotropic), shear stress |sigma_xy| (shear) [Pa].
  double control = 0.0;
  double axial_stress_pa = 0.0;    // -sigma_aa, compression positive
  double lateral_stress_pa = 0.0;  // -mean of the lateral normal stresses
  double platen_force_n = 0.0;     // mean compressive reaction of the two platens
  long broken_in_tension = 0;      // cumulative
  long broken_in_shear = 0;
  double kinetic_energy_j = 0.0;
  double elastic_energy_j = 0.0;
  double external_work_j = 0.0;
  double dissipated_j = 0.0;
};

// A bond that broke, when and how (detected at the sample after it broke).
struct BrokenBond {
  std::array<int, 2> pair = {0, 0};
  bool in_tension = true;  // else in shear
  double time_s = 0.0;
  double boundary_strain = 0.0;          // at detection
  Eigen::Vector3d midpoint = Eigen::Vector3d::Zero();  // between the centres at detection [m]
};

// The particle state at one moment, for VTU snapshots.
struct LabSnapshot {
  bool recorded = false;
  std::string label;  // "peak", "end"
  double time_s = 0.0;
  std::vector<Eigen::Vector3d> position;      // centres [m]
  std::vector<Eigen::Vector3d> displacement;  // from the packing [m]
  std::vector<std::array<int, 2>> bonds;      // every initial bond
  std::vector<ContactState> bond_state;       // per bond at that moment
};

// Secant elastic constants over the window (Labra (4.31), (4.34); Madan (4.19), (4.22)).
struct ElasticConstantsMeasured {
  bool measured = false;
  // 2D: in-plane E', nu' (the slopes); 3D: E, nu.
  double youngs_modulus_in_plane_pa = 0.0;
  double poisson_ratio_in_plane = 0.0;
  // 2D: plane strain E = E'(1 - nu^2), nu = nu'/(1 + nu'); 3D: equal to the above.
  double youngs_modulus_pa = 0.0;
  double poisson_ratio = 0.0;
  // E' (3D: E) with the platen strain instead of Bagi's.
  double youngs_modulus_platen_pa = 0.0;
  // The window used: control stresses [Pa] and the samples inside it.
  double window_low_pa = 0.0;
  double window_high_pa = 0.0;
  int samples_in_window = 0;
  // Bonds broken by the window's upper end (at the first sample reaching it): > 0 means the
  // secants include damage, which raises nu and lowers E (header comment, "Measurement").
  long broken_bonds_in_window = 0;
};

struct QuasiStaticCheck {
  // Not performed: neither passed nor failed, and the reports say so ("not run", with why).
  bool performed = false;
  std::string not_run_reason = "not requested (quasi_static_check = false or --no-quasi-static-check)";
  double half_rate_group = 0.0;
  // Relative changes of E (isotropic test: K; shear: G) and of the peak (strength tests)
  // at half the rate; 0 when not applicable.
  double modulus_change = 0.0;
  double peak_change = 0.0;
  double tolerance = 0.01;
  bool passed = false;
};

// The name of the control quantity with its unit in the outputs: "control_pa", or for the
// Brazilian test, whose control is the platen force, "control_n" (2D "control_n_per_m").
std::string ControlName(LabTestKind kind, int dimension);

enum class LabTermination { kPostPeak, kStrainLimit };

struct LabTestResult {
  int dimension = 0;
  LabTestKind kind = LabTestKind::kUniaxialCompression;
  // Specimen.
  std::string domain;  // Domain::ToText
  int particles = 0;
  int bonds = 0;
  double porosity = 0.0;                  // nominal, of the packing
  double mean_radius_m = 0.0;             // volume-based
  double density_used_kg_per_m3 = 0.0;    // rho, or rho' when scaled
  double height_m = 0.0;                  // extent along the loading axis (BTS: diameter D)
  double width_m = 0.0;                   // lateral extent (2D width, 3D diameter or x width)
  double thickness_m = 1.0;               // 2D: 1 m; 3D BTS: cylinder length; else depth
  int strain_cells = 0;                   // Delaunay cells of the Bagi strain
  // Rate and time stepping.
  double loading_rate_group = 0.0;
  double platen_speed_m_per_s = 0.0;
  double strain_rate_per_s = 0.0;
  double time_step_s = 0.0;
  double critical_time_step_s = 0.0;
  MassScalingSummary mass_scaling;  // what LabTestOptions::mass_scaling_budget did
  std::vector<std::string> stages;
  long steps = 0;
  int pauses = 0;         // quasi-static guard: times the platens paused
  long paused_steps = 0;  // steps spent paused
  double simulated_time_s = 0.0;
  double wall_seconds = 0.0;
  // Termination.
  LabTermination termination = LabTermination::kStrainLimit;
  std::string termination_message;
  double strain_limit = 0.0;  // used
  bool peak_reached = false;  // strength tests: the control stress fell after its peak
  // Results (compression positive).
  double peak_stress_pa = 0.0;  // UCS; biaxial: sigma_1 at the peak; BTS: sigma_t
  double peak_control = 0.0;    // the control quantity at the peak
  double strain_at_peak = 0.0;  // Bagi axial strain (shortening positive)
  double boundary_strain_at_peak = 0.0;
  double peak_force_n = 0.0;    // mean platen force at the peak
  double tensile_strength_pa = 0.0;  // BTS: k 2 F / (pi D t)
  // BTS: k, the centre's tensile stress per 2 F / (pi D t): 1 for flat platens (Labra (4.38)),
  // Hondros's (sin 2 alpha - alpha) / sin alpha for jaws with a loading arc 2 alpha.
  double tensile_strength_factor = 1.0;
  double loading_arc_deg = 0.0;  // BTS: the jaws' 2 alpha (0: flat platens)
  ElasticConstantsMeasured elastic;
  // UCS and biaxial: the linear portion of the intact specimen (lab_measurement.h
  // LinearPortionElasticConstants), what the calibrator matches to a rock's E and nu.
  ElasticConstantsMeasured linear_elastic;
  double bulk_modulus_pa = 0.0;   // isotropic test (2D: in-plane, sigma_h / eps_vol)
  double shear_modulus_pa = 0.0;  // shear test
  double confining_stress_pa = 0.0;
  double confinement_max_error = 0.0;  // largest relative |sigma_lat - sigma_3| while loading
  // Bonds and energy.
  long broken_in_tension = 0;
  long broken_in_shear = 0;
  std::vector<BrokenBond> broken_bonds;
  EnergyBalance energy;
  std::vector<LabCurvePoint> curve;
  QuasiStaticCheck quasi_static;
  LabSnapshot peak_snapshot;
  LabSnapshot end_snapshot;

  std::string BriefReport() const;
  std::string FullReport() const;
  // Everything but the curve, the broken-bond list and the snapshots (those go to CSV/VTU).
  nlohmann::json ToJson() const;
};

// Runs one test. `material` gives kn, kt, Rn, Rt, mu, rho (scaled when asked) and the
// optional DDEM particle elasticity; its damping fields are replaced by the options'.
template <int Dim>
LabTestResult RunLabTest(const Packing<Dim>& packing, const MaterialParameters& material,
                         const LabTestOptions& options);

// The quasi-static check of `result` against the same test at half the rate (`slow`): the
// relative changes of the modulus and the peak that options.kind compares, against
// options.quasi_static_tolerance.
QuasiStaticCheck CompareAtHalfRate(const LabTestOptions& options, const LabTestResult& result,
                                   const LabTestResult& slow);

}  // namespace specimen
