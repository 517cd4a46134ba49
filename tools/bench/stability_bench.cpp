// stability-bench: predicted against measured stability limits for one packing and one
// parameter set ("stiff and extreme cases"). tools/bench/stability_bench.py runs it
// over the grid and prints the table.
//
// Sample runs:
//   stability-bench --packing out/packing.packing --kn 7e10 --mode dt
//   stability-bench --packing p.packing --kn 7e10 --kt-ratio 1 --kn-over-ep 0.35 --nu-p 0.45
//   stability-bench --packing p.packing --kn 7e10 --walls top,bottom --wall-factor 10
//   stability-bench --packing p.packing --kn 7e10 --nu-p 0.49 --mode ep --steps 20000
//
// Measured = bisection with real solver runs (Simulation, undamped): the specimen starts with
// random velocities (and spins when kt > 0) of every particle, and a run is stable when the
// solver's divergence guard (kinetic energy above energy_growth_factor x the energy supplied,
// or a contact force beyond the force such energy could hold, or NaN) does not fire within
// --steps steps. Walls (--walls) are planes at the packing's bounding box, pressed in
// quasi-statically by --wall-preload mean radii, once per press-in duration of
// --wall-ramp-steps (the worst counts: impacts make the limit depend on it); with walls a
// run also fails when a loaded wall contact chatters (see Bounded()).
//  --mode dt: bisection on the time step, with kn/Ep as given (or rigid particles);
//  --mode ep: bisection on kn/(Ep l) at the time step --ep-step-fraction x dt_cr(DEM);
//  --mode scan: runs at fractions --scan .. --scan-high of the linear certified step (walls:
//    impacts make the bounded/unbounded boundary non-monotonic in the step).
// Prints one JSON object: the prediction (certified and Ritz), the bracket, the ratio
// predicted / largest stable value, the runs, the times.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "common/error.h"
#include "generator/packing_io.h"
#include "solver/regular_lattice.h"
#include "solver/simulation.h"
#include "stability/stability_analysis.h"
#include "tools/command_line.h"

