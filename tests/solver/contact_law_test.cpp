// The bonded contact law (Labra (2.20)-(2.37), Madan (2.25)-(2.40)): sign conventions,
// breakage at exactly Rn (tension) and Rt (shear), Coulomb friction by radial return after
// breakage, no tension in a broken contact, and the rotation of the stored tangential force.

#include "solver/contact_law.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "solver/regular_lattice.h"
#include "solver/simulation.h"

namespace specimen {
namespace {

constexpr double kRadius = 1e-3, kNormalStiffness = 7e10;

// Two touching discs along x (0 at the origin, 1 at 2R), both with prescribed motion:
// disc 0 held, disc 1 driven by `drive` (one FixedDofs set per axis, so each axis has its
// own amplitude). Rotations held, so the relative motion is the drive.
SceneOptions<2> PairScene(const std::vector<FixedDofs<2>>& drive) {
  SceneOptions<2> scene;
  MaterialParameters& m = scene.material;
  m.normal_stiffness_n_per_m = kNormalStiffness;
  m.tangential_stiffness_n_per_m = 0.5 * kNormalStiffness;
  m.bond_tensile_strength_n = 1e4;
  m.bond_shear_strength_n = 5e3;
  m.friction_coefficient = 0.1;  // mu |fn| = 2e3 N < Rt in the friction test
  m.density_kg_per_m3 = 2000;
  FixedDofs<2> held;
  held.name = "held";
  held.particles = {0};
  held.fix_translation = {true, true};
  held.fix_rotation = true;
  scene.fixed_dofs = {held};
  for (const auto& d : drive) scene.fixed_dofs.push_back(d);
  scene.time_step.time_step_s = 1e-7;
  return scene;
}

FixedDofs<2> Drive(int axis, double velocity, const Amplitude& amplitude) {
  FixedDofs<2> d;
  d.name = axis == 0 ? "drive x" : "drive y";
  d.particles = {1};
  d.fix_translation = {axis == 0, axis == 1};
  d.fix_rotation = true;
  d.velocity = Vector<2>::Zero();
  d.velocity[axis] = velocity;
  d.amplitude = amplitude;
  return d;
}

struct Record {
  long step;
  ContactState state;
  double normal_force;
  double tangential_force;  // signed component along the tangent perp(n)
};

std::vector<Record> Follow(Simulation<2>& simulation, long steps) {
  std::vector<Record> records;
  RunOptions run;
  run.max_steps = steps;
  run.observe_interval = 1;
  run.observer = [&]() {
    const ContactArrays<2>& c = simulation.contacts();
    const double ft = c.tangential_force[0].dot(Perpendicular(c.normal[0]));
    records.push_back({simulation.step(), c.state[0], c.normal_elastic_force[0], ft});
  };
  simulation.Run(run);
  return records;
}

// Pulled apart at constant speed, the bond carries fn = kn g up to Rn and breaks at the first
// step whose force would exceed Rn; afterwards the pair carries nothing.
TEST(BondedContact, BreaksInTensionAtExactlyRn) {
  const double speed = 0.01;  // fn grows by kn v dt = 70 N per step
  Simulation<2> simulation(SquareLatticePacking(2, 1, kRadius),
                           PairScene({Drive(0, speed, Amplitude()), Drive(1, 0.0, Amplitude())}));
  ASSERT_TRUE(simulation.plan().breakable);
  const std::vector<Record> r = Follow(simulation, 400);
  size_t broken = 0;
  while (broken < r.size() && r[broken].state == ContactState::kBonded) ++broken;
  ASSERT_LT(broken, r.size()) << "the bond never broke";
  ASSERT_GT(broken, 1u);
  EXPECT_EQ(r[broken].state, ContactState::kBrokenInTension);
  // Every force the bond carried was at most Rn, and the next one would have exceeded it.
  for (size_t k = 0; k < broken; ++k) EXPECT_LE(r[k].normal_force, 1e4);
  const double increment = r[broken - 1].normal_force - r[broken - 2].normal_force;
  EXPECT_NEAR(increment, kNormalStiffness * speed * 1e-7, 1e-6 * increment);
  EXPECT_GT(r[broken - 1].normal_force + increment, 1e4);
  // The k-th force evaluation (t_k = k dt) sees g = k v dt: the bond breaks at the first k
  // with kn k v dt > Rn.
  EXPECT_EQ(broken, static_cast<size_t>(std::floor(1e4 / (kNormalStiffness * speed * 1e-7))) + 1);
  for (size_t k = broken; k < r.size(); ++k) {
    EXPECT_EQ(r[k].normal_force, 0.0);
    EXPECT_EQ(simulation.contacts().force[0].norm(), 0.0);
  }
  EXPECT_EQ(simulation.last_summary().broken_in_tension, 1);
  // The bond's elastic energy at the break is released, not lost from the audit.
  EXPECT_NEAR(simulation.Energy().breakage_release_j,
              0.5 * r[broken - 1].normal_force * r[broken - 1].normal_force / kNormalStiffness,
              0.02 * 0.5 * 1e8 / kNormalStiffness);
}

// Sheared at constant speed (no normal load), the bond breaks at the first step |ft| > Rt.
TEST(BondedContact, BreaksInShearAtExactlyRt) {
  const double speed = 0.01;  // ft grows by kt v dt = 35 N per step
  Simulation<2> simulation(SquareLatticePacking(2, 1, kRadius),
                           PairScene({Drive(0, 0.0, Amplitude()), Drive(1, speed, Amplitude())}));
  const std::vector<Record> r = Follow(simulation, 400);
  size_t broken = 0;
  while (broken < r.size() && r[broken].state == ContactState::kBonded) ++broken;
  ASSERT_LT(broken, r.size()) << "the bond never broke";
  EXPECT_EQ(r[broken].state, ContactState::kBrokenInShear);
  for (size_t k = 0; k < broken; ++k) EXPECT_LE(std::abs(r[k].tangential_force), 5e3);
  // The force on disc 0 (i) follows the motion of disc 1 (j) relative to it: +y.
  EXPECT_GT(r[broken - 1].tangential_force, 0.0);
  const double increment = r[broken - 1].tangential_force - r[broken - 2].tangential_force;
  EXPECT_NEAR(increment, 0.5 * kNormalStiffness * speed * 1e-7, 1e-4 * increment);
  EXPECT_GT(r[broken - 1].tangential_force + increment, 5e3);
  // The pair is not in compression, so after the break nothing is carried.
  for (size_t k = broken; k < r.size(); ++k) EXPECT_EQ(r[k].tangential_force, 0.0);
}

// Compressed first (fn = -2e4 N), then sheared: the bond breaks at Rt; afterwards the
// tangential force is capped at mu |fn| = 2e3 N (sliding, radial return); pulled apart, the
// broken contact carries no tension.
TEST(BondedContact, FrictionCapsTheShearForceAfterBreakage) {
  const double dt = 1e-7;
  const double approach_time = 2e4 / (kNormalStiffness * 0.1);  // fn = -2e4 N at 0.1 m/s
  Amplitude approach_then_hold;
  approach_then_hold.points = {
      {0.0, 1.0}, {approach_time, 1.0}, {approach_time, 0.0}, {300 * dt, 0.0}, {300 * dt, -1.0}};
  Amplitude shear_later;
  shear_later.points = {
      {0.0, 0.0}, {approach_time, 0.0}, {approach_time, 1.0}, {300 * dt, 1.0}, {300 * dt, 0.0}};
  Simulation<2> simulation(
      SquareLatticePacking(2, 1, kRadius),
      PairScene({Drive(0, -0.1, approach_then_hold), Drive(1, 0.02, shear_later)}));
  const std::vector<Record> r = Follow(simulation, 400);
  bool sheared = false, sliding_seen = false, apart_seen = false;
  for (const Record& k : r) {
    if (k.state == ContactState::kBrokenInShear) sheared = true;
    if (k.state == ContactState::kBonded) {
      EXPECT_LE(std::abs(k.tangential_force), 5e3);
      continue;
    }
    EXPECT_EQ(k.state, ContactState::kBrokenInShear);
    EXPECT_LE(k.normal_force, 0.0);  // a broken contact carries no tension
    EXPECT_LE(std::abs(k.tangential_force), 0.1 * std::abs(k.normal_force) * (1 + 1e-12) + 1e-9);
    if (k.normal_force < -1.9e4 &&
        std::abs(std::abs(k.tangential_force) - 0.1 * std::abs(k.normal_force)) <
            1e-9 * std::abs(k.normal_force))
      sliding_seen = true;
    if (k.normal_force == 0.0) apart_seen = true;
  }
  EXPECT_TRUE(sheared);
  EXPECT_TRUE(sliding_seen);
  // At the break the shear force drops from about Rt to the friction cap.
  size_t first = 0;
  while (r[first].state == ContactState::kBonded) ++first;
  EXPECT_GT(std::abs(r[first - 1].tangential_force), 0.9 * 5e3);
  EXPECT_NEAR(std::abs(r[first].tangential_force), 0.1 * std::abs(r[first].normal_force),
              1e-9 * 2e4);
  EXPECT_TRUE(apart_seen);
  EXPECT_GT(simulation.Energy().friction_dissipation_j, 0.0);
  EXPECT_EQ(simulation.contacts().force[0].norm(), 0.0);
}

// Unbreakable bonds (infinite strengths, kt = 0): no failure stage, tension carried.
TEST(BondedContact, UnbreakableBondsCarryTension) {
  SceneOptions<2> scene = PairScene({Drive(0, 0.01, Amplitude()), Drive(1, 0.0, Amplitude())});
  scene.material.bond_tensile_strength_n = std::numeric_limits<double>::infinity();
  scene.material.bond_shear_strength_n = std::numeric_limits<double>::infinity();
  Simulation<2> simulation(SquareLatticePacking(2, 1, kRadius), scene);
  EXPECT_FALSE(simulation.plan().breakable);
  const std::vector<Record> r = Follow(simulation, 300);
  EXPECT_EQ(r.back().state, ContactState::kBonded);
  // fn = kn g with g = v t at the force evaluation (t_n = (n - 1) dt after n steps).
  EXPECT_NEAR(r.back().normal_force, kNormalStiffness * 0.01 * 299 * 1e-7, 1e-6 * 2e4);
}

// 2D: the stored force follows the turn of the normal, magnitude kept.
TEST(TangentialRotation, TwoDimensionsTurnsWithTheNormal) {
  const Vector<2> n0(1, 0), n1(std::cos(0.3), std::sin(0.3));
  const Vector<2> f0(0, 5);
  const Vector<2> f1 = RotateTangentialForce(f0, n0, n1, 0.0);
  EXPECT_NEAR(f1.dot(n1), 0.0, 1e-15);
  EXPECT_NEAR(f1.norm(), 5.0, 1e-14);
  EXPECT_NEAR(f1.x(), -5 * std::sin(0.3), 1e-14);
  EXPECT_NEAR(f1.y(), 5 * std::cos(0.3), 1e-14);
}

// 3D: under a rigid-body rotation of the pair (normal turned, and the twist about it) in many
// small steps, the stored force keeps its magnitude exactly and follows the rotation.
TEST(TangentialRotation, ThreeDimensionsRigidRotationKeepsMagnitude) {
  const Vector<3> axis = Vector<3>(0.3, -0.5, 0.8).normalized();
  const double total_angle = 1.2;  // rad
  const int steps = 2000;
  const double angle_step = total_angle / steps;
  const Vector<3> n0 = Vector<3>(1, 0.2, -0.1).normalized();
  Vector<3> f = Vector<3>(0.1, -0.4, 0.3);
  f -= f.dot(n0) * n0;
  const double magnitude = f.norm();
  const Vector<3> f_start = f;
  Vector<3> n = n0;
  for (int k = 1; k <= steps; ++k) {
    const Vector<3> next = Eigen::AngleAxisd(k * angle_step, axis) * n0;
    // Spin w = axis * angle_step / dt; twist = dt w . n (here with the new normal).
    f = RotateTangentialForce(f, n, next, angle_step * axis.dot(next));
    n = next;
    EXPECT_NEAR(f.norm(), magnitude, 1e-12 * magnitude);
    EXPECT_NEAR(f.dot(n), 0.0, 1e-12 * magnitude);
  }
  const Vector<3> expected = Eigen::AngleAxisd(total_angle, axis) * f_start;
  EXPECT_NEAR((f - expected).norm(), 0.0, 2e-3 * magnitude);
}

}  // namespace
}  // namespace specimen
