// Critical time step (Madan (2.14)-(2.18), thesis sections 3.5-3.6): the per-particle bound on
// the lattices, the A5/A6 stable/unstable pairs for DEM and DDEM, damping factors, and the
// refusal of a step above the limit.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

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
  // The limit a given step is checked against is the DEM one (Madan section 3.3).
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
    // sqrt(m/kn) / sin(19 pi / 40) = 3.00525e-7 s (note 3.7 item 1), certified from below.
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

}  // namespace
}  // namespace specimen
