#include "lab/lab_runner.h"

#include <array>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include "common/error.h"
#include "solver/homogenisation.h"
#include "solver/homogenisation_strain.h"
#include "lab/brazilian_jaws.h"
#include "lab/lab_measurement.h"
#include "solver/scene_state.h"
#include "solver/simulation.h"
#include "common/format.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;

template <int Dim>
Eigen::Matrix3d Embed(const Eigen::Matrix<double, Dim, Dim>& m) {
  Eigen::Matrix3d full = Eigen::Matrix3d::Zero();
  full.topLeftCorner<Dim, Dim>() = m;
  return full;
}

template <int Dim>
Eigen::Vector3d Embed(const Vector<Dim>& v) {
  Eigen::Vector3d full = Eigen::Vector3d::Zero();
  full.head<Dim>() = v;
  return full;
}

// 0 -> 1 over [start, start + ramp], then 1 (constant 1 without a ramp).
Amplitude RampFrom(double start_s, double ramp_s) {
  Amplitude a;
  if (ramp_s > 0.0) a.points = {{start_s, 0.0}, {start_s + ramp_s, 1.0}};
  return a;
}

// Wall indices: 0 bottom and 1 top platen along the loading axis; confined and isotropic
// tests add the lateral walls, two per lateral axis (min side, then max side).
template <int Dim>
class LabRun {
 public:
  LabRun(const Packing<Dim>& packing, const LabSpecimen<Dim>& specimen,
         const MaterialParameters& material, const LabTestOptions& options, double speed,
         double strain_limit)
      : packing_(packing),
        specimen_(specimen),
        material_(material),
        options_(options),
        speed_(speed),
        strain_limit_(strain_limit),
        strain_(packing.centres, specimen.strain_region) {
    transit_s_ = specimen.height_m / WaveSpeedScale<Dim>(material, specimen.mean_radius_m);
    ramp_s_ = options.velocity_ramp_transits * transit_s_;
    if (options.kind == LabTestKind::kPureShear && !specimen.strain_region.empty())
      hull_.emplace(packing.centres);  // the stress volume is the whole triangulated region
    if (Jaws()) jaws_ = BrazilianJawArcs<Dim>(packing, options.loading_arc_deg);
  }

  LabTestResult Run();

 private:
  bool Confined() const { return options_.kind == LabTestKind::kConfinedCompression; }
  // A Brazilian test with a loading arc: the platens are conforming jaws (brazilian_jaws.h).
  bool Jaws() const { return options_.kind == LabTestKind::kBrazilian && options_.loading_arc_deg > 0.0; }
  bool WithLateralWalls() const {
    return Confined() || options_.kind == LabTestKind::kIsotropicCompression;
  }
  SceneOptions<Dim> BuildScene();
  WallOptions<Dim> PlatenDrive(int index, double start_s) const;
  // Ramps the platen speed from its current value to `to` times V, over
  // max(one sample interval, pause_ramp_transits) times the change.
  void RampPlatenSpeed(double to);
  // The platen speed over V at time t, as set by the last RampPlatenSpeed (1 before any).
  double PlatenSpeedFactor(double t) const;
  // The kinetic energy of the affine compression at the speed V: the platens close at 2V,
  // the particles move on v_a = 2 V (x_a - centre) / H: 1/2 M V^2 / 3.
  double AffineKineticEnergy() const;
  void Consolidate();
  LabCurvePoint Sample() const;
  double WallGap(int a, int b) const {
    const WallState<Dim>& wa = simulation_->wall(a);
    return std::abs((simulation_->wall(b).point - wa.point).dot(wa.normal));
  }
  // Compressive stress on wall `w` over its face (the servo's own measure).
  double WallStress(int w) const;
  double LateralStressError() const;
  void TrackBrokenBonds(double boundary_strain);
  void Snapshot(const char* label, LabSnapshot* snapshot) const;
  void Measure(LabTestResult* result) const;