namespace specimen {
namespace {

struct Settings {
  std::string packing;
  double kn = 7e10, kt_ratio = 0.0, density = 2000.0;
  double kn_over_ep = 0.0;           // 0: rigid
  double kn_over_ep_fraction = 0.0;  // > 0: kn/Ep = this x the packing's admissible value
  double nu_p = 0.35;
  double damping = 0.0, dashpot = 0.0;
  std::string plane = "strain";
  std::string walls;
  double wall_factor = 10.0, wall_preload = 1e-3;
  std::vector<long> wall_ramp_steps = {4000, 8000, 16000};
  double kinetic_growth = 1e4;
  int chatter_openings = 10;
  long chatter_window = 100;
  double chatter_preload = 10.0;
  std::string mode = "dt";
  long steps = 5000;
  double tolerance = 0.002;
  double growth = 1e6;
  double ep_step_fraction = 0.25;
  double scan_low = 0.8, scan_high = 1.02, scan_step = 0.01;
  double velocity = 1e-3;
  std::uint64_t seed = 1;
  int threads = 1;
  std::string write_lattices;
};

// The scene of the runs, or (`for_analysis`) that of the prediction: the same, with the walls
// at their pressed-in position and counting only the particles they then touch (gap <= 0),
// which are exactly the wall contacts of the loaded runs.
template <int Dim>
SceneOptions<Dim> BuildScene(const Settings& s, const Packing<Dim>& packing, double kn_over_ep,
                             bool for_analysis = false) {
  SceneOptions<Dim> scene;
  MaterialParameters& m = scene.material;
  m.normal_stiffness_n_per_m = s.kn;
  m.tangential_stiffness_n_per_m = s.kt_ratio * s.kn;
  m.density_kg_per_m3 = s.density;
  m.particle_poisson_ratio = s.nu_p;
  m.plane_model = s.plane == "stress" ? PlaneModel::kPlaneStress : PlaneModel::kPlaneStrain;
  m.translational_damping = m.rotational_damping = s.damping;
  m.normal_dashpot_ratio = m.tangential_dashpot_ratio = s.dashpot;
  const double length = Dim == 2 ? 1.0 : VolumeMeanRadius<Dim>(packing.radii);
  if (kn_over_ep > 0.0) m.particle_youngs_modulus_pa = s.kn / (kn_over_ep * length);
  scene.num_threads = s.threads;
  scene.divergence.energy_growth_factor = s.growth;
  scene.time_step.allow_above_critical = true;
  scene.time_step.from_stability_analysis = false;  // the step is given; no analysis per run
  if (!s.walls.empty()) {
    Vector<Dim> lower = packing.centres[0], upper = packing.centres[0];
    for (int p = 0; p < packing.size(); ++p)
      for (int a = 0; a < Dim; ++a) {
        lower[a] = std::min(lower[a], packing.centres[p][a] - packing.radii[p]);
        upper[a] = std::max(upper[a], packing.centres[p][a] + packing.radii[p]);
      }
    const double preload = s.wall_preload * VolumeMeanRadius<Dim>(packing.radii);
    std::stringstream list(s.walls);
    std::string side;
    while (std::getline(list, side, ',')) {
      const char* names[] = {"left", "right", "bottom", "top", "back", "front"};
      int index = -1;
      for (int k = 0; k < 2 * Dim; ++k)
        if (side == names[k]) index = k;
      if (index < 0) throw InputError("--walls: unknown side '" + side + "'");
      const int axis = index / 2;
      const bool high = index % 2 == 1;
      WallOptions<Dim> w;
      w.name = side;
      w.normal = Vector<Dim>::Zero();
      w.normal[axis] = high ? -1.0 : 1.0;
      w.point = Vector<Dim>::Zero();
      // The wall starts touching the outermost particles and is pressed in by `preload`
      // along a smooth velocity pulse (Bounded() sets the pulse's duration).
      w.point[axis] = high ? upper[axis] : lower[axis];
      w.velocity = preload * w.normal;  // times the pulse amplitude [1/s]
      if (for_analysis) w.point += preload * w.normal;
      w.normal_stiffness_n_per_m = s.wall_factor * s.kn;
      scene.walls.push_back(w);
    }
    if (for_analysis) scene.contacts.bond_gap_tolerance = 0.0;
  }
  return scene;
}

// A loaded wall contact that opens and closes again and again (an impact oscillator): the
// kinetic energy may stay within --kinetic-growth while it chatters (the impacts limit the
// amplitude), so it is counted as a failure on its own. Counted: contacts whose force at the
// end of the press-in exceeds --chatter-preload x the largest change of their force over the
// first 100 steps after the perturbation (they cannot open at the perturbation's amplitude:
// it must have grown) and that then open --chatter-openings times within --chatter-window
// steps (every few steps: an oscillation near the top frequency) with a peak force between
// the openings above their force after the press-in (a grown oscillation, not a contact that
// a slow settling unloaded to the perturbation's level).
template <int Dim>
class ChatterMonitor {
 public:
  ChatterMonitor(const Settings& s, const Simulation<Dim>& simulation)
      : settings_(s), simulation_(simulation) {
    for (int w = 0; w < simulation.wall_count(); ++w) {
      const WallState<Dim>& wall = simulation.wall(w);
      for (size_t k = 0; k < wall.particle.size(); ++k)
        if (wall.normal_elastic_force[k] < 0.0)
          tracks_[Key(w, wall.particle[k])].preload = -wall.normal_elastic_force[k];
    }
  }
  // After every step: "" or the failure.
  std::string Observe() {
    ++steps_;
    for (int w = 0; w < simulation_.wall_count(); ++w) {
      const WallState<Dim>& wall = simulation_.wall(w);
      for (size_t k = 0; k < wall.particle.size(); ++k) {
        auto found = tracks_.find(Key(w, wall.particle[k]));
        if (found == tracks_.end()) continue;
        Track& t = found->second;
        const double force = -wall.normal_elastic_force[k];
        if (steps_ <= 100) t.initial_change = std::max(t.initial_change, std::abs(force - t.preload));
        const bool closed = force > 0.0;
        t.peak = std::max(t.peak, force);
        if (t.closed && !closed) {
          t.openings.push_back(steps_);
          t.peaks.push_back(t.peak);
          t.peak = 0.0;
        }
        t.closed = closed;
        const size_t n = t.openings.size(), count = settings_.chatter_openings;
        if (n >= count && steps_ - t.openings[n - count] <= settings_.chatter_window &&
            t.preload > settings_.chatter_preload * t.initial_change &&
            *std::max_element(t.peaks.end() - count, t.peaks.end()) > t.preload)
          return "chatter: the contact of wall " + std::to_string(w) + " with particle " +
                 std::to_string(wall.particle[k]) + " (force " + std::to_string(t.preload) +
                 " N after the press-in, peak " +
                 std::to_string(*std::max_element(t.peaks.end() - count, t.peaks.end())) +
                 " N) opened " + std::to_string(count) + " times within " +
                 std::to_string(steps_ - t.openings[n - count]) + " steps, by step " +
                 std::to_string(steps_);
      }
    }
    return "";
  }

