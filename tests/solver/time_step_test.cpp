// Critical time step (Madan (2.14)-(2.18), thesis sections 3.5-3.6): the per-particle bound on
// the lattices, the A5/A6 stable/unstable pairs for DEM and DDEM, damping factors, and the
// refusal of a step above the limit.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "common/error.h"
#include "tests/solver/madan_specimens.h"

namespace specimen {
namespace {

using namespace madan;

const double kMass = kDensity * kPi * kRadius * kRadius;  // 6.283e-3 kg per metre

// The per-particle bound (TimeStepOptions::from_stability_analysis = false); the default, the
// stability analysis, is checked in stability_analysis_test.cpp.
SceneOptions<2> PerParticle(SceneOptions<2> scene) {
  scene.time_step.from_stability_analysis = false;
  return scene;
}

TEST(CriticalTimeStep, PerParticleBoundOnTheLattices) {
  // SC: k_eff = 4 kn, dt_cr = sqrt(m / kn) = 2.9959e-7 s (Madan (3.46)-(3.47)).
  const Specimen sc = SquareSpecimen();
  Simulation<2> square(sc.packing, PerParticle(Scene(sc, std::nullopt, 1e-4, 0.0)));
  EXPECT_NEAR(square.critical_time_step().critical_time_step_s, std::sqrt(kMass / kNormalStiffness),
              1e-12 * 3e-7);
  EXPECT_NEAR(square.critical_time_step().critical_time_step_s, 2.9959e-7, 0.0001e-7);
  // The default step is the safety factor 0.7 of it; the guaranteed bound is 1/sqrt(2) of it.
  EXPECT_NEAR(square.time_step_s(), 0.7 * std::sqrt(kMass / kNormalStiffness), 1e-20);
  EXPECT_NEAR(square.critical_time_step().guaranteed_bound_s,
              std::sqrt(kMass / kNormalStiffness) / std::sqrt(2.0), 1e-20);
  // HCP: k_eff = 6 kn, 2 sqrt(m / 6 kn) = the infinite triangular lattice's M-point limit.
  const Specimen hcp = HexagonalSpecimen();
  Simulation<2> hexagonal(hcp.packing, PerParticle(Scene(hcp, std::nullopt, 1e-4, 0.0)));
  EXPECT_NEAR(hexagonal.critical_time_step().critical_time_step_s,
              2.0 * std::sqrt(kMass / (6.0 * kNormalStiffness)), 1e-12 * 3e-7);
}

TEST(CriticalTimeStep, DampingFactors) {
  const Specimen sc = SquareSpecimen();
  SceneOptions<2> scene = Scene(sc, std::nullopt, 1e-4, 0.3);
  scene.material.normal_dashpot_ratio = 0.5;
  Simulation<2> simulation(sc.packing, PerParticle(scene));
  const CriticalTimeStepEstimate& c = simulation.critical_time_step();
  EXPECT_NEAR(c.dashpot_factor, std::sqrt(1.25) - 0.5, 1e-15);  // Labra (2.53)
  EXPECT_NEAR(c.local_damping_factor, 1.0 / std::sqrt(1.3), 1e-15);
  EXPECT_NEAR(c.critical_time_step_s,
              std::sqrt(kMass / kNormalStiffness) * c.dashpot_factor * c.local_damping_factor,
              1e-20);
  // DDEM: the default step carries the strain-lag factor sqrt(1 - beta_est),
  // beta_est = 2 kn lambda_max(D) / pi for equal discs; plane strain lambda_max = (1 + nu)/E.
  Simulation<2> deformable(sc.packing, PerParticle(Scene(sc, 2e11, 1e-4, 0.0)));
  const double beta = 2 * kNormalStiffness * (1 + kParticlePoisson) / 2e11 / kPi;
  EXPECT_NEAR(deformable.critical_time_step().ddem_ratio_estimate, beta, 1e-12);
  EXPECT_NEAR(deformable.time_step_s(),
              0.7 * std::sqrt(kMass / kNormalStiffness) * std::sqrt(1 - beta), 1e-20);
  // The limit a given step is checked against is the DEM one (Madan section 3.5).
  EXPECT_NEAR(deformable.critical_time_step().critical_time_step_s,
              std::sqrt(kMass / kNormalStiffness), 1e-20);
}

TEST(CriticalTimeStep, RefusesAStepAboveTheLimitUnlessForced) {
  const Specimen sc = SquareSpecimen();
  SceneOptions<2> scene = Scene(sc, std::nullopt, 1e-4, 0.0);
  scene.time_step.time_step_s = 3.0559e-7;
  try {
    Simulation<2> simulation(sc.packing, scene);
    FAIL() << "a time step above the critical one was accepted";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("time_step_s = 3.0559e-07"), std::string::npos) << message;
    // The default limit is the stability analysis': the free-free 20-disc chain,
    // sqrt(m/kn) / sin(19 pi / 40) = 3.00525e-7 s (cf. Madan (3.44); docs/stability.md,
    // "Validation"), certified from below.
    EXPECT_NE(message.find("critical time step 3.0052"), std::string::npos) << message;
    EXPECT_NE(message.find("stability analysis"), std::string::npos) << message;
    EXPECT_NE(message.find("allow_above_critical"), std::string::npos) << message;
  }
  scene.time_step.allow_above_critical = true;
  Simulation<2> forced(sc.packing, scene);
  EXPECT_EQ(forced.time_step_s(), 3.0559e-7);
}

// Runs the undamped specimen (loads ramped over 0.1 ms, as the thesis) for a fixed number of
// steps at a given time step. Returns the divergence message, or "" when the run stayed
// bounded: the kinetic energy never exceeded 1e6 times the energy supplied.
std::string RunUndamped(const Specimen& specimen, std::optional<double> particle_modulus,
                        double time_step, long steps, RunSummary* summary = nullptr) {
  SceneOptions<2> scene = Scene(specimen, particle_modulus, 1e-4, 0.0);
  scene.time_step.time_step_s = time_step;
  scene.time_step.allow_above_critical = true;
  Simulation<2> simulation(specimen.packing, scene);
  RunOptions run;
  run.max_steps = steps;
  try {
    const RunSummary s = simulation.Run(run);
    if (summary) *summary = s;
  } catch (const ComputationError& e) {
    return e.what();
  }
  return "";
}

// A5: SC, undamped: 2.9959e-7 s stable, 3.0559e-7 s unstable, DEM and DDEM (Ep = 2e11,
// nu_p = 0.35). 4000 steps (1.2 ms, 8 times the thesis' 0.15 ms runs).
TEST(CriticalTimeStep, A5SquareLatticeStableAndUnstable) {
  const Specimen sc = SquareSpecimen();
  for (const std::optional<double> modulus :
       {std::optional<double>(), std::optional<double>(2e11)}) {
    SCOPED_TRACE(modulus ? "DDEM" : "DEM");
    RunSummary summary;
    EXPECT_EQ(RunUndamped(sc, modulus, 2.9959e-7, 4000, &summary), "");
    // Bounded and conservative: the undamped audit closes.
    EXPECT_LT(summary.energy.RelativeImbalance(), modulus ? 0.005 : 1e-6) << summary.FullReport();
    const std::string failure = RunUndamped(sc, modulus, 3.0559e-7, 4000);
    EXPECT_NE(failure.find("diverged at step"), std::string::npos) << failure;
    EXPECT_TRUE(failure.find("kinetic energy") != std::string::npos ||
                failure.find("contact force") != std::string::npos)
        << failure;
    EXPECT_NE(failure.find("above the critical time step"), std::string::npos) << failure;
    std::printf(
        "A5 %s: 2.9959e-7 s bounded over 4000 steps (audit imbalance %.2e); 3.0559e-7 s: %s\n",
        modulus ? "DDEM" : "DEM", summary.energy.RelativeImbalance(),
        failure.substr(0, failure.find(':')).c_str());
  }
}

// A6: HCP 110 discs (17 rows of 6 and 7), 10 kN per top/bottom particle: 2.4567e-7 s stable,
// 2.5166e-7 s unstable, both models.
TEST(CriticalTimeStep, A6HexagonalLatticeStableAndUnstable) {
  const Specimen hcp = HexagonalSpecimen();
  ASSERT_EQ(hcp.packing.size(), 110);
  for (const std::optional<double> modulus :
       {std::optional<double>(), std::optional<double>(2e11)}) {
    SCOPED_TRACE(modulus ? "DDEM" : "DEM");
    RunSummary summary;
    EXPECT_EQ(RunUndamped(hcp, modulus, 2.4567e-7, 4000, &summary), "");
    const std::string failure = RunUndamped(hcp, modulus, 2.5166e-7, 4000);
    EXPECT_NE(failure.find("diverged at step"), std::string::npos) << failure;
    std::printf(
        "A6 %s: 2.4567e-7 s bounded over 4000 steps (audit imbalance %.2e); 2.5166e-7 s: %s\n",
        modulus ? "DDEM" : "DEM", summary.energy.RelativeImbalance(),
        failure.substr(0, failure.find(':')).c_str());
  }
}

// --- Inertia scaling (MaterialParameters::mass_scaling_budget, particles.h) ---

MaterialParameters ScalingMaterial(double budget) {
  MaterialParameters m;
  m.normal_stiffness_n_per_m = 1e9;
  m.tangential_stiffness_n_per_m = 2e8;
  m.density_kg_per_m3 = 2500.0;
  m.mass_scaling_budget = budget;
  return m;
}

// The per-particle bound up to its common factor: sqrt(m / max(1, contacts)).
std::vector<double> Bounds(const ParticleArrays<2>& p, const Packing<2>& packing) {
  std::vector<int> count(p.size(), 0);
  for (const auto& [i, j] : packing.contacts) ++count[i], ++count[j];
  std::vector<double> bound(p.size());
  for (int i = 0; i < p.size(); ++i) bound[i] = std::sqrt(p.mass[i] / std::max(1, count[i]));
  return bound;
}

TEST(MassScaling, ChainOfFourClosedForm) {
  // Discs r = 1, 1, 0.5, 1 mm in a row, contacts 0-1, 1-2, 2-3. Bounds sqrt(m/n): the small
  // disc (m/4, two contacts) limits at sqrt(m/8), the next is disc 1 at sqrt(m/2). With a
  // budget B of the total 3.25 m only disc 2 is raised, to the floor t with
  // m2 ((t/b2)^2 - 1) = B M: factor 1 + B M / m2 = 1 + 0.01 x 3.25 / 0.25 = 1.13.
  Packing<2> packing(Domain<2>::Rectangle(0, 0, 0.01, 0.01));
  packing.radii = {1e-3, 1e-3, 0.5e-3, 1e-3};
  packing.centres = {Vector<2>(1e-3, 5e-3), Vector<2>(3e-3, 5e-3), Vector<2>(4.5e-3, 5e-3),
                     Vector<2>(6e-3, 5e-3)};
  packing.contacts = {{0, 1}, {1, 2}, {2, 3}};
  const ParticleArrays<2> plain = BuildParticles<2>(packing, ScalingMaterial(0.0), false);
  const ParticleArrays<2> scaled = BuildParticles<2>(packing, ScalingMaterial(0.01), false);
  EXPECT_EQ(plain.mass_scaling.scaled_particles, 0);
  EXPECT_EQ(scaled.mass_scaling.scaled_particles, 1);
  for (int i : {0, 1, 3}) {
    EXPECT_EQ(scaled.mass[i], plain.mass[i]);
    EXPECT_EQ(scaled.inverse_inertia[i], plain.inverse_inertia[i]);
  }
  EXPECT_NEAR(scaled.mass[2] / plain.mass[2], 1.13, 1e-12);
  EXPECT_NEAR(plain.inverse_inertia[2] / scaled.inverse_inertia[2], 1.13, 1e-12);
  EXPECT_NEAR(scaled.inverse_mass[2] * scaled.mass[2], 1.0, 1e-14);
  EXPECT_NEAR(scaled.mass_scaling.added_mass_share, 0.01, 1e-14);
  EXPECT_NEAR(scaled.mass_scaling.bound_gain, std::sqrt(1.13), 1e-12);
  EXPECT_NEAR(scaled.mass_scaling.largest_factor, 1.13, 1e-12);
  // The radius (hence the DDEM volume) is untouched.
  EXPECT_EQ(scaled.radius, plain.radius);
}

TEST(MassScaling, PolydisperseFloorSpendsTheBudgetExactly) {
  // 400 discs, radii spread 1:8, a ring of contacts plus pseudo-random extra pairs: every
  // raised particle ends exactly at the floor, every other one above it, and the added mass
  // is the budget.
  Packing<2> packing(Domain<2>::Rectangle(0, 0, 1, 1));
  const int n = 400;
  unsigned state = 12345u;
  auto next = [&] { return (state = state * 1103515245u + 12345u) / 4294967296.0; };
  for (int i = 0; i < n; ++i) {
    packing.centres.emplace_back(next(), next());
    packing.radii.push_back(1e-3 * std::pow(8.0, next()));
  }
  for (int i = 0; i < n; ++i) packing.contacts.push_back({std::min(i, (i + 1) % n), std::max(i, (i + 1) % n)});
  for (int k = 0; k < 2 * n; ++k) {
    const int i = static_cast<int>(next() * n), j = static_cast<int>(next() * n);
    if (i != j) packing.contacts.push_back({std::min(i, j), std::max(i, j)});
  }
  for (const double budget : {0.001, 0.01, 0.05}) {
    const ParticleArrays<2> plain = BuildParticles<2>(packing, ScalingMaterial(0.0), false);
    const ParticleArrays<2> scaled = BuildParticles<2>(packing, ScalingMaterial(budget), false);
    const std::vector<double> before = Bounds(plain, packing), after = Bounds(scaled, packing);
    const double floor = *std::min_element(after.begin(), after.end());
    double total = 0.0, added = 0.0;
    int raised = 0;
    for (int i = 0; i < n; ++i) {
      total += plain.mass[i];
      added += scaled.mass[i] - plain.mass[i];
      if (scaled.mass[i] != plain.mass[i]) {
        ++raised;
        EXPECT_NEAR(after[i], floor, 1e-12 * floor) << "particle " << i;
        EXPECT_LT(before[i], floor);
      } else {
        EXPECT_GE(before[i], floor * (1 - 1e-12)) << "particle " << i;
      }
    }
    EXPECT_NEAR(added / total, budget, 1e-12) << "budget " << budget;
    EXPECT_EQ(raised, scaled.mass_scaling.scaled_particles);
    EXPECT_GT(raised, 1);
    EXPECT_NEAR(scaled.mass_scaling.bound_gain,
                floor / *std::min_element(before.begin(), before.end()), 1e-12);
  }
}

TEST(MassScaling, RaisesTheSimulationsCriticalStepAndRefusesABadBudget) {
  // Equal discs of the square lattice: the corner discs (two contacts) and the sides (three)
  // have larger bounds than the interior (four), so a budget raises the interior together.
  const Specimen sc = SquareSpecimen();
  SceneOptions<2> scene = PerParticle(Scene(sc, std::nullopt, 1e-4, 0.0));
  Simulation<2> plain(sc.packing, scene);
  scene.material.mass_scaling_budget = 0.01;
  Simulation<2> scaled(sc.packing, scene);
  const MassScalingSummary& s = scaled.particles().mass_scaling;
  EXPECT_GT(s.scaled_particles, 100);
  EXPECT_NEAR(s.added_mass_share, 0.01, 1e-12);
  EXPECT_NEAR(scaled.critical_time_step().critical_time_step_s /
                  plain.critical_time_step().critical_time_step_s,
              s.bound_gain, 1e-12);
  scene.material.mass_scaling_budget = 0.06;
  try {
    Simulation<2> refused(sc.packing, scene);
    FAIL() << "a budget of 0.06 was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mass_scaling_budget"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("[0, 0.05]"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace specimen
