// Bonding within an interaction range (bond_range.h): the pairs within gamma (ri + rj) join
// the packing's contact pairs, once each, as stress-free bonds of the contact law; a bond at
// range is a spring kn at its initial distance and breaks at Rn; and the stability analysis
// counts its springs. On a square lattice of touching discs (spacing a = 2r) the diagonals
// lie at sqrt(2) (ri + rj): with gamma 1.42 they are bonded, and the infinite lattice's
// highest frequency rises from omega^2 = 4 kn / m (the nearest springs, at wave vector
// (pi/a, pi/a)) to 8 kn / m (with the diagonals, at (pi/a, 0)), which a free block approaches
// from below (its springs are a subset of the infinite lattice's).

#include "solver/bond_range.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "common/error.h"
#include "solver/regular_lattice.h"
#include "solver/simulation.h"
#include "solver/stability_limits.h"

namespace specimen {
namespace {

constexpr double kRadius = 1e-3, kNormalStiffness = 5e10, kDensity = 2500.0;
constexpr double kPi = 3.14159265358979323846;

MaterialParameters RangeMaterial(double bond_range) {
  MaterialParameters m;
  m.normal_stiffness_n_per_m = kNormalStiffness;
  m.tangential_stiffness_n_per_m = 0.0;
  m.bond_tensile_strength_n = 1e3;
  m.bond_shear_strength_n = 1e3;
  m.friction_coefficient = 0.5;
  m.density_kg_per_m3 = kDensity;
  m.bond_range = bond_range;
  return m;
}

TEST(BondRange, PairsWithinTheRangeJoinThePackingPairsOnce) {
  const Packing<2> block = SquareLatticePacking(3, 3, kRadius);  // 12 touching pairs
  ASSERT_EQ(block.contacts.size(), 12u);
  EXPECT_EQ(BondCandidatePairs(block, 1.0).size(), 12u);
  EXPECT_EQ(BondCandidatePairs(block, 1.4).size(), 12u);   // diagonals at 1.414 (ri + rj)
  const auto with_diagonals = BondCandidatePairs(block, 1.42);
  EXPECT_EQ(with_diagonals.size(), 20u);                   // + 2 per cell, 4 cells
  EXPECT_EQ(BondCandidatePairs(block, 1.5).size(), 20u);   // next: 2 (ri + rj), out of range
  for (size_t k = 0; k < with_diagonals.size(); ++k) {
    EXPECT_LT(with_diagonals[k][0], with_diagonals[k][1]);
    if (k > 0) {
      EXPECT_LT(with_diagonals[k - 1], with_diagonals[k]);  // sorted, no duplicate
    }
  }
  const Packing<3> cube = CubicLatticePacking(2, 2, 2, kRadius);  // 12 edges
  EXPECT_EQ(BondCandidatePairs(cube, 1.42).size(), 12u + 12u);    // + 2 face diagonals x 6 faces
}

// Particle 0 held, particle 1 pulled along x by `force` [N] (ramped), damped to rest.
SceneOptions<2> PullScene(double bond_range, double force) {
  SceneOptions<2> scene;
  scene.material = RangeMaterial(bond_range);
  scene.material.translational_damping = 0.7;
  scene.contacts.detect_new_contacts = false;
  FixedDofs<2> held;
  held.name = "held";
  held.particles = {0};
  held.fix_translation.fill(true);
  held.fix_rotation = true;
  scene.fixed_dofs = {held};
  PointLoad<2> pull;
  pull.name = "pull";
  pull.particles = {1};
  pull.force_n = Vector<2>(force, 0.0);
  pull.amplitude = Amplitude::Ramp(2e-4);
  scene.point_loads.push_back(pull);
  return scene;
}

// Two discs 0.3 (ri + rj) apart, no contact in the packing's list: bonded at gamma 1.4 and
// not at 1.2; a pull F below Rn stretches the bond by F / kn from its initial distance (no
// force there); above Rn it breaks in tension.
TEST(BondRange, ABondAtRangeIsASpringAtItsInitialDistance) {
  Packing<2> pair = SquareLatticePacking(2, 1, kRadius);
  pair.centres[1].x() += 0.3 * 2.0 * kRadius;
  pair.contacts.clear();
  EXPECT_EQ(Simulation<2>(pair, PullScene(1.2, 0.0)).contacts().size(), 0);

  const double force = 0.5e3;  // half of Rn
  Simulation<2> simulation(pair, PullScene(1.4, force));
  ASSERT_EQ(simulation.contacts().size(), 1);
  EXPECT_EQ(simulation.contacts().state[0], ContactState::kBonded);
  const double start = simulation.particles().position[1].x();
  RunOptions run;
  run.max_steps = 40000;
  simulation.Run(run);
  EXPECT_NEAR(simulation.particles().position[1].x() - start, force / kNormalStiffness,
              1e-6 * force / kNormalStiffness);
  EXPECT_EQ(simulation.contacts().state[0], ContactState::kBonded);

  Simulation<2> breaking(pair, PullScene(1.4, 3.0 * force));  // 1.5 Rn
  run.max_steps = 20000;
  breaking.Run(run);
  EXPECT_NE(breaking.contacts().state[0], ContactState::kBonded);
  EXPECT_EQ(breaking.last_summary().broken_in_tension, 1);
}

// The diagonals enter the stability analysis: the Ritz value of omega^2 on a 24 x 24 block
// lies below the infinite lattice's 8 kn / m and within 1 % of it (4 kn / m without them); a
// run at 0.99 of the certified step stays bounded, one at 1.01 of the Ritz step diverges.
TEST(BondRange, TheStabilityAnalysisCountsTheBondsAtRange) {
  const Packing<2> block = SquareLatticePacking(24, 24, kRadius);
  const double mass = kDensity * kPi * kRadius * kRadius;
  for (const double gamma : {1.0, 1.42}) {
    SceneOptions<2> scene;
    scene.material = RangeMaterial(gamma);
    scene.material.bond_tensile_strength_n = std::numeric_limits<double>::infinity();
    scene.contacts.detect_new_contacts = false;
    const StabilityLimits s = AnalyseStabilityLimits<2>(block, scene, StabilityLimitOptions());
    const double omega_squared = std::pow(2.0 / s.dem_time_step_ritz_s, 2);
    const double infinite = (gamma > 1.0 ? 8.0 : 4.0) * kNormalStiffness / mass;
    EXPECT_LE(omega_squared, infinite * (1.0 + 1e-9)) << "gamma " << gamma;
    EXPECT_GT(omega_squared, 0.99 * infinite) << "gamma " << gamma;
    if (gamma == 1.0) continue;
    auto run = [&](double dt) {
      SceneOptions<2> o = scene;
      o.time_step.time_step_s = dt;
      o.time_step.allow_above_critical = true;
      Simulation<2> simulation(block, o);
      std::mt19937_64 engine(3);
      std::normal_distribution<double> gaussian;
      for (int p = 0; p < block.size(); ++p)
        simulation.SetVelocity(p, Vector<2>(gaussian(engine), gaussian(engine)));
      RunOptions run_options;
      run_options.max_steps = 3000;
      try {
        simulation.Run(run_options);
      } catch (const ComputationError& e) {
        return std::string(e.what());
      }
      return std::string();
    };
    EXPECT_EQ(run(0.99 * s.critical_time_step_s), "");
    EXPECT_NE(run(1.01 * s.dem_time_step_ritz_s).find("diverged"), std::string::npos);
  }
}

TEST(BondRange, TheRangeIsValidated) {
  std::string error;
  for (const double gamma : {0.9, 1.6}) {
    const MaterialParameters m = RangeMaterial(gamma);
    EXPECT_FALSE(m.IsValid(&error));
    EXPECT_NE(error.find("bond_range"), std::string::npos) << error;
  }
  EXPECT_TRUE(RangeMaterial(1.3).IsValid(&error)) << error;
}

}  // namespace
}  // namespace specimen