  const Packing<Dim>& packing_;
  const LabSpecimen<Dim>& specimen_;
  MaterialParameters material_;
  const LabTestOptions& options_;
  double speed_;
  double strain_limit_;
  // The last ramp of the platen speed factor (quasi-static guard).
  double ramp_start_s_ = 0.0, ramp_end_s_ = 0.0, ramp_from_ = 1.0, ramp_to_ = 1.0;
  BagiStrain<Dim> strain_;
  std::optional<BagiStrain<Dim>> hull_;
  double transit_s_ = 0.0;
  double ramp_s_ = 0.0;
  std::unique_ptr<Simulation<Dim>> simulation_;
  int axis_ = Dim - 1;
  // References at the start of the axial loading.
  double load_start_s_ = 0.0;
  double gap0_ = 0.0;
  Eigen::Matrix3d strain0_ = Eigen::Matrix3d::Zero();
  // Pure shear: the top-most boundary particle, its initial position, the height over
  // the bottom reference, and the shear rate.
  int shear_particle_ = -1;
  double shear_height_ = 0.0;
  double shear_rate_ = 0.0;
  // Bonds: the initial bonds (sorted), the broken ones recorded so far (sorted, with mode).
  std::vector<std::array<int, 2>> bonds_;
  std::vector<std::pair<std::array<int, 2>, bool>> broken_;
  long broken_total_ = 0;
  std::vector<BrokenBond> broken_list_;
  bool guard_budget_spent_ = false;
  std::array<JawArc<Dim>, 2> jaws_;  // bottom, top (Jaws())
};

template <int Dim>
WallOptions<Dim> LabRun<Dim>::PlatenDrive(int index, double start_s) const {
  WallOptions<Dim> w;
  const Vector<Dim> e = Vector<Dim>::Unit(axis_);
  const bool bottom = index == 0;
  w.name = bottom ? "bottom platen" : "top platen";
  w.point = Vector<Dim>::Zero();
  w.point[axis_] = bottom ? specimen_.lower[axis_] : specimen_.upper[axis_];
  w.normal = bottom ? e : Vector<Dim>(-e);
  w.normal_stiffness_n_per_m = options_.platen_stiffness_ratio * material_.normal_stiffness_n_per_m;
  if (options_.platen_friction > 0.0) {
    const double kt = material_.tangential_stiffness_n_per_m > 0.0
                          ? material_.tangential_stiffness_n_per_m
                          : material_.normal_stiffness_n_per_m;
    w.tangential_stiffness_n_per_m = options_.platen_stiffness_ratio * kt;
    w.friction_coefficient = options_.platen_friction;
  }
  if (Jaws()) {
    w.jaw_particles = jaws_[index].particles;
    w.jaw_weights = jaws_[index].weights;
    w.jaw_inward = jaws_[index].inward;
  }
  w.drive = WallDrive::kVelocity;
  w.velocity = speed_ * w.normal;  // towards the particles
  w.velocity_amplitude = RampFrom(start_s, ramp_s_);
  return w;
}

template <int Dim>
double LabRun<Dim>::PlatenSpeedFactor(double t) const {
  if (t >= ramp_end_s_) return ramp_to_;
  if (t <= ramp_start_s_) return ramp_from_;
  return ramp_from_ + (ramp_to_ - ramp_from_) * (t - ramp_start_s_) / (ramp_end_s_ - ramp_start_s_);
}

template <int Dim>
void LabRun<Dim>::RampPlatenSpeed(double to) {
  const double t = simulation_->time_s();
  const double from = PlatenSpeedFactor(t);
  const double ramp = std::max(options_.sample_interval_steps * simulation_->time_step_s(),
                               options_.pause_ramp_transits * transit_s_) *
                      std::abs(to - from);
  ramp_start_s_ = t;
  ramp_end_s_ = t + ramp;
  ramp_from_ = from;
  ramp_to_ = to;
  for (int k = 0; k < 2; ++k) {
    WallOptions<Dim> w = PlatenDrive(k, t);
    w.velocity_amplitude.points = {{t, from}, {t + ramp, to}};
    if (!(ramp > 0.0)) w.velocity_amplitude.points = {{t, to}};
    simulation_->SetWallOptions(k, w);
  }
}

