// Rigid plane walls (platens): a simple-cubic block of spheres compressed between two walls
// gives the row-of-springs stiffness (rigid and DDEM), a force-driven wall settles at its
// load, wall friction sticks below mu N and slides above it.

#include <gtest/gtest.h>

#include <cmath>

#include "solver/regular_lattice.h"
#include "solver/simulation.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;

// 3 x 3 x 5 spheres (R = 1 mm) between a fixed bottom wall and a top wall moved down by
// `shortening`, then held. Static reaction = 9 columns x f, with the column compliance
//   1/k = 4/kn + 2/k_wall  (+ DDEM: 5 spheres x 2 halves x 3/(2 pi R E), uniaxial stress
//   sigma_zz = 2 f R / V = 3 f / (2 pi R^2) in each sphere, Madan (2.41) in 3D).
TEST(Walls, CubicBlockBetweenPlatensGivesTheSeriesSpringStiffness) {
  const double radius = 1e-3, kn = 1e8, k_wall = 2e8, shortening = 1e-7;
  for (const bool deformable : {false, true}) {
    SCOPED_TRACE(deformable ? "DDEM" : "DEM");
    const Packing<3> packing = CubicLatticePacking(3, 3, 5, radius);
    SceneOptions<3> scene;
    MaterialParameters& m = scene.material;
    m.normal_stiffness_n_per_m = kn;
    m.tangential_stiffness_n_per_m = 0.5 * kn;  // lateral bonds stay unloaded (SC: nu = 0)
    m.density_kg_per_m3 = 2000;
    m.translational_damping = 0.3;
    m.rotational_damping = 0.3;
    if (deformable) {
      m.particle_youngs_modulus_pa = 2e11;
      m.particle_poisson_ratio = 0.25;
    }
    WallOptions<3> bottom;
    bottom.name = "bottom platen";
    bottom.point = Vector<3>(0, 0, -radius);
    bottom.normal = Vector<3>(0, 0, 1);
    bottom.normal_stiffness_n_per_m = k_wall;
    WallOptions<3> top = bottom;
    top.name = "top platen";
    top.point = Vector<3>(0, 0, 9 * radius);
    top.normal = Vector<3>(0, 0, -1);
    const double ramp = 2e-4;
    top.velocity = Vector<3>(0, 0, -shortening / ramp);
    top.velocity_amplitude.points = {{0.0, 0.0}, {ramp / 2, 2.0}, {ramp, 0.0}};
    scene.walls = {bottom, top};
    Simulation<3> simulation(packing, scene);
    RunOptions run;
    run.max_steps = 300000;
    run.min_steps = std::lround(ramp / simulation.time_step_s()) + 10;
    run.static_force_ratio = 1e-9;
    const RunSummary summary = simulation.Run(run);
    ASSERT_EQ(summary.termination, TerminationReason::kStatic) << summary.FullReport();
    const double moved = 9 * radius - simulation.wall(1).point.z();
    EXPECT_NEAR(moved, shortening, 0.01 * shortening);
    double compliance = 4 / kn + 2 / k_wall;
    if (deformable) compliance += 5 * 2 * 3 / (2 * kPi * radius * 2e11);
    const double expected = 9 * moved / compliance;
    EXPECT_NEAR(simulation.wall(1).NormalReaction(), expected, 1e-6 * expected)
        << summary.FullReport();
    EXPECT_NEAR(simulation.wall(0).NormalReaction(), expected, 1e-6 * expected);
    EXPECT_EQ(summary.walls.size(), 2u);
    EXPECT_EQ(summary.walls[1].touching_particles, 9);
    // The drive's work is stored in the springs (less the damping losses).
    const EnergyBalance e = simulation.Energy();
    EXPECT_LT(e.RelativeImbalance(), deformable ? 0.02 : 1e-6) << e.Table("  ");
    std::printf("walls %s: reaction %.6e N, series-spring %.6e N\n", deformable ? "DDEM" : "DEM",
                simulation.wall(1).NormalReaction(), expected);
  }
}

