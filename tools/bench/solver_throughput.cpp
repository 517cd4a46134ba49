// solver-throughput: the speed benchmark of the solver core ("Speed").
//
//   solver-throughput --packing bench-out/solver/specimens/sphere3d_30k.packing
//                     [--model rigid|ddem|both|moment] [--threads 2] [--steps 2000] [--warmup 100]
//
// Loads a packing written by generate-packing, bonds it (the packing's contact pairs), puts
// it between two velocity-driven platens across its last axis (y in 2D, z in 3D: the lower
// platen fixed, the upper one moving down slowly), and times Simulation::Run over --steps
// steps after --warmup steps. Reported: particle-steps per second of the stepping loop only
// (RunSummary::wall_seconds: no construction, no file reading), bytes of solver arrays per
// particle (RunSummary::memory_bytes), the stages that ran and those left out, and one JSON
// line per model ("RESULT {...}") for tools/bench/solver_bench.py.
//
// --model both builds the rigid and the DDEM scene side by side and runs them in alternating
// chunks of --chunk steps (the order alternating too), so that both see the same machine:
// the DDEM overhead (rigid rate / DDEM rate - 1) is then a paired measurement, robust on a
// busy machine; its median over the chunk pairs is reported next to the ratio of totals.
// --model moment does the same for rigid particles with and without moment-carrying bonds
// (--bond-radius-ratio, solver/bond_moment.h): the cost of the bond moments.
//
// The scene is the workload of a bonded virtual test, and the one Yade is given in
// solver_bench.py: linear normal and tangential springs (kt = kt_ratio kn), bonds with a
// finite but unreachable strength (the failure check runs, nothing breaks), Coulomb friction
// on unbonded contacts, rotation, non-viscous local damping 0.1, two walls, the neighbour
// search on. DDEM adds deformable particles (Ep, nu_p = 0.2); kn is set from Ep so that the
// strain-lag ratio stays small (kn = 0.2 Ep l in 2D, 0.2 Ep R_min in 3D) and the rigid scene
// uses the same kn and time step (DDEM's default, with its lag factor): the two differ by the
// DDEM stages only.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/format.h"
#include "generator/packing_io.h"
#include "solver/simulation.h"
#include "tools/command_line.h"

namespace specimen {
namespace {

struct BenchOptions {
  std::string packing;
  std::string model = "rigid";  // rigid, ddem, both (rigid and DDEM) or moment (rigid and
                                // rigid with moment-carrying bonds)
  double bond_radius_ratio = 1.0;  // lambda of the moment variant
  int threads = 1;
  long steps = 2000;
  long warmup = 100;
  long chunk = 20;                  // --model both, moment: steps per alternation
  double youngs_modulus_pa = 1e10;  // Ep: sets kn (see the header) in both variants
  double kt_ratio = 0.5;
  double damping = 0.1;
  double friction = 0.5;
  // Platen speed in mean radii per 1000 steps (a slow compression on the scale of the run).
  double platen_speed = 0.02;
  bool quiet = false;
  bool step_times = false;
  std::string dump;
};

double ProcessCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t m = values.size() / 2;
  return values.size() % 2 ? values[m] : 0.5 * (values[m - 1] + values[m]);
}

template <int Dim>
struct Specimen {
  Packing<Dim> packing;
  int count = 0;
  double r_mean = 0.0, r_min = 0.0, lower = 0.0, upper = 0.0;
  double load_seconds = 0.0;

