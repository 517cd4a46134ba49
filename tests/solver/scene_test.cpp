// Scene composition (docs/solver.md, "Stage plan": leave out what a given scene does not
// need), bad input, divergence, the run summary, and thread-count independence.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "common/error.h"
#include "solver/regular_lattice.h"
#include "solver/simulation.h"

namespace specimen {
namespace {

bool Has(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

SceneOptions<2> Minimal() {
  SceneOptions<2> scene;
  scene.material.normal_stiffness_n_per_m = 7e10;
  scene.material.density_kg_per_m3 = 2000;
  return scene;
}

// A rigid, unbreakable, kt = 0 scene without walls runs no DDEM, failure, tangential or wall
// stage, and says so.
TEST(SceneComposition, MinimalSceneRunsOnlyTheContactAndParticlePasses) {
  SceneOptions<2> scene = Minimal();
  scene.contacts.detect_new_contacts = false;
  Simulation<2> simulation(SquareLatticePacking(4, 4, 1e-3), scene);
  RunOptions run;
  run.max_steps = 10;
  const RunSummary summary = simulation.Run(run);
  EXPECT_EQ(summary.stages, (std::vector<std::string>{"contact_forces", "particle_update"}));
  for (const char* name :
       {"ddem_deformed_overlap", "ddem_particle_strain", "bond_failure", "tangential", "walls",
        "dashpots", "local_damping", "rotation", "neighbour_search", "bond_moments"})
    EXPECT_TRUE(Has(summary.omitted_stages, name)) << name;
  const std::string report = summary.FullReport();
  EXPECT_NE(report.find("stages run: contact_forces, particle_update"), std::string::npos)
      << report;
  EXPECT_NE(report.find("stages left out: neighbour_search, ddem_deformed_overlap, tangential"),
            std::string::npos)
      << report;
  // Nothing of the left-out stages is even allocated.
  EXPECT_TRUE(simulation.particles().strain.empty());
  EXPECT_TRUE(simulation.contacts().tangential_force.empty());
  EXPECT_TRUE(simulation.contacts().bond_moment.empty());
  EXPECT_TRUE(simulation.state().external_force.empty());
}

TEST(SceneComposition, FullSceneRunsEveryStage) {
  SceneOptions<2> scene = Minimal();
  MaterialParameters& m = scene.material;
  m.tangential_stiffness_n_per_m = 3e10;
  m.bond_tensile_strength_n = 1e5;
  m.friction_coefficient = 0.5;
  m.particle_youngs_modulus_pa = 2e11;
  m.particle_poisson_ratio = 0.3;
  m.translational_damping = 0.1;
  m.normal_dashpot_ratio = 0.1;
  m.bond_radius_ratio = 0.5;
  WallOptions<2> wall;
  wall.name = "floor";
  wall.point = Vector<2>(0, -1e-3);
  wall.normal = Vector<2>(0, 1);
  wall.normal_stiffness_n_per_m = 7e10;
  wall.tangential_stiffness_n_per_m = 3e10;
  wall.friction_coefficient = 0.5;
  scene.walls = {wall};
  PointLoad<2> load;
  load.particles = {15};
  load.force_n = Vector<2>(0, -1e3);
  scene.point_loads = {load};
  FixedDofs<2> fixed;
  fixed.particles = {0};
  fixed.fix_translation = {true, false};
  scene.fixed_dofs = {fixed};
  Simulation<2> simulation(SquareLatticePacking(4, 4, 1e-3), scene);
  RunOptions run;
  run.max_steps = 10;
  const RunSummary summary = simulation.Run(run);
  EXPECT_TRUE(summary.omitted_stages.empty()) << summary.FullReport();
  EXPECT_EQ(summary.stages.size(), 15u);
  // JSON carries the same content.
  const nlohmann::json j = summary.ToJson();
  EXPECT_EQ(j["stages"].size(), 15u);
  EXPECT_EQ(j["steps"], 10);
  EXPECT_TRUE(j["energy"].contains("relative_imbalance"));
  EXPECT_EQ(j["walls"][0]["name"], "floor");
  EXPECT_EQ(j["termination"], "step limit");
  EXPECT_NE(summary.BriefReport().find("10 steps"), std::string::npos) << summary.BriefReport();
}

void ExpectInputError(const std::function<void()>& build, const std::vector<std::string>& words) {
  try {
    build();
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    const std::string message = e.what();
    for (const auto& word : words) EXPECT_NE(message.find(word), std::string::npos) << message;
  }
}

TEST(SceneValidation, EachInvalidFieldIsNamedWithItsRange) {
  const Packing<2> packing = SquareLatticePacking(2, 2, 1e-3);
  auto with = [&](auto change) {
    return [&packing, change]() {
      SceneOptions<2> scene = Minimal();
      change(scene);
      Simulation<2> simulation(packing, scene);
    };
  };
  ExpectInputError(with([](SceneOptions<2>& s) { s.material.normal_stiffness_n_per_m = 0; }),
                   {"normal_stiffness_n_per_m (kn) = 0", "> 0"});
  ExpectInputError(with([](SceneOptions<2>& s) { s.material.normal_stiffness_n_per_m = -5; }),
                   {"normal_stiffness_n_per_m (kn) = -5", "> 0"});
  ExpectInputError(with([](SceneOptions<2>& s) { s.material.tangential_stiffness_n_per_m = -1; }),
                   {"tangential_stiffness_n_per_m (kt) = -1", ">= 0"});
  ExpectInputError(with([](SceneOptions<2>& s) { s.material.density_kg_per_m3 = 0; }),
                   {"density_kg_per_m3 = 0", "> 0"});
  ExpectInputError(with([](SceneOptions<2>& s) { s.material.particle_poisson_ratio = 0.5; }),
                   {"particle_poisson_ratio (nu_p) = 0.5", "(-1, 0.5)"});
  ExpectInputError(with([](SceneOptions<2>& s) { s.material.particle_poisson_ratio = -1; }),
                   {"particle_poisson_ratio (nu_p) = -1", "(-1, 0.5)"});
  ExpectInputError(with([](SceneOptions<2>& s) { s.material.particle_youngs_modulus_pa = -2e11; }),
                   {"particle_youngs_modulus_pa (Ep) = -2e+11", "> 0"});
  ExpectInputError(with([](SceneOptions<2>& s) { s.material.bond_tensile_strength_n = 0; }),
                   {"bond_tensile_strength_n (Rn) = 0", "> 0"});
  ExpectInputError(with([](SceneOptions<2>& s) { s.material.translational_damping = 1.0; }),
                   {"translational_damping (alpha_t) = 1", "[0, 1)"});
  ExpectInputError(with([](SceneOptions<2>& s) { s.time_step.safety_factor = 1.5; }),
                   {"safety_factor = 1.5", "(0, 1]"});
  ExpectInputError(
      with([](SceneOptions<2>& s) { s.time_step.time_step_s = 1e-5; }),
      {"time_step_s = 1e-05 s is above the critical time step", "allow_above_critical"});
  ExpectInputError(with([](SceneOptions<2>& s) {
                     PointLoad<2> load;
                     load.particles = {7};
                     s.point_loads = {load};
                   }),
                   {"particle index 7", "[0, 3]"});
  ExpectInputError(with([](SceneOptions<2>& s) {
                     WallOptions<2> wall;
                     wall.name = "w";
                     wall.normal = Vector<2>(0, 1);
                     s.walls = {wall};
                   }),
                   {"wall \"w\"", "normal_stiffness_n_per_m = 0", "> 0"});
  // Radius: every particle must have a finite positive radius.
  Packing<2> bad = packing;
  bad.radii[2] = 0.0;
  ExpectInputError([&]() { Simulation<2> simulation(bad, Minimal()); },
                   {"radius of particle 2 = 0", "> 0"});
  bad.radii[2] = -1e-3;
  ExpectInputError([&]() { Simulation<2> simulation(bad, Minimal()); },
                   {"radius of particle 2", "> 0"});
  // Run options.
  Simulation<2> simulation(packing, Minimal());
  ExpectInputError([&]() { simulation.Run(RunOptions()); }, {"max_steps > 0 or duration_s > 0"});
}

// A deliberately unstable run (forced time step 1.6 times the critical one) stops with
// ComputationError naming what grew and the step; the summary of the failed run says so.
TEST(Divergence, UnstableRunNamesWhatGrewAndTheStep) {
  SceneOptions<2> scene = Minimal();
  scene.time_step.time_step_s = 1.6 * std::sqrt(2000 * 3.14159265358979 * 1e-6 / 7e10);
  scene.time_step.allow_above_critical = true;
  PointLoad<2> load;
  load.particles = {0};
  load.force_n = Vector<2>(1e3, 0);
  scene.point_loads = {load};
  Simulation<2> simulation(SquareLatticePacking(5, 5, 1e-3), scene);
  RunOptions run;
  run.max_steps = 10000;
  try {
    simulation.Run(run);
    FAIL() << "the unstable run did not stop";
  } catch (const ComputationError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("diverged at step"), std::string::npos) << message;
    EXPECT_TRUE(message.find("kinetic energy grew") != std::string::npos ||
                message.find("contact force grew") != std::string::npos)
        << message;
    EXPECT_NE(message.find("above the critical time step"), std::string::npos) << message;
    EXPECT_EQ(simulation.last_summary().termination, TerminationReason::kDiverged);
    EXPECT_EQ(simulation.last_summary().termination_message, message);
    EXPECT_LT(simulation.last_summary().steps, 10000);
  }
}

// The passes gather contact forces per particle in a fixed order, so the trajectory does
// not depend on the number of threads (5000 particles: the parallel loops are active).
TEST(Threads, TrajectoryIndependentOfThreadCount) {
  const Packing<2> packing = HexagonalLatticePacking(50, 100, 100, 1e-3);
  auto run = [&](int threads) {
    SceneOptions<2> scene = Minimal();
    scene.material.tangential_stiffness_n_per_m = 3e10;
    scene.material.particle_youngs_modulus_pa = 2e11;
    scene.material.particle_poisson_ratio = 0.3;
    scene.material.translational_damping = 0.1;
    scene.num_threads = threads;
    PointLoad<2> load;
    for (int c = 0; c < 100; ++c) load.particles.push_back(49 * 100 + c);
    load.force_n = Vector<2>(2e3, -1e4);
    load.application_direction = Vector<2>(0, 1);
    scene.point_loads = {load};
    FixedDofs<2> base;
    for (int c = 0; c < 100; ++c) base.particles.push_back(c);
    base.fix_translation = {true, true};
    scene.fixed_dofs = {base};
    Simulation<2> simulation(packing, scene);
    RunOptions options;
    options.max_steps = 100;
    simulation.Run(options);
    return simulation.particles().position;
  };
  const auto one = run(1), two = run(2);
  for (int q = 0; q < packing.size(); ++q) ASSERT_EQ(one[q], two[q]) << "particle " << q;
}

// Local damping F_d = -alpha |F| v/|v| (Madan (2.7)-(2.8)) at a velocity decaying towards
// rest: |v|^2 denormal must not overflow |F|^2/|v|^2 (it once made a spin infinite in one
// step after a UCS peak). The damped torque has the magnitude (1 - alpha) |T| against the spin.
TEST(LocalDamping, DenormalSpeedsStayFinite) {
  SceneOptions<2> scene = Minimal();
  scene.material.translational_damping = 0.7;
  scene.material.rotational_damping = 0.7;
  scene.contacts.detect_new_contacts = false;
  PointLoad<2> load;  // a force at the top of disc 1: a torque about its centre
  load.particles = {1};
  load.force_n = Vector<2>(-1e3, 0.0);
  load.application_direction = Vector<2>(0.0, 1.0);
  scene.point_loads = {load};
  FixedDofs<2> held;
  held.particles = {0, 1};
  held.fix_translation = {true, true};
  scene.fixed_dofs = {held};
  Simulation<2> simulation(SquareLatticePacking(2, 1, 1e-3), scene);
  simulation.SetAngularVelocity(1, 1e-161);  // |w|^2 = 1e-322, denormal
  RunOptions run;
  run.max_steps = 1;
  simulation.Run(run);
  const double spin = simulation.particles().angular_velocity[1];
  ASSERT_TRUE(std::isfinite(spin));
  const double torque = 1e3 * 1e-3;  // |s x F| = R |F|, positive about z
  const double inertia = 0.5 * 2000 * 3.14159265358979323846 * 1e-6 * 1e-6;
  // The spin is positive: damping opposes it with 0.7 |T|.
  EXPECT_NEAR(spin, 1e-161 + (1.0 - 0.7) * torque * simulation.time_step_s() / inertia,
              1e-9 * torque * simulation.time_step_s() / inertia);

  // The same for a translation: v = (1, 1) 1e-161 m/s, a free disc under F = (-1e3, 0) N:
  // dv = (F - 0.7 |F| v/|v|) dt / m.
  scene.fixed_dofs[0].particles = {0};
  Simulation<2> free(SquareLatticePacking(2, 1, 1e-3), scene);
  free.SetVelocity(1, Vector<2>(1e-161, 1e-161));
  free.Run(run);
  const Vector<2> v = free.particles().velocity[1];
  ASSERT_TRUE(v.allFinite());
  const double mass = 2000 * 3.14159265358979323846 * 1e-6;
  const Vector<2> expected =
      (Vector<2>(-1e3, 0.0) - 0.7 * 1e3 * Vector<2>(1.0, 1.0) / std::sqrt(2.0)) *
      (free.time_step_s() / mass);
  EXPECT_NEAR(v.x(), expected.x(), 1e-9 * expected.norm());
  EXPECT_NEAR(v.y(), expected.y(), 1e-9 * expected.norm());
}

}  // namespace
}  // namespace specimen
