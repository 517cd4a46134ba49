// Contact detection for unbonded pairs: the cell-list candidate search against brute force,
// a collision of two free discs, and a contact found on the deformed shape (DDEM, Madan
// section 2.2, Fig. 2.4: a laterally bulging particle touches a neighbour its undeformed
// circle misses).

#include "solver/neighbour_search.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "solver/regular_lattice.h"
#include "solver/simulation.h"

namespace specimen {
namespace {

template <int Dim>
void CompareWithBruteForce(int count, std::uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> position(0.0, 1.0), radius(0.005, 0.04);
  std::vector<Vector<Dim>> x(count);
  std::vector<double> r(count);
  for (int i = 0; i < count; ++i) {
    for (int a = 0; a < Dim; ++a) x[i][a] = position(random);
    r[i] = radius(random);
  }
  const double margin = 0.01;
  std::vector<std::array<int, 2>> expected;
  for (int i = 0; i < count; ++i)
    for (int j = i + 1; j < count; ++j)
      if ((x[j] - x[i]).norm() < r[i] + r[j] + margin) expected.push_back({i, j});
  CandidateSearch<Dim> search;
  std::vector<std::array<int, 2>> found;
  search.FindPairs(x, r, margin, &found);
  EXPECT_EQ(found, expected);
  EXPECT_GT(found.size(), 0u);
  // A second call reuses the buffers and gives the same answer.
  search.FindPairs(x, r, margin, &found);
  EXPECT_EQ(found, expected);
}

TEST(CandidateSearch, MatchesBruteForce) {
  CompareWithBruteForce<2>(1500, 1);
  CompareWithBruteForce<3>(1500, 2);
}

// Two free discs (no bond), one thrown at the other: the search finds the pair, the unbonded
// law pushes them apart, and, undamped and frictionless, the equal masses swap velocities.
TEST(NewContacts, FreeDiscsCollideElastically) {
  Packing<2> packing(Domain<2>::Rectangle(-0.01, -0.01, 0.02, 0.01));
  packing.centres = {Vector<2>(0, 0), Vector<2>(2.6e-3, 0)};
  packing.radii = {1e-3, 1e-3};
  SceneOptions<2> scene;
  scene.material.normal_stiffness_n_per_m = 7e10;
  scene.material.density_kg_per_m3 = 2000;
  // A free particle counts one contact in the per-particle bound, while the collision of
  // two has omega^2 = 2 kn / m: resolve the impact with a tenth of the bound.
  scene.time_step.safety_factor = 0.1;
  Simulation<2> simulation(packing, scene);
  simulation.SetVelocity(1, Vector<2>(-5.0, 0.0));
  EXPECT_EQ(simulation.contacts().size(), 0);
  RunOptions run;
  run.duration_s = 3e-4;
  bool touched = false;
  run.observe_interval = 1;
  run.observer = [&]() {
    if (simulation.contacts().size() > 0 && simulation.contacts().normal_elastic_force[0] < 0) {
      touched = true;
      EXPECT_EQ(simulation.contacts().state[0], ContactState::kFrictional);
    }
  };
  const RunSummary summary = simulation.Run(run);
  EXPECT_TRUE(touched);
  EXPECT_GT(summary.neighbour_searches, 0);
  // Penalty contact: the impact starts and ends inside a step, an O(dt) error of a few 1e-3
  // with some 30 steps of contact.
  EXPECT_NEAR(simulation.particles().velocity[0].x(), -5.0, 0.01 * 5.0);
  EXPECT_NEAR(simulation.particles().velocity[1].x(), 0.0, 0.01 * 5.0);
  EXPECT_LT(summary.energy.RelativeImbalance(), 5e-3) << summary.energy.Table("  ");
  EXPECT_EQ(summary.energy.contact_elastic_j, 0.0);  // apart again
}

// A bond broken in tension and pulled far apart leaves the contact list at the next search;
// pushed back, the pair is found again as a new, never-bonded frictional contact.
TEST(NewContacts, BrokenBondLeavesAndFrictionalContactReturns) {
  SceneOptions<2> scene;
  scene.material.normal_stiffness_n_per_m = 7e10;
  scene.material.bond_tensile_strength_n = 1e4;
  scene.material.density_kg_per_m3 = 2000;
  FixedDofs<2> held;
  held.particles = {0};
  held.fix_translation = {true, true};
  FixedDofs<2> driven = held;
  driven.particles = {1};
  driven.velocity = Vector<2>(1.0, 0.0);
  driven.amplitude.points = {{0.0, 1.0}, {1e-3, 1.0}, {1e-3, -1.0}};  // out 1 mm, then back
  scene.fixed_dofs = {held, driven};
  Simulation<2> simulation(SquareLatticePacking(2, 1, 1e-3), scene);
  ASSERT_EQ(simulation.contacts().size(), 1);
  RunOptions run;
  run.duration_s = 1e-3;
  simulation.Run(run);
  EXPECT_EQ(simulation.last_summary().broken_in_tension, 1);
  EXPECT_EQ(simulation.contacts().size(), 0);  // 1 mm apart: beyond the skin, dropped
  run.duration_s = 1.003e-3;                   // back to an overlap of about 3 um (v dt = 0.4 um)
  simulation.Run(run);
  ASSERT_EQ(simulation.contacts().size(), 1);
  EXPECT_EQ(simulation.contacts().state[0], ContactState::kFrictional);
  EXPECT_LT(simulation.contacts().normal_elastic_force[0], 0.0);
  EXPECT_EQ(simulation.IntactBondCount(), 0);
}

// Disc A (DDEM, plane strain) squeezed vertically by balanced pole loads bulges sideways by
// R eps_xx = R nu (1 + nu) |sigma_yy| / Ep; disc B sits beside it, not bonded, with a gap
// smaller than that bulge. Rigid particles would never touch; deformable ones must.
TEST(NewContacts, DeformedShapeTouchesAnUnbondedNeighbour) {
  const double radius = 1e-3, load = 2e5, ep = 2e11, nu = 0.35;
  const double sigma = 2 * load / (3.14159265358979 * radius);  // |sigma_yy|, Madan (2.41)
  const double bulge = radius * nu * (1 + nu) * sigma / ep;     // plane strain (2.48)
  for (const bool deformable : {false, true}) {
    SCOPED_TRACE(deformable ? "DDEM" : "DEM");
    Packing<2> packing(Domain<2>::Rectangle(-0.01, -0.01, 0.01, 0.01));
    packing.centres = {Vector<2>(0, 0), Vector<2>(2 * radius + 0.5 * bulge, 0)};
    packing.radii = {radius, radius};
    SceneOptions<2> scene;
    scene.material.normal_stiffness_n_per_m = 7e10;
    scene.material.density_kg_per_m3 = 2000;
    scene.material.translational_damping = 0.3;
    if (deformable) {
      scene.material.particle_youngs_modulus_pa = ep;
      scene.material.particle_poisson_ratio = nu;
    }
    PointLoad<2> top;
    top.particles = {0};
    top.force_n = Vector<2>(0, -load);
    top.application_direction = Vector<2>(0, 1);
    top.amplitude = Amplitude::Ramp(2e-5);
    PointLoad<2> bottom = top;
    bottom.force_n = Vector<2>(0, load);
    bottom.application_direction = Vector<2>(0, -1);
    scene.point_loads = {top, bottom};
    FixedDofs<2> held;
    held.particles = {0, 1};
    held.fix_translation = {true, true};
    scene.fixed_dofs = {held};
    Simulation<2> simulation(packing, scene);
    RunOptions run;
    run.duration_s = 1e-4;
    simulation.Run(run);
    const int c = simulation.contacts().Find(0, 1);
    ASSERT_GE(c, 0);  // a candidate pair within the search skin
    const double fn = simulation.contacts().normal_elastic_force[c];
    if (deformable) {
      // Overlap of the deformed shapes: half the bulge of A, less B's own squeeze.
      EXPECT_LT(fn, 0.0);
      EXPECT_GT(-fn, 0.2 * 7e10 * 0.5 * bulge);
    } else {
      EXPECT_EQ(fn, 0.0);
    }
  }
}

}  // namespace
}  // namespace specimen