  explicit Specimen(const std::string& path) : packing(LoadPacking<Dim>(path)) {
    count = packing.size();
    r_mean = VolumeMeanRadius<Dim>(packing.radii);
    r_min = *std::min_element(packing.radii.begin(), packing.radii.end());
    lower = std::numeric_limits<double>::infinity();
    upper = -lower;
    for (int q = 0; q < count; ++q) {
      lower = std::min(lower, packing.centres[q][Dim - 1] - packing.radii[q]);
      upper = std::max(upper, packing.centres[q][Dim - 1] + packing.radii[q]);
    }
  }
};

// The variants a run compares.
enum class Variant { kRigid, kDdem, kMoment };

const char* VariantName(Variant v) {
  return v == Variant::kRigid ? "rigid" : v == Variant::kDdem ? "ddem" : "moment";
}

template <int Dim>
SceneOptions<Dim> BenchScene(const Specimen<Dim>& sp, const BenchOptions& o, Variant variant,
                             double time_step) {
  const bool deformable = variant == Variant::kDdem;
  constexpr int kAxis = Dim - 1;
  SceneOptions<Dim> scene;
  MaterialParameters& m = scene.material;
  const double kn = Dim == 2 ? 0.2 * o.youngs_modulus_pa : 0.2 * o.youngs_modulus_pa * sp.r_min;
  m.normal_stiffness_n_per_m = kn;
  m.tangential_stiffness_n_per_m = o.kt_ratio * kn;
  m.bond_tensile_strength_n = 1e30;  // the failure check runs; nothing breaks
  m.bond_shear_strength_n = 1e30;
  m.friction_coefficient = o.friction;
  m.density_kg_per_m3 = 2600;
  m.translational_damping = o.damping;
  m.rotational_damping = o.damping;
  if (variant == Variant::kMoment) m.bond_radius_ratio = o.bond_radius_ratio;
  if (deformable) {
    m.particle_youngs_modulus_pa = o.youngs_modulus_pa;
    m.particle_poisson_ratio = 0.2;
  }
  scene.num_threads = o.threads;
  WallOptions<Dim> bottom;
  bottom.name = "lower platen";
  bottom.point[kAxis] = sp.lower;
  bottom.normal[kAxis] = 1.0;
  bottom.normal_stiffness_n_per_m = kn;
  WallOptions<Dim> top = bottom;
  top.name = "upper platen";
  top.point[kAxis] = sp.upper;
  top.normal[kAxis] = -1.0;
  if (time_step > 0.0) top.velocity[kAxis] = -o.platen_speed * sp.r_mean / (1000.0 * time_step);
  scene.walls = {bottom, top};
  scene.time_step.time_step_s = time_step;
  return scene;
}

// One model's scene, built and warmed up, and what its timed steps measured.
template <int Dim>
struct Measured {
  Variant variant = Variant::kRigid;
  std::unique_ptr<Simulation<Dim>> simulation;
  double build_seconds = 0.0;
  double seconds = 0.0;      // sum of RunSummary::wall_seconds of the timed runs
  double cpu_seconds = 0.0;  // process CPU time over the timed runs (all threads)
  long steps = 0;
  std::vector<double> chunk_seconds;  // --model both, moment: per chunk
  std::vector<double> step_seconds;   // --step-times
  RunSummary last;
};

template <int Dim>
void TimedRun(Measured<Dim>& m, long steps, bool step_times) {
  RunOptions run;
  run.max_steps = steps;
  auto last = std::chrono::steady_clock::now();
  if (step_times) {
    run.observe_interval = 1;
    run.observer = [&]() {
      const auto now = std::chrono::steady_clock::now();
      m.step_seconds.push_back(std::chrono::duration<double>(now - last).count());
      last = now;
    };
  }
  last = std::chrono::steady_clock::now();
  const double cpu_start = ProcessCpuSeconds();
  m.last = m.simulation->Run(run);
  m.cpu_seconds += ProcessCpuSeconds() - cpu_start;
  m.seconds += m.last.wall_seconds;
  m.steps += m.last.steps;
}

template <int Dim>
nlohmann::json Record(const Specimen<Dim>& sp, const BenchOptions& o, const Measured<Dim>& m) {
  const Simulation<Dim>& simulation = *m.simulation;
  const RunSummary& summary = m.last;
  const int n = sp.count;
  const double rate = m.seconds > 0.0 ? static_cast<double>(m.steps) * n / m.seconds : 0.0;
  // A fingerprint of the final state (packing order, so comparable across builds): changes
  // that keep the arithmetic give the same digits, others differ at round-off level.
  double position_sum = 0.0, speed_sum = 0.0;
  const ParticleArrays<Dim>& particles = simulation.particles();
  for (int q = 0; q < n; ++q) {
    position_sum += (particles.position[q] - sp.packing.centres[q]).norm();
    speed_sum += particles.velocity[q].norm();
  }
  nlohmann::json r;
  r["dimension"] = Dim;
  r["packing"] = o.packing;
  r["particles"] = n;
  r["contacts"] = summary.contacts;
  r["bonds"] = summary.bonds_created;
  r["bonds_intact"] = summary.bonds_intact;
  r["contacts_per_particle"] = static_cast<double>(summary.contacts) / n;
  r["bonds_per_particle"] = static_cast<double>(summary.bonds_created) / n;
  r["model"] = VariantName(m.variant);
  r["threads"] = o.threads;
  r["steps"] = m.steps;
  r["warmup_steps"] = o.warmup;
  r["seconds"] = m.seconds;
  // CPU time of the process over the timed runs (all threads): wall time well above
  // cpu_seconds / threads means the benchmark waited for a core.
  r["cpu_seconds"] = m.cpu_seconds;
  r["particle_steps_per_second"] = rate;
  r["memory_bytes"] = summary.memory_bytes;
  r["bytes_per_particle"] = static_cast<double>(summary.memory_bytes) / n;
  r["stages"] = summary.stages;
  r["omitted_stages"] = summary.omitted_stages;
  r["time_step_s"] = summary.time_step_s;
  r["normal_stiffness_n_per_m"] = simulation.state().law.normal_stiffness;
  r["platen_speed_m_per_s"] = -simulation.wall(1).velocity[Dim - 1];
  r["platen_travel_m"] = sp.upper - simulation.wall(1).point[Dim - 1];
  r["upper_platen_reaction_n"] = simulation.wall(1).NormalReaction();
  r["neighbour_searches"] = summary.neighbour_searches;
  r["energy_relative_imbalance"] = summary.energy.RelativeImbalance();
  r["load_seconds"] = sp.load_seconds;
  r["build_seconds"] = m.build_seconds;
  r["r_mean_m"] = sp.r_mean;
  r["displacement_sum_m"] = position_sum;
  r["speed_sum_m_per_s"] = speed_sum;
  if (!m.step_seconds.empty()) {
    std::vector<double> sorted = m.step_seconds;
    std::sort(sorted.begin(), sorted.end());
    r["median_step_particle_steps_per_second"] = n / Median(sorted);
    r["fastest_step_particle_steps_per_second"] = n / sorted.front();
  }
  if (!o.quiet) {
    std::printf("%dD %s, %d particles, %d contacts (%.2f per particle), %d thread(s)\n", Dim,
                VariantName(m.variant), n, summary.contacts,
                static_cast<double>(summary.contacts) / n, o.threads);
    std::printf("  %ld steps in %.3f s (cpu %.3f s): %.3e particle-steps/s, %.0f bytes/particle\n",
                m.steps, m.seconds, m.cpu_seconds, rate,
                static_cast<double>(summary.memory_bytes) / n);
    std::printf("  stages run:");
    for (const std::string& s : summary.stages) std::printf(" %s", s.c_str());
    std::printf("\n  left out:  ");
    for (const std::string& s : summary.omitted_stages) std::printf(" %s", s.c_str());
    std::printf("\n  dt %.3e s, platen travel %.3e m, upper reaction %.3e N, searches %ld, "
                "energy imbalance %.2e\n",
                summary.time_step_s, sp.upper - simulation.wall(1).point[Dim - 1],
                simulation.wall(1).NormalReaction(), summary.neighbour_searches,
                summary.energy.RelativeImbalance());
    std::printf("  fingerprint: displacement sum %.15e m, speed sum %.15e m/s\n", position_sum,
                speed_sum);
  }
  if (!o.dump.empty()) {
    // Final positions and velocities in the packing's order, full precision (comparisons).
    const std::string path =
        o.dump + (o.model == "both" || o.model == "moment" ? std::string(".") + VariantName(m.variant)
                                                            : std::string());
    std::FILE* file = std::fopen(path.c_str(), "w");
    if (!file) throw FileError("cannot write " + path);
    for (int q = 0; q < n; ++q) {
      for (int a = 0; a < Dim; ++a) std::fprintf(file, "%.17g ", particles.position[q][a]);
      for (int a = 0; a < Dim; ++a) std::fprintf(file, "%.17g ", particles.velocity[q][a]);
      std::fprintf(file, "\n");
    }
    std::fclose(file);
  }
  return r;
}

template <int Dim>
int RunBenchmark(const BenchOptions& o) {
  const auto load_start = std::chrono::steady_clock::now();
  Specimen<Dim> sp(o.packing);
  sp.load_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - load_start).count();