template <int Dim>
double LabRun<Dim>::AffineKineticEnergy() const {
  double mass = 0.0;
  for (const double m : simulation_->particles().mass) mass += m;
  return 0.5 * mass * speed_ * speed_ / 3.0;
}

template <int Dim>
SceneOptions<Dim> LabRun<Dim>::BuildScene() {
  SceneOptions<Dim> scene;
  scene.material = material_;
  scene.num_threads = options_.num_threads;
  scene.time_step.safety_factor = options_.time_step_safety_factor;
  const LabTestKind kind = options_.kind;
  if (kind == LabTestKind::kPureShear) {
    // Madan section 4.5: boundary particles on the simple-shear field, rotations free.
    FixedDofs<Dim> boundary;
    boundary.name = "sheared boundary";
    boundary.particles = specimen_.boundary_particles;
    boundary.fix_translation.fill(true);
    boundary.amplitude = RampFrom(0.0, ramp_s_);
    const int s = Dim - 1;
    double bottom = std::numeric_limits<double>::infinity(), top = -bottom;
    for (const int q : boundary.particles) {
      bottom = std::min(bottom, packing_.centres[q][s]);
      if (packing_.centres[q][s] > top) {
        top = packing_.centres[q][s];
        shear_particle_ = q;
      }
    }
    shear_height_ = top - bottom;
    shear_rate_ = 2.0 * speed_ / specimen_.height_m;  // gamma_dot: the top moves at ~2V
    for (const int q : boundary.particles) {
      Vector<Dim> v = Vector<Dim>::Zero();
      v.x() = shear_rate_ * (packing_.centres[q][s] - bottom);
      boundary.particle_velocities.push_back(v);
    }
    scene.fixed_dofs.push_back(boundary);
    return scene;
  }
  scene.walls.push_back(PlatenDrive(0, 0.0));
  scene.walls.push_back(PlatenDrive(1, 0.0));
  if (!WithLateralWalls()) return scene;
  // Lateral walls: two per lateral axis at the extreme particles.
  for (int a = 0; a < Dim; ++a) {
    if (a == axis_) continue;
    for (int side = 0; side < 2; ++side) {
      WallOptions<Dim> w = scene.walls[0];
      const Vector<Dim> e = Vector<Dim>::Unit(a);
      w.name = std::string(side == 0 ? "min " : "max ") + "xyz"[a] + " wall";
      w.point = Vector<Dim>::Zero();
      w.point[a] = side == 0 ? specimen_.lower[a] : specimen_.upper[a];
      w.normal = side == 0 ? e : Vector<Dim>(-e);
      // Isotropic test: the same strain rate as the platens'.
      const double extent = specimen_.upper[a] - specimen_.lower[a];
      w.velocity = speed_ * extent / specimen_.height_m * w.normal;
      scene.walls.push_back(w);
    }
  }
  if (!Confined()) return scene;
  // Confined: every wall servo-held at sigma_3 (consolidation); the platens switch to their
  // velocity drive once it is reached (Consolidate).
  const int walls = static_cast<int>(scene.walls.size());
  for (int k = 0; k < walls; ++k) {
    WallOptions<Dim>& w = scene.walls[k];
    const bool platen = k < 2;
    if (platen && options_.confining_stress_pa == 0.0) continue;  // nothing to consolidate
    w.drive = WallDrive::kServo;
    w.velocity = Vector<Dim>::Zero();
    w.velocity_amplitude = Amplitude();
    w.servo.stress_pa = options_.confining_stress_pa;
    w.servo.gain_fraction = options_.servo_gain_fraction;
    w.servo.integral_time_s = options_.servo_integral_transits * transit_s_;
    w.servo.max_speed_m_per_s = 10.0 * speed_;
    // The face area: the gaps of the wall pairs of the other axes.
    const int own = platen ? 0 : 2 + 2 * ((k - 2) / 2);
    for (int pair = 0; pair < walls; pair += 2)
      if (pair != own) w.servo.area_wall_pairs.push_back({pair, pair + 1});
  }
  return scene;
}

