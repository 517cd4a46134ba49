// 3D smoke tests of the solver core: an undamped bonded pair of spheres spinning and
// vibrating in shear keeps its energy (and angular momentum), and a 3D bond breaks at Rn.

#include <gtest/gtest.h>

#include <cmath>

#include "solver/regular_lattice.h"
#include "solver/simulation.h"

namespace specimen {
namespace {

SceneOptions<3> PairScene() {
  SceneOptions<3> scene;
  scene.material.normal_stiffness_n_per_m = 1e8;
  scene.material.tangential_stiffness_n_per_m = 5e7;
  scene.material.density_kg_per_m3 = 2000;
  return scene;
}

Vector<3> AngularMomentum(const Simulation<3>& simulation) {
  const ParticleArrays<3>& p = simulation.particles();
  Vector<3> total = Vector<3>::Zero();
  for (int q = 0; q < p.size(); ++q)
    total += p.mass[q] * p.position[q].cross(p.velocity[q]) +
             p.angular_velocity[q] / p.inverse_inertia[q];
  return total;
}

// Two bonded spheres given opposite velocities across the bond and spins: the pair turns
// about a revolution while the bond vibrates in shear, twist and stretch. Undamped, the audit
// (kinetic + elastic against the initial energy) must close: the incremental tangential law
// drifts at second order in dt here, so the check is made at 0.2 and 0.1 of the per-particle
// bound (the 2-sphere shear-rotation mode has omega^2 = 7 kt/m, above the bound's 2.75e8/m).
double SpinningPairImbalance(double safety, RunSummary* summary, double* swept_angle,
                             double* momentum_change) {
  const Packing<3> packing = CubicLatticePacking(2, 1, 1, 1e-3);
  SceneOptions<3> scene = PairScene();
  scene.time_step.safety_factor = safety;
  Simulation<3> simulation(packing, scene);
  simulation.SetVelocity(0, Vector<3>(0.0, -2.0, -1.0));
  simulation.SetVelocity(1, Vector<3>(0.0, 2.0, 1.0));
  simulation.SetAngularVelocity(0, Vector<3>(300.0, -200.0, 500.0));
  simulation.SetAngularVelocity(1, Vector<3>(-100.0, 400.0, 200.0));
  const Vector<3> momentum0 = AngularMomentum(simulation);
  RunOptions run;
  run.duration_s = 4e-3;
  double largest_imbalance = 0.0;
  Vector<3> last_normal(1, 0, 0);
  *swept_angle = 0.0;
  run.observe_interval = 100;
  run.observer = [&]() {
    largest_imbalance = std::max(largest_imbalance, simulation.Energy().RelativeImbalance());
    const Vector<3>& n = simulation.contacts().normal[0];
    *swept_angle += std::acos(std::min(1.0, n.dot(last_normal)));
    last_normal = n;
  };
  *summary = simulation.Run(run);
  EXPECT_TRUE(simulation.plan().rotation);
  EXPECT_TRUE(simulation.plan().tangential);
  *momentum_change = (AngularMomentum(simulation) - momentum0).norm() / momentum0.norm();
  return largest_imbalance;
}

TEST(ThreeDimensions, SpinningShearedPairConservesEnergy) {
  RunSummary coarse_summary, summary;
  double swept = 0.0, momentum_change = 0.0;
  const double coarse = SpinningPairImbalance(0.2, &coarse_summary, &swept, &momentum_change);
  const double fine = SpinningPairImbalance(0.1, &summary, &swept, &momentum_change);
  const EnergyBalance& e = summary.energy;
  EXPECT_GT(e.initial_total_j, 0.0);
  EXPECT_GT(e.contact_elastic_j, 1e-3 * e.initial_total_j);  // the bond works
  EXPECT_LT(fine, 1e-3) << e.Table("  ");
  EXPECT_LT(fine, 0.5 * coarse);  // converging with dt
  // The pair really turned: the bond normal swept more than a full turn.
  EXPECT_GT(swept, 2 * 3.14159265358979);
  // Angular momentum about the origin: conserved up to the bond gap (arms R n, not d/2).
  EXPECT_LT(momentum_change, 1e-3);
  std::printf(
      "3D pair: %ld steps, normal swept %.2f rad, largest audit imbalance %.2e (%.2e at "
      "twice the step), angular momentum change %.2e\n",
      summary.steps, swept, fine, coarse, momentum_change);
}

TEST(ThreeDimensions, BondBreaksInTensionAtRn) {
  const Packing<3> packing = CubicLatticePacking(1, 1, 2, 1e-3);
  SceneOptions<3> scene = PairScene();
  scene.material.bond_tensile_strength_n = 50.0;
  FixedDofs<3> held;
  held.particles = {0};
  held.fix_translation = {true, true, true};
  FixedDofs<3> pulled = held;
  pulled.particles = {1};
  pulled.velocity = Vector<3>(0, 0, 0.01);  // fn grows by kn v dt per step
  scene.fixed_dofs = {held, pulled};
  scene.time_step.time_step_s = 1e-7;
  Simulation<3> simulation(packing, scene);
  double largest = 0.0;
  long broken_at = -1;
  RunOptions run;
  run.max_steps = 1000;
  run.observe_interval = 1;
  run.observer = [&]() {
    if (simulation.contacts().state[0] == ContactState::kBonded)
      largest = std::max(largest, simulation.contacts().normal_elastic_force[0]);
    else if (broken_at < 0)
      broken_at = simulation.step() - 1;  // the force evaluation that broke it
  };
  simulation.Run(run);
  EXPECT_EQ(simulation.contacts().state[0], ContactState::kBrokenInTension);
  EXPECT_LE(largest, 50.0);
  EXPECT_GT(largest, 50.0 - 1e8 * 0.01 * 1e-7 * 1.001);
  EXPECT_EQ(broken_at, static_cast<long>(std::floor(50.0 / (1e8 * 0.01 * 1e-7))) + 1);
}

}  // namespace
}  // namespace specimen