  std::vector<Variant> variants;
  if (o.model == "rigid") variants = {Variant::kRigid};
  if (o.model == "ddem") variants = {Variant::kDdem};
  if (o.model == "both") variants = {Variant::kRigid, Variant::kDdem};
  if (o.model == "moment") variants = {Variant::kRigid, Variant::kMoment};

  // The time step: DDEM's default (0.7 of the per-particle bound times the strain-lag
  // factor), or the moment variant's when lower, given explicitly to every variant so that
  // they take the same steps.
  double dt = std::numeric_limits<double>::infinity();
  for (const Variant v : {Variant::kDdem, Variant::kMoment}) {
    if (v == Variant::kMoment && o.model != "moment") continue;
    SceneOptions<Dim> probe = BenchScene<Dim>(sp, o, v, 0.0);
    probe.contacts.detect_new_contacts = false;
    dt = std::min(dt, Simulation<Dim>(sp.packing, probe).time_step_s());
  }

  std::vector<Measured<Dim>> models;
  for (const Variant variant : variants) {
    Measured<Dim> m;
    m.variant = variant;
    const auto build_start = std::chrono::steady_clock::now();
    m.simulation =
        std::make_unique<Simulation<Dim>>(sp.packing, BenchScene<Dim>(sp, o, variant, dt));
    m.build_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - build_start).count();
    if (o.warmup > 0) {
      RunOptions warm;
      warm.max_steps = o.warmup;
      m.simulation->Run(warm);
    }
    m.step_seconds.reserve(o.step_times ? o.steps : 0);
    models.push_back(std::move(m));
  }

  double paired_overhead = 0.0, paired_median = 0.0;
  if (models.size() == 1) {
    TimedRun(models[0], o.steps, o.step_times);
  } else {
    // Alternating chunks, the order alternating too.
    const long rounds = std::max(1L, o.steps / o.chunk);
    std::vector<double> ratios;
    for (long k = 0; k < rounds; ++k) {
      for (int which = 0; which < 2; ++which) {
        Measured<Dim>& m = models[(k + which) % 2];
        const double before = m.seconds;
        TimedRun(m, o.chunk, o.step_times);
        m.chunk_seconds.push_back(m.seconds - before);
      }
      ratios.push_back(models[1].chunk_seconds.back() / models[0].chunk_seconds.back());
    }
    paired_overhead = 100.0 * (models[1].seconds / models[0].seconds - 1.0);
    paired_median = 100.0 * (Median(ratios) - 1.0);
  }
  for (const Measured<Dim>& m : models) {
    nlohmann::json r = Record<Dim>(sp, o, m);
    if (models.size() == 2 && m.variant != Variant::kRigid) {
      r["paired_overhead_percent"] = paired_overhead;
      r["paired_overhead_median_chunk_percent"] = paired_median;
      if (!o.quiet)
        std::printf("%s overhead, paired: %.1f %% (totals), %.1f %% (median of %zu chunk pairs)\n",
                    VariantName(m.variant), paired_overhead, paired_median, m.chunk_seconds.size());
    }
    std::printf("RESULT %s\n", r.dump().c_str());
  }
  return kExitOk;
}

}  // namespace
}  // namespace specimen