template <int Dim>
double LabRun<Dim>::WallStress(int w) const {
  const int walls = simulation_->wall_count();
  const int own = w < 2 ? 0 : 2 + 2 * ((w - 2) / 2);
  double area = 1.0;
  for (int pair = 0; pair < walls; pair += 2)
    if (pair != own) area *= WallGap(pair, pair + 1);
  return simulation_->wall(w).NormalReaction() / area;
}

template <int Dim>
double LabRun<Dim>::LateralStressError() const {
  const double target = options_.confining_stress_pa;
  if (!(target > 0.0)) return 0.0;
  double error = 0.0;
  for (int w = 2; w < simulation_->wall_count(); ++w)
    error = std::max(error, std::abs(WallStress(w) - target) / target);
  return error;
}

template <int Dim>
void LabRun<Dim>::Consolidate() {
  const double target = options_.confining_stress_pa;
  if (target > 0.0) {
    // Every wall holds sigma_3 until all are within the tolerance for three samples.
    RunOptions run;
    run.max_steps = options_.sample_interval_steps;
    const long step_cap = static_cast<long>(400.0 * transit_s_ / simulation_->time_step_s()) +
                          20L * options_.sample_interval_steps;
    int settled = 0;
    while (settled < 3) {
      simulation_->Run(run);
      double error = 0.0;
      for (int w = 0; w < simulation_->wall_count(); ++w)
        error = std::max(error, std::abs(WallStress(w) - target) / target);
      settled = error <= options_.consolidation_tolerance ? settled + 1 : 0;
      if (simulation_->step() > step_cap)
        throw ComputationError("the confining servo did not bring the walls to " +
                               Number(target) + " Pa within " + std::to_string(step_cap) +
                               " steps (400 wave transits); the largest relative error is " +
                               Number(error) + ": lower servo_gain_fraction or check the material");
      if (options_.progress) options_.progress(-1.0, "consolidating to sigma_3");
    }
    for (int k = 0; k < 2; ++k)
      simulation_->SetWallOptions(k, PlatenDrive(k, simulation_->time_s()));
  }
  load_start_s_ = simulation_->time_s();
}

template <int Dim>
LabCurvePoint LabRun<Dim>::Sample() const {
  const SceneState<Dim>& s = simulation_->state();
  LabCurvePoint p;
  p.step = s.step;
  p.time_s = s.time_s;
  const LabTestKind kind = options_.kind;
  // The stress volume (lab_test.h): the current wall-to-wall volume.
  if (kind == LabTestKind::kPureShear) {
    p.volume_m3 = hull_ ? hull_->volume() : strain_.volume();
  } else if (kind == LabTestKind::kBrazilian) {
    p.volume_m3 = specimen_.domain_volume_m3;
  } else if (WithLateralWalls()) {
    p.volume_m3 = 1.0;
    for (int w = 0; w < simulation_->wall_count(); w += 2) p.volume_m3 *= WallGap(w, w + 1);
  } else {
    p.volume_m3 = WallGap(0, 1) * specimen_.cross_section_m2;
  }
  p.stress_pa = Embed<Dim>(SpecimenStress<Dim>(s, p.volume_m3));
  p.strain = Embed<Dim>(strain_.Strain(s.particles.position)) - strain0_;
  p.axial_stress_pa = -p.stress_pa(axis_, axis_);
  double lateral = 0.0;
  for (int a = 0; a < Dim; ++a)
    if (a != axis_) lateral -= p.stress_pa(a, a) / (Dim - 1);
  p.lateral_stress_pa = lateral;
  if (kind == LabTestKind::kPureShear) {
    const int q = shear_particle_;
    const double moved = s.particles.position[q].x() - packing_.centres[q].x();
    p.boundary_strain = shear_height_ > 0.0 ? 0.5 * moved / shear_height_ : 0.0;
    p.control = p.stress_pa(0, Dim - 1);
  } else {
    p.platen_force_n =
        0.5 * (simulation_->wall(0).NormalReaction() + simulation_->wall(1).NormalReaction());
    p.boundary_strain = (gap0_ - WallGap(0, 1)) / gap0_;
    switch (kind) {
      case LabTestKind::kBrazilian:
        p.control = p.platen_force_n;
        break;
      case LabTestKind::kConfinedCompression:
        p.control = p.axial_stress_pa - p.lateral_stress_pa;
        break;
      case LabTestKind::kIsotropicCompression:
        p.control = -p.stress_pa.trace() / Dim;
        break;
      default:
        p.control = p.axial_stress_pa;
    }
  }
  p.broken_in_tension = s.broken_in_tension;
  p.broken_in_shear = s.broken_in_shear;
  const EnergyBalance e = simulation_->Energy();
  p.kinetic_energy_j = e.kinetic_j;
  p.elastic_energy_j = e.Elastic();
  p.external_work_j = e.ExternalWork();
  p.dissipated_j = e.Dissipated();
  return p;
}

