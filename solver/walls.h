#pragma once
// Rigid plane walls (platens) with their own contact stiffness. A wall is a plane through
// `point` with unit `normal` pointing to the particles' side. A particle touches it when
// its (deformed) surface crosses the plane:
//   gap = (x - point) . normal - R  [- R normal.eps.normal in DDEM scenes, Madan (2.53)],
//   force on the particle = -k_wall gap normal for gap < 0 (compression only),
// plus optional Coulomb friction (tangential spring k_t,wall, radial return with mu_wall)
// and the normal dashpot of the scene (ratio xi_n of 2 sqrt(m k_wall)). The wall force on
// a particle enters its DDEM stress like a contact force at the contact point s = -R normal.
//
// A wall may instead be a conforming jaw (the loading arc of a Brazilian test): it presses
// a fixed set of surface particles along their own inward directions n_k with the shares
// w_k (sum 1) of one force F = K max(p, 0), a uniform radial pressure over the arc (Hondros
// 1959). p is the jaw's penetration, travel C - sum w_k n_k . (u_k + eps_k s_k): a rigid jaw
// shaped to the arc and moved by `travel` along its normal moves the arc point k by travel
// (n_k . normal) along n_k; C = sum w_k n_k . normal; u_k is the particle's displacement,
// s_k = -R_k n_k its loaded surface point (DDEM: the point moves by eps s, Madan (2.52)).
// K = k_wall x the number of jaw particles, so each particle meets about one wall spring;
// K w w^T <= K diag(w) (sum w = 1) bounds it for the time step by a spring K w_k on each.
// The jaw's energy is 1/2 K p^2, its reaction F C, its drive work that of a wall.
//
// Walls translate only. A velocity-driven wall follows its prescribed velocity; a
// force-driven wall has a mass and moves along its normal under the applied force and the
// particles' reaction; a servo-controlled wall (the lateral walls of a confined biaxial
// test) is massless and moves along its normal at the speed a proportional-integral
// controller sets to hold a target stress on it (WallServo below). The work of the drive
// (prescribed motion, applied force or servo) is the wall's external work; the energy of
// the wall springs is contact energy.

#include <array>
#include <string>
#include <vector>

#include "solver/loads.h"
#include "solver/vector_algebra.h"

namespace specimen {

template <int Dim>
struct SceneState;

enum class WallDrive {
  kVelocity,  // prescribed velocity (zero: a fixed wall)
  kForce,     // prescribed force towards the particles, the wall has a mass
  kServo,     // massless, moved along its normal to hold a target stress (WallServo)
};

// The stress servo of a kServo wall. Each step, at t_n:
//   F_target = stress_pa x A,  A = product over area_wall_pairs of the distance between the
//              two walls' planes (x 1 m in 2D), or reference_area_m2 when there are no pairs
//              (so the target follows the specimen as the other walls move);
//   e = F_target - F,  F = the wall's compressive reaction (WallState::NormalReaction);
//   v = gain (e + (1 / integral_time_s) sum e dt) along the normal (towards the particles),
//   gain = gain_fraction / (k_wall n_touch dt), |v| <= max_speed_m_per_s,
// with n_touch >= 1 the particles touching the wall at t_n. Without the specimen's own
// compliance the wall springs alone would close the error in 1 / gain_fraction steps;
// gain_fraction < 1 keeps the loop stable with the specimen's inertia in it (PFC's servo
// uses 0.5). The integral term removes the steady lag of a wall that must keep moving
// (a specimen dilating under axial load): with a proportional servo alone that lag is
// v_wall k_wall n_touch dt / gain_fraction.
struct WallServo {
  double stress_pa = 0.0;  // target compressive stress on the wall, >= 0 [Pa]
  // Pairs of wall indices (into SceneOptions::walls) whose plane distances multiply to the
  // wall's area, e.g. in 2D the two platens for a lateral wall; in 3D two pairs.
  std::vector<std::array<int, 2>> area_wall_pairs;
  double reference_area_m2 = 0.0;  // used when area_wall_pairs is empty, > 0 then
  double gain_fraction = 0.2;      // in (0, 1]
  double integral_time_s = 0.0;    // >= 0; 0: proportional only
  double max_speed_m_per_s = 1.0;  // > 0
};

template <int Dim>
struct WallOptions {
  std::string name;                           // for reports, e.g. "top platen"
  Vector<Dim> point = Vector<Dim>::Zero();    // a point of the plane at t = 0 [m]
  Vector<Dim> normal = Vector<Dim>::Zero();   // towards the particles; normalised on use
  double normal_stiffness_n_per_m = 0.0;      // k_wall > 0 [N/m]
  double tangential_stiffness_n_per_m = 0.0;  // >= 0; 0 = frictionless wall
  double friction_coefficient = 0.0;          // mu_wall >= 0 (needs a tangential stiffness)
  WallDrive drive = WallDrive::kVelocity;
  // kVelocity: wall velocity [m/s] = velocity * velocity_amplitude(t).
  Vector<Dim> velocity = Vector<Dim>::Zero();
  Amplitude velocity_amplitude;
  // kForce: force pushing the wall towards the particles (along +normal) [N] times
  // force_amplitude(t); the wall mass [kg] > 0; damped by the scene's alpha_t.
  double applied_force_n = 0.0;
  Amplitude force_amplitude;
  double mass_kg = 0.0;
  // kServo: the stress controller.
  WallServo servo;