int main(int argc, char** argv) {
  using namespace specimen;
  CLI::App app{"solver-throughput: particle-steps per second of a bonded specimen between platens"};
  BenchOptions o;
  app.add_option("--packing", o.packing, "packing file written by generate-packing")->required();
  app.add_option("--model", o.model,
                 "rigid, ddem, both (rigid and DDEM) or moment (rigid without and with "
                 "moment-carrying bonds): alternating chunks, paired overhead")
      ->check(CLI::IsMember({"rigid", "ddem", "both", "moment"}));
  app.add_option("--bond-radius-ratio", o.bond_radius_ratio,
                 "lambda of the moment variant, in (0, 1]");
  app.add_flag_callback("--deformable", [&]() { o.model = "ddem"; }, "same as --model ddem");
  app.add_option("--threads", o.threads, "OpenMP threads of the passes, >= 1");
  app.add_option("--steps", o.steps, "timed steps (per model), >= 1");
  app.add_option("--warmup", o.warmup, "steps run before the timed ones, >= 0");
  app.add_option("--chunk", o.chunk, "--model both or moment: steps per alternation, >= 1");
  app.add_option("--youngs-modulus", o.youngs_modulus_pa, "Ep [Pa], sets kn (both variants)");
  app.add_option("--kt-ratio", o.kt_ratio, "kt / kn");
  app.add_option("--damping", o.damping, "local damping alpha_t = alpha_r");
  app.add_option("--friction", o.friction, "friction coefficient of unbonded contacts");
  app.add_option("--platen-speed", o.platen_speed, "upper platen travel, mean radii per 1000 steps");
  app.add_flag("--step-times", o.step_times, "also time every step (median and fastest step)");
  app.add_option("--dump", o.dump, "write the final positions and velocities to this file");
  app.add_flag("--quiet", o.quiet, "only the RESULT lines");
  CLI11_PARSE(app, argc, argv);
  return RunCommand("solver-throughput", [&]() {
    if (o.threads < 1 || o.steps < 1 || o.warmup < 0 || o.chunk < 1)
      throw InputError("--threads, --steps and --chunk must be >= 1, --warmup >= 0");
    if (!(o.bond_radius_ratio > 0.0 && o.bond_radius_ratio <= 1.0))
      throw InputError("--bond-radius-ratio = " + Number(o.bond_radius_ratio) +
                       " is not allowed: it must be in (0, 1]");
    return ReadPackingDimension(o.packing) == 2 ? RunBenchmark<2>(o) : RunBenchmark<3>(o);
  });
}