template <int Dim>
void LabRun<Dim>::TrackBrokenBonds(double boundary_strain) {
  const SceneState<Dim>& s = simulation_->state();
  const long total = s.broken_in_tension + s.broken_in_shear;
  if (total == broken_total_) return;
  broken_total_ = total;
  const ContactArrays<Dim>& c = s.contacts;
  auto less = [](const std::pair<std::array<int, 2>, bool>& a, const std::array<int, 2>& b) {
    return a.first < b;
  };
  std::vector<std::pair<std::array<int, 2>, bool>> fresh;
  for (int k = 0; k < c.size(); ++k) {
    const ContactState state = c.state[k];
    if (state != ContactState::kBrokenInTension && state != ContactState::kBrokenInShear) continue;
    const auto it = std::lower_bound(broken_.begin(), broken_.end(), c.pair[k], less);
    if (it != broken_.end() && it->first == c.pair[k]) continue;
    const bool tension = state == ContactState::kBrokenInTension;
    fresh.push_back({c.pair[k], tension});
    BrokenBond b;
    b.pair = c.pair[k];
    b.in_tension = tension;
    b.time_s = s.time_s;
    b.boundary_strain = boundary_strain;
    b.midpoint = Embed<Dim>(Vector<Dim>(0.5 * (s.particles.position[b.pair[0]] +
                                               s.particles.position[b.pair[1]])));
    broken_list_.push_back(b);
  }
  broken_.insert(broken_.end(), fresh.begin(), fresh.end());
  std::sort(broken_.begin(), broken_.end());
}

template <int Dim>
void LabRun<Dim>::Snapshot(const char* label, LabSnapshot* snapshot) const {
  const SceneState<Dim>& s = simulation_->state();
  snapshot->recorded = true;
  snapshot->label = label;
  snapshot->time_s = s.time_s;
  const int count = s.particles.size();
  snapshot->position.resize(count);
  snapshot->displacement.resize(count);
  for (int q = 0; q < count; ++q) {
    snapshot->position[q] = Embed<Dim>(s.particles.position[q]);
    snapshot->displacement[q] = Embed<Dim>(Vector<Dim>(s.particles.position[q] - packing_.centres[q]));
  }
  snapshot->bonds = bonds_;
  snapshot->bond_state.assign(bonds_.size(), ContactState::kBonded);
  // Both lists are sorted by pair: one merge. A bond missing from the contacts has broken
  // and separated beyond the search skin; its recorded mode (or tension) is used.
  const ContactArrays<Dim>& c = s.contacts;
  int k = 0;
  for (size_t b = 0; b < bonds_.size(); ++b) {
    while (k < c.size() && c.pair[k] < bonds_[b]) ++k;
    if (k < c.size() && c.pair[k] == bonds_[b]) {
      snapshot->bond_state[b] = c.state[k];
    } else {
      const auto it = std::lower_bound(
          broken_.begin(), broken_.end(), std::make_pair(bonds_[b], false));
      const bool tension = it == broken_.end() || it->first != bonds_[b] || it->second;
      snapshot->bond_state[b] =
          tension ? ContactState::kBrokenInTension : ContactState::kBrokenInShear;
    }
  }
}