  // A conforming jaw (header): its particles (indices of the packing, distinct), their force
  // shares (> 0, summing to 1) and inward unit directions. Empty: a plane wall. A jaw is
  // frictionless and velocity-driven.
  std::vector<int> jaw_particles;
  std::vector<double> jaw_weights;
  std::vector<Vector<Dim>> jaw_inward;

  bool friction() const { return tangential_stiffness_n_per_m > 0.0 && friction_coefficient > 0.0; }
  bool conforming() const { return !jaw_particles.empty(); }
  // The jaw's stiffness K [N/m] (header).
  double JawStiffness() const { return normal_stiffness_n_per_m * static_cast<double>(jaw_particles.size()); }
  bool IsValid(std::string* error) const;
};

// The state of one wall during a run.
template <int Dim>
struct WallState {
  WallOptions<Dim> options;
  Vector<Dim> normal = Vector<Dim>::Zero();    // unit
  Vector<Dim> point = Vector<Dim>::Zero();     // current point of the plane (t_n)
  Vector<Dim> velocity = Vector<Dim>::Zero();  // at the last half step
  // Total force the particles exert on the wall at the last evaluation [N].
  Vector<Dim> force_on_wall = Vector<Dim>::Zero();
  // Force of the drive on the wall at the last evaluation (for the trapezoidal work).
  Vector<Dim> previous_drive_force = Vector<Dim>::Zero();
  double work_j = 0.0;  // work of the drive since t = 0
  // kServo: the target force of the last step [N] and the integral of its error [N s].
  double servo_target_force_n = 0.0;
  double servo_error_integral_n_s = 0.0;
  double displacement_since_search = 0.0;
  // Candidate contacts, sorted by particle: particles within the search skin of the plane.
  std::vector<int> particle;
  std::vector<double> normal_elastic_force;   // k_wall gap (<= 0) [N]
  std::vector<Vector<Dim>> tangential_force;  // spring force on the particle [N]
  // Merge buffers for the candidate rebuild (kept to avoid allocation in the loop).
  std::vector<int> scratch_particle;
  std::vector<double> scratch_normal_force;
  std::vector<Vector<Dim>> scratch_tangential_force;

  // A conforming jaw: per candidate (`particle` holds the jaw's particles, fixed), the
  // inward direction n_k and force share w_k, the particle's centre at t = 0, and the jaw's
  // reach C, travel (along `normal` since t = 0) and penetration p at the last evaluation.
  std::vector<Vector<Dim>> jaw_inward;
  std::vector<double> jaw_weight;
  std::vector<Vector<Dim>> jaw_reference_centre;
  double jaw_reach = 0.0;
  double jaw_travel_m = 0.0;
  double jaw_penetration_m = 0.0;

  // The compressive reaction, -force_on_wall . normal (>= 0 when pushed) [N].
  double NormalReaction() const { return -force_on_wall.dot(normal); }
  // The direction the wall pushes candidate k: the plane's normal, or a jaw's n_k. The
  // contact point is at -R times it from the particle's centre; the force on the particle is
  // -normal_elastic_force[k] times it plus the tangential force.
  const Vector<Dim>& PushDirection(size_t k) const { return jaw_inward.empty() ? normal : jaw_inward[k]; }
  // The energy of the wall's springs [J].
  double ElasticEnergy() const;
};

struct WallPassTotals {
  double work_j = 0.0;                 // drive work increment of this step
  double supplied_j = 0.0;             // sum of |work increments| of the walls
  double kinetic_energy_j = 0.0;       // force-driven walls, 1/2 M v_- . v_+
  double damping_dissipation_j = 0.0;  // force-driven walls
  double dashpot_dissipation_j = 0.0;
  double friction_dissipation_j = 0.0;
  double max_force_n = 0.0;
  bool finite = true;
};

// Contact forces of every wall on its candidates at t_n; adds them to the particles'
// external force, moment and (DDEM) surface moment accumulators; sums the reaction on each
// wall; accumulates the drive work; moves the walls to t_{n+1} (force-driven walls by
// central differences under the applied force, the reaction and the local damping alpha_t;
// servo walls at the controller's speed).
template <int Dim>
void WallPass(SceneState<Dim>& state, bool deformable, bool rotation, bool dashpots,
              WallPassTotals* totals);

// A jaw's state at t = 0 from its options and the particles' centres: its particles as
// the candidates (sorted), their directions, shares and reference centres, and its reach.
template <int Dim>
void StartJaw(WallState<Dim>& wall, const std::vector<Vector<Dim>>& centres);

// Rebuilds each plane wall's candidate list (particles whose surface is within `skin` of the
// plane), carrying the tangential history of candidates that stay; a jaw keeps its own.
template <int Dim>
void RebuildWallCandidates(SceneState<Dim>& state, double skin);

}  // namespace specimen