 private:
  struct Track {
    double preload = 0.0, initial_change = 0.0;
    bool closed = true;
    std::vector<long> openings;  // steps of the openings
    std::vector<double> peaks;   // the largest force before each opening
    double peak = 0.0;
  };
  static long long Key(int wall, int particle) {
    return static_cast<long long>(wall) << 32 | static_cast<unsigned>(particle);
  }
  const Settings& settings_;
  const Simulation<Dim>& simulation_;
  std::map<long long, Track> tracks_;
  long steps_ = 0;
};

// One undamped run: true when bounded over the steps. Without walls: the solver's divergence
// guard decides. With walls, which hold only in compression, the walls are first pressed in by
// a smooth velocity pulse over `ramp` steps (quasi-static: the wall contacts stay closed,
// and the loaded scene is the linear system the analysis describes); the run is then unstable
// when the kinetic energy grows by --kinetic-growth over its level just after the ramp (long
// before the oscillation could open a preloaded contact), a loaded wall contact chatters
// (ChatterMonitor) or the solver's guard fires.
template <int Dim>
bool BoundedOnce(const Settings& s, const Packing<Dim>& packing, SceneOptions<Dim> scene,
                 double time_step, long ramp, std::string* failure) {
  scene.time_step.time_step_s = time_step;
  const double ramp_s = ramp * time_step;
  for (WallOptions<Dim>& w : scene.walls) {
    // Velocity pulse 0 -> 2/T -> 0 over T: the wall moves in by `preload` in total.
    w.velocity_amplitude.points = {{0.0, 0.0}, {0.5 * ramp_s, 2.0 / ramp_s}, {ramp_s, 0.0}};
  }
  Simulation<Dim> simulation(packing, scene);
  // The perturbation: random velocities (and spins when kt > 0), added to the current ones.
  auto perturb = [&]() {
    std::mt19937_64 engine(s.seed);
    std::normal_distribution<double> gaussian(0.0, 1.0);
    for (int p = 0; p < packing.size(); ++p) {
      Vector<Dim> v = simulation.particles().velocity[p];
      for (int a = 0; a < Dim; ++a) v[a] += s.velocity * gaussian(engine);
      simulation.SetVelocity(p, v);
      if (s.kt_ratio > 0.0) {
        Angular<Dim> w = simulation.particles().angular_velocity[p];
        if constexpr (Dim == 2) {
          w += s.velocity / packing.radii[p] * gaussian(engine);
        } else {
          for (int a = 0; a < 3; ++a) w[a] += s.velocity / packing.radii[p] * gaussian(engine);
        }
        simulation.SetAngularVelocity(p, w);
      }
    }
  };
  try {
    RunOptions run;
    if (ramp == 0) {
      perturb();
      run.max_steps = s.steps;
      simulation.Run(run);
      return true;
    }
    // Walls: a smooth press-in from rest first (a perturbation during it would make the
    // lightly loaded wall contacts chatter: impacts, outside the linear analysis), then the
    // perturbation of the loaded state.
    run.max_steps = ramp;
    simulation.Run(run);
    ChatterMonitor<Dim> chatter(s, simulation);
    std::string chattered;
    run.observe_interval = 1;
    run.observer = [&] {
      if (chattered.empty()) chattered = chatter.Observe();
    };
    perturb();
    const long chunk = 100;
    double reference = 0.0;
    for (long done = 0; done < s.steps; done += chunk) {
      run.max_steps = chunk;
      simulation.Run(run);
      if (!chattered.empty()) {
        if (failure) *failure = chattered + " (press-in of " + std::to_string(ramp) + " steps)";
        return false;
      }
      const double kinetic = simulation.Energy().kinetic_j;
      if (done < 5 * chunk) {
        reference = std::max(reference, kinetic);
      } else if (kinetic > s.kinetic_growth * reference) {
        if (failure)
          *failure = "kinetic energy grew " + std::to_string(kinetic / reference) +
                     " times after the wall ramp, at step " + std::to_string(ramp + done + chunk);
        return false;
      }
    }
  } catch (const ComputationError& e) {
    if (failure) *failure = e.what();
    return false;
  }
  return true;
}

// Bounded for every press-in duration (--wall-ramp-steps; one run without walls).
template <int Dim>
bool Bounded(const Settings& s, const Packing<Dim>& packing, const SceneOptions<Dim>& scene,
             double time_step, std::string* failure) {
  if (scene.walls.empty()) return BoundedOnce<Dim>(s, packing, scene, time_step, 0, failure);
  for (const long ramp : s.wall_ramp_steps)
    if (!BoundedOnce<Dim>(s, packing, scene, time_step, ramp, failure)) return false;
  return true;
}

template <int Dim>
int Run(const Settings& s) {
  const Packing<Dim> packing = LoadPacking<Dim>(s.packing);
  const auto start = std::chrono::steady_clock::now();
  StabilityOptions options;
  options.locate_mode = true;
  nlohmann::json out;
  out["packing"] = s.packing;
  out["particles"] = packing.size();
  out["mode"] = s.mode;
  out["kn"] = s.kn;
  out["kt_ratio"] = s.kt_ratio;
  out["nu_p"] = s.nu_p;
  out["walls"] = s.walls;
  out["damping"] = s.damping;
  out["dashpot"] = s.dashpot;
  out["wall_factor"] = s.wall_factor;
  out["steps"] = s.steps;
  double min_r = packing.radii[0], max_r = packing.radii[0];
  for (double r : packing.radii) {
    min_r = std::min(min_r, r);
    max_r = std::max(max_r, r);
  }
  out["radius_ratio"] = max_r / min_r;
  out["min_radius_m"] = min_r;
  nlohmann::json runs = nlohmann::json::array();

  double kn_over_ep = s.kn_over_ep;
  if (s.kn_over_ep_fraction > 0.0) {
    const StabilitySummary rigid =
        AnalyseStability<Dim>(packing, BuildScene<Dim>(s, packing, 0.0), options);
    kn_over_ep = s.kn_over_ep_fraction * s.kn /
                 (rigid.group_length_m * rigid.convergence_eigenvalue.ritz_value);
  }
  out["kn_over_ep"] = kn_over_ep;
  out["kn_over_ep_fraction"] = s.kn_over_ep_fraction;
  if (s.mode == "dt") {
    const SceneOptions<Dim> scene = BuildScene<Dim>(s, packing, kn_over_ep);
    const StabilitySummary summary =
        AnalyseStability<Dim>(packing, BuildScene<Dim>(s, packing, kn_over_ep, true), options);
    out["analysis"] = summary.ToJson();
    const double predicted = summary.critical_time_step_s;
    const double sharp = summary.ddem_time_step_available ? summary.ddem_time_step_ritz_s
                                                          : summary.dem_time_step_ritz_s;
    out["predicted"] = predicted;
    out["predicted_ritz"] = sharp;
    double low = 0.95 * sharp, high = 1.05 * sharp;
    auto probe = [&](double dt) {
      std::string failure;
      const bool ok = Bounded<Dim>(s, packing, scene, dt, &failure);
      runs.push_back({{"value", dt}, {"bounded", ok}, {"failure", failure.substr(0, 160)}});
      return ok;
    };
    while (!probe(low)) low *= 0.9;
    while (probe(high)) high *= 1.1;
    while ((high - low) / low > s.tolerance) {
      const double middle = 0.5 * (low + high);
      if (probe(middle))
        low = middle;
      else
        high = middle;
    }
    out["measured_stable"] = low;
    out["measured_unstable"] = high;
    out["ratio"] = predicted / low;
    out["ratio_ritz"] = sharp / low;
  } else if (s.mode == "ep") {
    // The time step: a fraction of the DEM limit, held for every probe.
    SceneOptions<Dim> rigid = BuildScene<Dim>(s, packing, 0.0);
    const StabilitySummary dem = AnalyseStability<Dim>(packing, rigid, options);
    const double dt = s.ep_step_fraction * dem.dem_critical_time_step_s;
    const double predicted = dem.admissible_kn_over_ep;
    const double sharp = s.kn / (dem.group_length_m * dem.convergence_eigenvalue.ritz_value);
    out["analysis"] = dem.ToJson();
    out["time_step_s"] = dt;
    out["predicted"] = predicted;
    out["predicted_ritz"] = sharp;
    auto probe = [&](double x) {
      std::string failure;
      const bool ok = Bounded<Dim>(s, packing, BuildScene<Dim>(s, packing, x), dt, &failure);
      runs.push_back({{"value", x}, {"bounded", ok}, {"failure", failure.substr(0, 160)}});
      return ok;
    };
    double low = 0.95 * sharp, high = 1.05 * sharp;
    while (!probe(low)) low *= 0.9;
    while (probe(high)) high *= 1.1;
    while ((high - low) / low > s.tolerance) {
      const double middle = 0.5 * (low + high);
      if (probe(middle))
        low = middle;
      else
        high = middle;
    }
    out["measured_stable"] = low;
    out["measured_unstable"] = high;
    out["ratio"] = predicted / low;
    out["ratio_ritz"] = sharp / low;
  } else if (s.mode == "scan") {
    // Bounded or not at fractions of the linear certified step, from scan_high down to
    // scan_low (contacts that open and close make the limit non-monotonic: a bisection would
    // not see it). Measured = the largest probed step below which every probe was bounded.
    const SceneOptions<Dim> scene = BuildScene<Dim>(s, packing, kn_over_ep);
    const StabilitySummary summary =
        AnalyseStability<Dim>(packing, BuildScene<Dim>(s, packing, kn_over_ep, true), options);
    out["analysis"] = summary.ToJson();
    const double linear = summary.linear_critical_time_step_s;
    out["predicted"] = summary.critical_time_step_s;
    out["predicted_ritz"] = summary.ddem_time_step_available ? summary.ddem_time_step_ritz_s
                                                             : summary.dem_time_step_ritz_s;
    out["linear_predicted"] = linear;
    double lowest_failure = 0.0;
    std::vector<double> fractions;
    for (double f = s.scan_high; f >= s.scan_low - 1e-9; f -= s.scan_step) fractions.push_back(f);
    for (const double fraction : fractions) {
      std::string failure;
      const bool ok = Bounded<Dim>(s, packing, scene, fraction * linear, &failure);
      runs.push_back({{"value", fraction * linear}, {"fraction", fraction}, {"bounded", ok},
                      {"failure", failure.substr(0, 160)}});
      if (!ok) lowest_failure = fraction;
    }
    double stable = fractions.back();
    for (const double fraction : fractions)
      if (fraction < lowest_failure || lowest_failure == 0.0) {
        stable = fraction;
        break;
      }
    out["lowest_failing_fraction"] = lowest_failure;
    out["measured_stable"] = stable * linear;
    out["measured_unstable"] = lowest_failure * linear;  // 0: none failed
    out["ratio"] = summary.critical_time_step_s / (stable * linear);
    out["ratio_ritz"] = out["predicted_ritz"].get<double>() / (stable * linear);
  } else {
    throw InputError("--mode '" + s.mode + "' is not allowed: use dt, ep or scan");
  }
  out["runs"] = runs;
  out["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << out.dump() << "\n";
  return kExitOk;
}

}  // namespace
}  // namespace specimen

int main(int argc, char** argv) {
  using namespace specimen;
  CLI::App app{"stability-bench: predicted against bisected stability limits"};
  Settings s;
  app.add_option("--packing", s.packing, "packing file");
  app.add_option("--write-lattices", s.write_lattices,
                 "write Madan's SC 9x20 and HCP 110-disc specimens (R = 1 mm) into this "
                 "directory as sc_9x20.packing and hcp_110.packing, and stop");
  app.add_option("--kn", s.kn, "normal stiffness [N/m]");
  app.add_option("--kt-ratio", s.kt_ratio, "kt / kn");
  app.add_option("--density", s.density, "particle density [kg/m^3]");
  app.add_option("--kn-over-ep", s.kn_over_ep, "kn/(Ep l) (3D: kn/(Ep R_mean)); 0: rigid");
  app.add_option("--kn-over-ep-fraction", s.kn_over_ep_fraction,
                 "kn/(Ep l) as this fraction of the packing's limit rho(B) = 1 (Ritz value)");
  app.add_option("--nu-p", s.nu_p, "particle Poisson ratio");
  app.add_option("--plane", s.plane, "strain | stress");
  app.add_option("--damping", s.damping, "local damping alpha_t = alpha_r");
  app.add_option("--dashpot", s.dashpot, "contact dashpot ratio xi_n = xi_t");
  app.add_option("--walls", s.walls, "comma-separated sides: left,right,bottom,top,back,front");
  app.add_option("--wall-factor", s.wall_factor, "wall stiffness / kn");
  app.add_option("--wall-preload", s.wall_preload, "wall press-in in mean radii");
  app.add_option("--wall-ramp-steps", s.wall_ramp_steps,
                 "steps of the wall press-in pulse, one run per value (the worst counts)");
  app.add_option("--chatter-openings", s.chatter_openings,
                 "with walls: a loaded wall contact opening this often is a failure");
  app.add_option("--chatter-window", s.chatter_window,
                 "with walls: ... within this many steps");
  app.add_option("--chatter-preload", s.chatter_preload,
                 "with walls: counted contacts carry this x their initial force change");
  app.add_option("--kinetic-growth", s.kinetic_growth,
                 "with walls: unstable when the kinetic energy grows by this factor");
  app.add_option("--mode", s.mode, "dt | ep");
  app.add_option("--steps", s.steps, "steps per run");
  app.add_option("--tolerance", s.tolerance, "relative width of the final bracket");
  app.add_option("--growth", s.growth, "energy growth factor of the divergence guard");
  app.add_option("--ep-step-fraction", s.ep_step_fraction, "--mode ep: dt / dt_cr(DEM)");
  app.add_option("--scan", s.scan_low, "--mode scan: lowest fraction of the certified step");
  app.add_option("--scan-high", s.scan_high, "--mode scan: highest fraction");
  app.add_option("--scan-step", s.scan_step, "--mode scan: fraction decrement");
  app.add_option("--velocity", s.velocity, "random initial speed scale [m/s]");
  app.add_option("--seed", s.seed, "seed of the initial velocities");
  app.add_option("--threads", s.threads, "solver threads");
  CLI11_PARSE(app, argc, argv);
  if (!s.write_lattices.empty())
    return RunCommand("stability-bench", [&] {
      SavePacking<2>(SquareLatticePacking(9, 20, 1e-3), s.write_lattices + "/sc_9x20.packing");
      SavePacking<2>(HexagonalLatticePacking(17, 6, 7, 1e-3),
                     s.write_lattices + "/hcp_110.packing");
      return static_cast<int>(kExitOk);
    });
  if (s.packing.empty()) {
    std::cerr << "stability-bench: error: give --packing\n";
    return kExitBadInput;
  }
  return RunCommand("stability-bench",
                    [&] { return ReadPackingDimension(s.packing) == 2 ? Run<2>(s) : Run<3>(s); });
}