// A column of 5 discs on a fixed wall, pressed by a force-driven wall (mass 0.01 kg, 1e4 N
// ramped): the wall settles where the reaction equals the load.
TEST(Walls, ForceDrivenWallSettlesAtItsLoad) {
  const double radius = 1e-3, kn = 7e10, k_wall = 7e10, load = 1e4;
  const Packing<2> packing = SquareLatticePacking(1, 5, radius);
  SceneOptions<2> scene;
  scene.material.normal_stiffness_n_per_m = kn;
  scene.material.density_kg_per_m3 = 2000;
  scene.material.translational_damping = 0.3;
  WallOptions<2> bottom;
  bottom.name = "support";
  bottom.point = Vector<2>(0, -radius);
  bottom.normal = Vector<2>(0, 1);
  bottom.normal_stiffness_n_per_m = k_wall;
  WallOptions<2> top = bottom;
  top.name = "press";
  top.point = Vector<2>(0, 9 * radius);
  top.normal = Vector<2>(0, -1);
  top.drive = WallDrive::kForce;
  top.applied_force_n = load;
  top.force_amplitude = Amplitude::Ramp(1e-4);
  top.mass_kg = 0.01;
  scene.walls = {bottom, top};
  Simulation<2> simulation(packing, scene);
  RunOptions run;
  run.max_steps = 400000;
  run.min_steps = 1000;
  run.static_force_ratio = 1e-10;
  const RunSummary summary = simulation.Run(run);
  ASSERT_EQ(summary.termination, TerminationReason::kStatic) << summary.FullReport();
  EXPECT_NEAR(simulation.wall(1).NormalReaction(), load, 1e-6 * load);
  EXPECT_NEAR(simulation.wall(0).NormalReaction(), load, 1e-6 * load);
  const double moved = 9 * radius - simulation.wall(1).point.y();
  const double expected = load * (4 / kn + 2 / k_wall);
  EXPECT_NEAR(moved, expected, 1e-5 * expected);
  EXPECT_GT(simulation.Energy().wall_work_j, 0.0);
}

// A disc (rotation held) pressed on a frictional wall by N = 1e4 N and pushed sideways by
// Q: it sticks for Q < mu N and slides for Q > mu N.
TEST(Walls, FrictionSticksBelowAndSlidesAboveTheCoulombLimit) {
  const double radius = 1e-3, mu = 0.4, normal_load = 1e4;
  for (const double ratio : {0.5, 1.5}) {
    SCOPED_TRACE("Q / mu N = " + std::to_string(ratio));
    Packing<2> packing(Domain<2>::Rectangle(-0.01, -0.01, 0.01, 0.01));
    packing.centres = {Vector<2>(0, 0)};
    packing.radii = {radius};
    SceneOptions<2> scene;
    scene.material.normal_stiffness_n_per_m = 7e10;
    scene.material.density_kg_per_m3 = 2000;
    WallOptions<2> floor;
    floor.name = "floor";
    floor.point = Vector<2>(0, -radius);
    floor.normal = Vector<2>(0, 1);
    floor.normal_stiffness_n_per_m = 7e10;
    floor.tangential_stiffness_n_per_m = 3.5e10;
    floor.friction_coefficient = mu;
    scene.walls = {floor};
    PointLoad<2> press;
    press.particles = {0};
    press.force_n = Vector<2>(0, -normal_load);
    press.application_direction = Vector<2>(0, 1);
    PointLoad<2> push = press;
    push.force_n = Vector<2>(ratio * mu * normal_load, 0);
    push.application_direction = Vector<2>::Zero();
    push.amplitude = Amplitude::Ramp(2e-5);
    scene.point_loads = {press, push};
    FixedDofs<2> no_spin;
    no_spin.particles = {0};
    no_spin.fix_rotation = true;
    scene.fixed_dofs = {no_spin};
    scene.material.translational_damping = 0.2;
    // The per-particle step (the run's 2e-4 s damp the normal oscillation out at that step).
    scene.time_step.from_stability_analysis = false;
    Simulation<2> simulation(packing, scene);
    EXPECT_TRUE(simulation.plan().wall_friction);
    RunOptions run;
    run.duration_s = 2e-4;
    simulation.Run(run);
    const double slide = simulation.particles().position[0].x();
    if (ratio < 1) {
      EXPECT_LT(std::abs(slide), 2 * ratio * mu * normal_load / 3.5e10);  // the spring's stretch
      EXPECT_NEAR(simulation.wall(0).force_on_wall.x(), ratio * mu * normal_load,
                  0.05 * mu * normal_load);
    } else {
      EXPECT_GT(slide, 1e-5);  // accelerating: far beyond any spring stretch
      EXPECT_NEAR(std::abs(simulation.wall(0).force_on_wall.x()), mu * normal_load,
                  0.01 * mu * normal_load);
      EXPECT_GT(simulation.Energy().friction_dissipation_j, 0.0);
    }
  }
}

}  // namespace
}  // namespace specimen
