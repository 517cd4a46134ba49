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
// The tests (Labra 2012 section 4.2; Madan 2019 section 4.5):
//  - kUniaxialCompression: a rectangle (2D), cylinder or box (3D) between two rigid,
//    frictionless platens (walls placed at the extreme particles, stiffness kn), each moving
//    towards the other at the speed V; through the peak until the axial stress has fallen to
//    post_peak_stress_fraction of it.
//  - kBrazilian: a disc (2D) or cylinder (3D, axis z) between flat platens normal to y;
//    sigma_t = 2 F / (pi D t) with F the peak platen force, t = 1 m in 2D (Labra (4.38)).
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
// Measurement (solver/lab_measurement.h): stress by the branch-vector average with the
// wall contacts (homogenisation.h SpecimenStress) over V = the current wall-to-wall volume
// (platen gap x the specimen's lateral extent from its domain; confined and isotropic
// tests: the product of the wall gaps; pure shear: the triangulated region of the centres,
// where its boundary forces act); strain by Bagi's method (homogenisation_strain.h) and
// from the platen displacement; secant E, nu over [modulus_window_low,
// modulus_window_high] x peak (Labra: 1-50 %), in 2D both the in-plane E', nu' and the
// plane-strain E = E'(1 - nu^2), nu = nu'/(1 + nu') (design.md; Labra's (4.33) is wrong).
//
// Loading rate (Labra (4.20)): the group V / sqrt(kn / rho) in 2D (kn per unit thickness),
// V / sqrt(kn / (rho r_mean)) in 3D, V the speed of each platen; sqrt(kn / rho) is the
// scale of the wave speed, so the group is the axial strain added per wave transit of the
// specimen over two. The default 5e-5 is about 150 transits to the peak of a typical rock
// and passes the quasi-static check (halving the rate changes E and the peak by < 1 %,
// check_quasi_static) while a 10,000-disc 2D UCS runs in about a minute.
//
// Damping belongs to the protocol, not the material: local non-viscous damping
// alpha_t = alpha_r = local_damping (Labra note 1.5 gap: 0.7, PFC's default) and contact
// dashpots at dashpot_ratio of critical replace the material's damping fields. The
// dashpot ratio is small (0.1): at quasi-static rates the viscous forces are below 1e-4 of
// the elastic ones, and each 0.1 costs about 10 % of the time step (Labra (2.53)).
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
  // Quasi-static guard of the strength tests (UCS, BTS, biaxial): after the ramp, the platens
  // pause (their speed ramps to 0 over one sample interval) while the kinetic energy of the
  // particles exceeds this multiple of the kinetic energy of the affine compression at V,
  // 1/2 M V^2 / 3 - the signature of a bond-breaking cascade - and resume once it has decayed,
  // or after max_pause_transits wave transits (a fragment flying off keeps its energy).
  // Bonded specimens fail progressively; at constant speed the peak keeps rising with the
  // rate (2.6 % per halving even at 1/8 of the default rate, without the guard), because the
  // load grows while each cascade redistributes. >= 0; 0 = constant speed.
  double pause_kinetic_energy_ratio = 3.0;
  double max_pause_transits = 4.0;  // > 0

  // --- When to stop ---
  // A strength test stops once the control stress (axial stress, BTS platen force, biaxial
  // deviator) has fallen to this fraction of its peak, in (0, 1).
  double post_peak_stress_fraction = 0.5;
  // Strain at which the test stops [-], > 0 and < 0.5; 0: automatic, 0.02 for strength tests
  // (then reported as "no peak"), 0.001 for the isotropic and shear tests. Axial platen
  // strain (UCS, biaxial, isotropic), platen displacement / D (BTS), eps_xy imposed (shear).
  double strain_limit = 0.0;

  // --- Measurement ---
  // Secant window, fractions of the peak control stress (of the largest one when there is
  // no peak), 0 < low < high < 1 (Labra section 4.2.2: 1-50 %).
  double modulus_window_low = 0.01;
  double modulus_window_high = 0.5;
  // Steps between samples of the curve (stress, strain, broken bonds, energy), >= 1.
  int sample_interval_steps = 200;
  // Bagi strain over the cells whose vertices are at least this many mean radii inside the
  // specimen's domain, >= 0; 0 = every cell (the convex hull of the centres, Labra).
  double strain_boundary_margin = 0.0;

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

  // --- Damping (replaces the material's damping fields, header comment) ---
  double local_damping = 0.7;  // alpha_t = alpha_r, in [0, 1)
  double dashpot_ratio = 0.1;  // xi_n = xi_t, >= 0

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
// positive (design.md); the scalar "control" quantities are positive in compression.
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
};

struct QuasiStaticCheck {
  bool performed = false;
  double half_rate_group = 0.0;
  // Relative changes of E (isotropic test: K; shear: G) and of the peak (strength tests)
  // at half the rate; 0 when not applicable.
  double modulus_change = 0.0;
  double peak_change = 0.0;
  double tolerance = 0.01;
  bool passed = false;
};

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
  double tensile_strength_pa = 0.0;  // BTS: 2 F / (pi D t)
  ElasticConstantsMeasured elastic;
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

}  // namespace specimen