template <int Dim>
LabTestResult LabRun<Dim>::Run() {
  const auto start = std::chrono::steady_clock::now();
  LabTestResult r;
  axis_ = specimen_.axis;
  simulation_ = std::make_unique<Simulation<Dim>>(packing_, BuildScene());
  const ContactArrays<Dim>& contacts = simulation_->contacts();
  for (int k = 0; k < contacts.size(); ++k)
    if (contacts.state[k] == ContactState::kBonded) bonds_.push_back(contacts.pair[k]);
  if (options_.kind != LabTestKind::kPureShear) gap0_ = WallGap(0, 1);
  // The step budget, before any step: the platens' travel to the strain limit at V.
  const double travel_m = strain_limit_ * (gap0_ > 0.0 ? gap0_ : specimen_.height_m);
  const double steps_needed = travel_m / (2.0 * speed_) / simulation_->time_step_s() + ramp_s_ / simulation_->time_step_s();
  if (!(steps_needed <= static_cast<double>(options_.max_steps)))
    throw InputError(StepBudgetRefusal(
        steps_needed, strain_limit_, speed_, simulation_->time_step_s(), options_.max_steps,
        ", or check kn and kt (kt/kn = " +
            Number(material_.tangential_stiffness_n_per_m / material_.normal_stiffness_n_per_m) +
            "; the time step follows the stiffer of the two)"));
  if (Confined()) {
    Consolidate();
    gap0_ = WallGap(0, 1);
    strain0_ = Embed<Dim>(strain_.Strain(simulation_->particles().position));
  }

  // The loading loop: a sample every sample_interval_steps until the control quantity has
  // fallen after its peak (strength tests) or the strain limit is reached.
  const bool strength = IsStrengthTest(options_.kind);
  r.curve.push_back(Sample());
  RunOptions run;
  run.max_steps = options_.sample_interval_steps;
  int best = 0;
  r.termination = LabTermination::kStrainLimit;
  // Quasi-static guard (LabTestOptions::pause_kinetic_energy_ratio): the platens pause while
  // a bond-breaking cascade runs, at most max_pause_samples samples at a time.
  const bool guard = strength && options_.pause_kinetic_energy_ratio > 0.0;
  const double kinetic_limit = options_.pause_kinetic_energy_ratio * AffineKineticEnergy();
  const int max_pause_samples = std::max(
      1, static_cast<int>(std::ceil(options_.max_pause_transits * transit_s_ /
                                    (options_.sample_interval_steps * simulation_->time_step_s()))));
  double speed_factor = 1.0;
  int paused_samples = 0;
  long broken_before = 0;
  // While the platens move, fresh breakage is looked for every quarter sample interval
  // (the run summaries carry the counts): the sooner a cascade holds the platens, the less
  // they load the specimen while it redistributes.
  const int check_steps = std::max(1, options_.sample_interval_steps / 4);
  // The pauses may cost at most four times the time the platens need to reach the strain
  // limit at V: a specimen that keeps breaking bonds without losing its load (grinding
  // fragments) must not stall the test. Past the budget the platens move at V.
  const long pause_budget =
      static_cast<long>(4.0 * strain_limit_ * gap0_ / (2.0 * speed_) / simulation_->time_step_s());
  auto guard_active = [&] {
    return guard && simulation_->time_s() >= load_start_s_ + ramp_s_ &&
           r.paused_steps < pause_budget;
  };
  auto record = [&](const LabCurvePoint& point) {
    r.curve.push_back(point);
    TrackBrokenBonds(point.boundary_strain);
    const int index = static_cast<int>(r.curve.size()) - 1;
    if (point.control > r.curve[best].control) {
      best = index;
      if (options_.record_snapshots) Snapshot("peak", &r.peak_snapshot);
    }
  };
  while (true) {
    for (long done = 0; done < options_.sample_interval_steps;) {
      const bool watch = guard_active() && options_.pause_on_breakage && speed_factor == 1.0;
      run.max_steps = watch ? std::min<long>(check_steps, options_.sample_interval_steps - done)
                            : options_.sample_interval_steps - done;
      const RunSummary summary = simulation_->Run(run);
      r.steps += summary.steps;
      done += summary.steps;
      if (watch && summary.broken_in_tension + summary.broken_in_shear > broken_before) {
        // The state at the hold is a sample of its own: the load is at a local maximum there
        // (the cascade relaxes it), so the peak is not missed between regular samples.
        record(Sample());
        RampPlatenSpeed(0.0);
        speed_factor = 0.0;
        paused_samples = -1;  // counted from the next sample
        ++r.pauses;
      }
    }
    const LabCurvePoint point = Sample();
    record(point);
    if (Confined() && point.time_s >= load_start_s_ + ramp_s_)
      r.confinement_max_error = std::max(r.confinement_max_error, LateralStressError());
    const LabCurvePoint& peak = r.curve[best];
    if (strength && best >= 3 && peak.time_s >= load_start_s_ + ramp_s_ && peak.control > 0.0 &&
        point.control <= options_.post_peak_stress_fraction * peak.control) {
      r.termination = LabTermination::kPostPeak;
      break;
    }
    if (point.boundary_strain >= strain_limit_) break;
    if (r.steps > options_.max_steps)
      throw ComputationError("the test passed its step budget max_steps = " + std::to_string(options_.max_steps) +
                             " at strain " + Number(point.boundary_strain) + " of the limit " + Number(strain_limit_) +
                             " (" + std::to_string(r.pauses) + " quasi-static pauses, " +
                             std::to_string(r.paused_steps) + " paused steps): raise max_steps or the loading rate");
    const long broken_now = point.broken_in_tension + point.broken_in_shear;
    const bool breaking = options_.pause_on_breakage && broken_now > broken_before;
    broken_before = broken_now;
    if (guard_active()) {
      paused_samples = speed_factor == 0.0 ? paused_samples + 1 : 0;
      // Pause on a cascade's kinetic energy or on fresh breakage; while paused, wait for a
      // quiet sample: no new broken bond and the kinetic energy below the affine one.
      const bool unsettled =
          speed_factor == 0.0
              ? breaking || point.kinetic_energy_j > kinetic_limit / options_.pause_kinetic_energy_ratio
              : breaking || point.kinetic_energy_j > kinetic_limit;
      const double target = unsettled && paused_samples < max_pause_samples ? 0.0 : 1.0;
      if (target != speed_factor) {
        RampPlatenSpeed(target);
        speed_factor = target;
        if (target == 0.0) ++r.pauses;
      }
      if (speed_factor == 0.0) r.paused_steps += options_.sample_interval_steps;
    } else if (guard && speed_factor == 0.0) {  // the pause budget is spent
      RampPlatenSpeed(1.0);
      speed_factor = 1.0;
      guard_budget_spent_ = true;
    }
    if (options_.progress)
      options_.progress(std::clamp(point.boundary_strain / strain_limit_, 0.0, 1.0),
                        std::string(LabTestKindName(options_.kind)) + ": strain " +
                            Number(point.boundary_strain, 3) + ", control " +
                            Number(point.control, 4) + ", broken bonds " +
                            std::to_string(point.broken_in_tension + point.broken_in_shear));
  }
  if (options_.record_snapshots) Snapshot("end", &r.end_snapshot);
  r.stages = simulation_->last_summary().stages;
  r.energy = simulation_->Energy();
  r.broken_in_tension = simulation_->state().broken_in_tension;
  r.broken_in_shear = simulation_->state().broken_in_shear;
  r.broken_bonds = broken_list_;
  r.bonds = static_cast<int>(bonds_.size());
  r.time_step_s = simulation_->time_step_s();
  r.critical_time_step_s = simulation_->critical_time_step().critical_time_step_s;
  r.mass_scaling = simulation_->particles().mass_scaling;
  r.simulated_time_s = simulation_->time_s();
  r.strain_limit = strain_limit_;
  r.strain_cells = strain_.cell_count();
  Measure(&r);
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

template <int Dim>
void LabRun<Dim>::Measure(LabTestResult* r) const {
  const LabTestOptions& o = options_;
  const CurvePeak peak = FindPeak(r->curve, o.post_peak_stress_fraction);
  const bool strength = IsStrengthTest(o.kind);
  r->peak_reached = strength && r->termination == LabTermination::kPostPeak;
  const LabCurvePoint& at_peak = r->curve[peak.index];
  r->peak_control = at_peak.control;
  r->peak_stress_pa = at_peak.axial_stress_pa;
  r->strain_at_peak = -at_peak.strain(axis_, axis_);
  r->boundary_strain_at_peak = at_peak.boundary_strain;
  r->peak_force_n = at_peak.platen_force_n;
  r->confining_stress_pa = Confined() ? o.confining_stress_pa : 0.0;
  switch (o.kind) {
    case LabTestKind::kBrazilian:
      // Labra (4.38): sigma_t = 2 F / (pi D t); 2D: F per unit thickness, t = 1 m; over a
      // loading arc the centre's stress, Hondros's k times it.
      r->tensile_strength_factor = HondrosFactor(Jaws() ? o.loading_arc_deg : 0.0);
      r->loading_arc_deg = Jaws() ? o.loading_arc_deg : 0.0;
      r->tensile_strength_pa = r->tensile_strength_factor * 2.0 * at_peak.platen_force_n /
                               (kPi * specimen_.width_m * specimen_.thickness_m);
      r->peak_stress_pa = r->tensile_strength_pa;
      break;
    case LabTestKind::kIsotropicCompression:
      r->bulk_modulus_pa = SecantBulkModulus<Dim>(r->curve, peak, o.modulus_window_low,
                                                  o.modulus_window_high);
      r->peak_stress_pa = at_peak.control;
      break;
    case LabTestKind::kPureShear:
      r->shear_modulus_pa = SecantShearModulus<Dim>(r->curve, peak, o.modulus_window_low,
                                                    o.modulus_window_high);
      r->peak_stress_pa = at_peak.control;
      r->strain_at_peak = at_peak.strain(0, Dim - 1);
      break;
    default:
      r->elastic = SecantElasticConstants<Dim>(r->curve, peak, axis_, o.modulus_window_low,
                                               o.modulus_window_high);
      r->linear_elastic = LinearPortionElasticConstants<Dim>(r->curve, axis_, o.linear_portion_low);
  }
  std::ostringstream m;
  if (r->termination == LabTermination::kPostPeak) {
    m << "the control quantity fell to " << Number(100 * o.post_peak_stress_fraction, 3)
      << " % of its peak (" << Number(peak.control) << ") at strain "
      << Number(r->curve.back().boundary_strain, 4);
  } else if (strength) {
    m << "reached the strain limit " << Number(strain_limit_) << " without a peak: the largest "
      << "control value " << Number(peak.control) << " (at strain "
      << Number(at_peak.boundary_strain, 4) << ") never fell to "
      << Number(100 * o.post_peak_stress_fraction, 3)
      << " % of itself; raise strain_limit or check the bond strengths";
  } else {
    m << "reached the strain limit " << Number(strain_limit_);
  }
  if (guard_budget_spent_)
    m << " (the quasi-static guard spent its pause budget, " << r->paused_steps
      << " steps, and the platens moved on at constant speed)";
  r->termination_message = m.str();
}

}  // namespace

template <int Dim>
double WaveSpeedScale(const MaterialParameters& material, double mean_radius_m) {
  const double kn = material.normal_stiffness_n_per_m, rho = material.density_kg_per_m3;
  return Dim == 2 ? std::sqrt(kn / rho) : std::sqrt(kn / (rho * mean_radius_m));
}

template <int Dim>
LabTestResult RunLabTestAtSpeed(const Packing<Dim>& packing, const LabSpecimen<Dim>& specimen,
                                const MaterialParameters& material,
                                const LabTestOptions& options, double speed,
                                double strain_limit) {
  LabRun<Dim> run(packing, specimen, material, options, speed, strain_limit);
  return run.Run();
}

template double WaveSpeedScale<2>(const MaterialParameters&, double);
template double WaveSpeedScale<3>(const MaterialParameters&, double);
template LabTestResult RunLabTestAtSpeed<2>(const Packing<2>&, const LabSpecimen<2>&,
                                            const MaterialParameters&, const LabTestOptions&,
                                            double, double);
template LabTestResult RunLabTestAtSpeed<3>(const Packing<3>&, const LabSpecimen<3>&,
                                            const MaterialParameters&, const LabTestOptions&,
                                            double, double);

}  // namespace specimen
