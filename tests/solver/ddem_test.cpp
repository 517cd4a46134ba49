// DDEM (Madan 2019): particle compliance (2.46)-(2.49), the implicit force iteration on a
// row of discs (A1, thesis Table 3.1 and (3.24)-(3.27)), the two-particle FEM equivalence
// (A13, thesis section 2.9), and the rigid limit Ep -> infinity.

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"
#include "solver/regular_lattice.h"
#include "solver/scene_state.h"
#include "solver/simulation.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(ParticleCompliance, PlaneStrainPlaneStressAndThreeDimensions) {
  const double e = 2e11, nu = 0.35;
  const SymmetricTensor<2> stress(3e6, -5e6, 2e6);
  // Madan (2.48): plane strain.
  const ParticleCompliance<2> strain_model(e, nu, PlaneModel::kPlaneStrain);
  const SymmetricTensor<2> a = strain_model.Strain(stress);
  const double tolerance = 1e-12 * 5e6 / e;
  EXPECT_NEAR(a[0], (1 + nu) / e * ((1 - nu) * stress[0] - nu * stress[1]), tolerance);
  EXPECT_NEAR(a[1], (1 + nu) / e * ((1 - nu) * stress[1] - nu * stress[0]), tolerance);
  EXPECT_NEAR(2 * a[2], 2 * (1 + nu) / e * stress[2], tolerance);  // engineering shear
  // Madan (2.49): plane stress.
  const ParticleCompliance<2> stress_model(e, nu, PlaneModel::kPlaneStress);
  const SymmetricTensor<2> b = stress_model.Strain(stress);
  EXPECT_NEAR(b[0], (stress[0] - nu * stress[1]) / e, tolerance);
  EXPECT_NEAR(b[1], (stress[1] - nu * stress[0]) / e, tolerance);
  EXPECT_NEAR(b[2], (1 + nu) / e * stress[2], tolerance);
  // Inverses.
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(strain_model.Stress(a)[k], stress[k], 1e-9 * 5e6);
    EXPECT_NEAR(stress_model.Stress(b)[k], stress[k], 1e-9 * 5e6);
  }
  // 3D isotropic Hooke: uniaxial stress gives eps = sigma/E axially, -nu sigma/E laterally.
  const ParticleCompliance<3> solid(e, nu, PlaneModel::kPlaneStrain);
  SymmetricTensor<3> uniaxial = SymmetricTensor<3>::Zero();
  uniaxial[2] = -1e7;
  const SymmetricTensor<3> c = solid.Strain(uniaxial);
  EXPECT_NEAR(c[2], -1e7 / e, 1e-12 * 1e7 / e);
  EXPECT_NEAR(c[0], nu * 1e7 / e, 1e-12 * 1e7 / e);
  EXPECT_NEAR(c[1], nu * 1e7 / e, 1e-12 * 1e7 / e);
  SymmetricTensor<3> general;
  general << 1e6, -2e6, 3e6, 4e5, -5e5, 6e5;
  const SymmetricTensor<3> back = solid.Stress(solid.Strain(general));
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(back[k], general[k], 1e-9 * 3e6);
}

// A row of discs at fixed centre spacing d = 1.99 mm (overlap h = 1e-5 m), kn = 7e10,
// nu_p = 0.35, plane strain: the row of thesis section 3.4. The middle contact of a 41-disc
// row sees the infinite row (end effects decay by a factor <= 0.27 per disc).
Simulation<2> Row(double particle_modulus) {
  constexpr int kDiscs = 41;
  Packing<2> packing(Domain<2>::Rectangle(-0.01, -0.01, 0.1, 0.01));
  for (int k = 0; k < kDiscs; ++k) {
    packing.centres.emplace_back(1.99e-3 * k, 0.0);
    packing.radii.push_back(1e-3);
    if (k > 0) packing.contacts.push_back({k - 1, k});
  }
  SceneOptions<2> scene;
  scene.material.normal_stiffness_n_per_m = 7e10;
  scene.material.density_kg_per_m3 = 2000;
  scene.material.particle_youngs_modulus_pa = particle_modulus;
  scene.material.particle_poisson_ratio = 0.35;
  scene.contacts.stress_free_bonds = false;  // the overlap is the step load
  scene.contacts.detect_new_contacts = false;
  // Ep = 7.5e10 is beyond rho(B) = 1 on purpose (the divergence check): the Simulation would
  // refuse it (stability analysis) unless forced.
  scene.time_step.allow_above_critical = true;
  return Simulation<2>(packing, scene);
}

// A1: Table 3.1 forces (thesis rounded, with pi ~ 3.14 in kp) and the exact series-spring
// force kn h / (1 + 2 kn / kp), kp = pi Ep / (2 (1 - nu^2)) (2.72), the iteration ratio
// -2 kn / kp (3.25), and divergence at Ep = 7.5e10 (ratio 1.043).
TEST(DdemForceIteration, A1RowConvergesToTheSeriesSpringForce) {
  const double kn = 7e10, h = 1e-5, nu = 0.35;
  const double moduli[] = {5e11, 4e11, 3e11, 2e11, 1e11, 0.8e11};
  const double table_kn[] = {605.3, 585.5, 555.2, 503.2, 392.8, 354.0};
  for (int k = 0; k < 6; ++k) {
    SCOPED_TRACE("Ep = " + std::to_string(moduli[k]));
    Simulation<2> row = Row(moduli[k]);
    ForceIterationOptions options;
    options.max_iterations = 5000;
    options.tolerance = 1e-13;
    options.watched_contact = 20;
    const ForceIterationSummary s = row.IterateDeformedContactForces(options);
    ASSERT_TRUE(s.converged) << s.termination;
    const double kp = kPi * moduli[k] / (2 * (1 - nu * nu));
    const double ratio = 2 * kn / kp;
    const double expected = kn * h / (1 + ratio);
    const double force = -s.watched_normal_force_n.back();  // compression is negative
    EXPECT_NEAR(force, expected, 1e-9 * expected);
    EXPECT_NEAR(force / 1e3, table_kn[k], 0.05);
    // The first iterations at the middle contact follow Madan (3.24) exactly:
    // df^(k+1) = -(2 kn / kp) df^(k).
    const auto& f = s.watched_normal_force_n;
    EXPECT_NEAR(f[1], -kn * h, 1e-9 * kn * h);
    // (Force differences lose digits as they shrink: compare the first few.)
    for (int i = 2; i < 7; ++i)
      EXPECT_NEAR((f[i] - f[i - 1]) / (f[i - 1] - f[i - 2]), -ratio, 1e-7);
    std::printf("A1 Ep = %.2e: f = %.4f kN (exact %.4f, thesis %.1f), ratio %.5f, %d iterations\n",
                moduli[k], force / 1e3, expected / 1e3, table_kn[k], -ratio, s.iterations);
  }
  // Divergence at Ep = 7.5e10: 2 kn / kp = 1.043.
  Simulation<2> row = Row(7.5e10);
  ForceIterationOptions options;
  options.max_iterations = 5000;
  options.watched_contact = 20;
  const ForceIterationSummary s = row.IterateDeformedContactForces(options);
  EXPECT_TRUE(s.diverged) << s.termination;
  EXPECT_FALSE(s.converged);
  const double ratio = 4 * kn * (1 - nu * nu) / (kPi * 7.5e10);
  EXPECT_NEAR(ratio, 1.043, 0.0005);
  const auto& f = s.watched_normal_force_n;
  EXPECT_NEAR((f[3] - f[2]) / (f[2] - f[1]), -ratio, 1e-9);
  // The finite row's dominant mode is slightly below the infinite row's: > 1 all the same.
  EXPECT_GT(s.change_ratio, 1.0);
  EXPECT_LT(s.change_ratio, ratio + 1e-9);
  std::printf("A1 Ep = 7.5e10: diverged after %d iterations, observed ratio %.4f (row %.4f)\n",
              s.iterations, s.change_ratio, ratio);
}

TEST(DdemForceIteration, RefusesRigidParticles) {
  Packing<2> packing = SquareLatticePacking(2, 1, 1e-3);
  SceneOptions<2> scene;
  scene.material.normal_stiffness_n_per_m = 7e10;
  scene.material.density_kg_per_m3 = 2000;
  Simulation<2> simulation(packing, scene);
  EXPECT_THROW(simulation.IterateDeformedContactForces(ForceIterationOptions()), InputError);
}

// A13: two discs, plane stress, Ep = 2e11, nu_p = 0.35, R = 1 mm, kn = 3.32e10, f = 10 kN at
// the outer poles: centre approach 3.65e-7 m (FEM, within 1 %), lateral diameter change
// 2R eps_xx = 2.23e-8 m (thesis section 2.9).
TEST(DdemTwoParticles, A13PlaneStressEquivalence) {
  Packing<2> packing = SquareLatticePacking(1, 2, 1e-3);  // disc 0 below disc 1
  SceneOptions<2> scene;
  MaterialParameters& m = scene.material;
  m.normal_stiffness_n_per_m = 3.32e10;
  m.density_kg_per_m3 = 2000;
  m.particle_youngs_modulus_pa = 2e11;
  m.particle_poisson_ratio = 0.35;
  m.plane_model = PlaneModel::kPlaneStress;
  m.translational_damping = 0.3;
  PointLoad<2> top;
  top.particles = {1};
  top.force_n = Vector<2>(0, -1e4);
  top.application_direction = Vector<2>(0, 1);
  top.amplitude = Amplitude::Ramp(2e-5);
  PointLoad<2> bottom = top;
  bottom.particles = {0};
  bottom.force_n = Vector<2>(0, 1e4);
  bottom.application_direction = Vector<2>(0, -1);
  scene.point_loads = {top, bottom};
  Simulation<2> simulation(packing, scene);
  RunOptions run;
  run.max_steps = 100000;
  run.min_steps = 200;
  run.static_force_ratio = 1e-10;
  const RunSummary summary = simulation.Run(run);
  ASSERT_EQ(summary.termination, TerminationReason::kStatic) << summary.FullReport();
  const auto& x = simulation.particles().position;
  const double approach = 2e-3 - (x[1].y() - x[0].y());
  EXPECT_NEAR(approach, 3.65e-7, 0.01 * 3.65e-7);
  const double diameter_change = 2e-3 * simulation.particles().strain[1][0];
  EXPECT_NEAR(diameter_change, 2.23e-8, 0.01 * 2.23e-8);
  // The particle stress is the thesis' -2 f R / (pi R^2) = -6.37 MPa.
  EXPECT_NEAR(simulation.ParticleStress(1)[1], -2 * 1e4 / (kPi * 1e-3), 1e-6 * 6.37e6);
  std::printf("A13: approach %.4e m (FEM 3.65e-7), diameter change %.4e m (thesis 2.23e-8)\n",
              approach, diameter_change);
}

// Rigid limit: Ep = 1e30 reproduces the rigid (DEM) trajectory to round-off, with the whole
// machinery on (tangential springs, rotation, damping, loads, fixed dofs, failure check).
TEST(DdemRigidLimit, HugeParticleModulusReproducesDem) {
  const Packing<2> packing = HexagonalLatticePacking(8, 8, 8, 1e-3);
  auto scene = [&](std::optional<double> modulus) {
    SceneOptions<2> s;
    MaterialParameters& m = s.material;
    m.normal_stiffness_n_per_m = 7e10;
    m.tangential_stiffness_n_per_m = 2.8e10;
    m.bond_tensile_strength_n = 1e6;
    m.bond_shear_strength_n = 1e6;
    m.friction_coefficient = 0.5;
    m.density_kg_per_m3 = 2000;
    m.particle_youngs_modulus_pa = modulus;
    m.particle_poisson_ratio = 0.3;
    m.translational_damping = 0.1;
    m.rotational_damping = 0.1;
    PointLoad<2> load;
    for (int c = 0; c < 8; ++c) load.particles.push_back(7 * 8 + c);
    load.force_n = Vector<2>(3e3, -1e4);  // oblique: shear and rotation
    load.application_direction = Vector<2>(0, 1);
    load.amplitude = Amplitude::Ramp(5e-5);
    s.point_loads = {load};
    FixedDofs<2> base;
    for (int c = 0; c < 8; ++c) base.particles.push_back(c);
    base.fix_translation = {true, true};
    base.fix_rotation = true;
    s.fixed_dofs = {base};
    s.time_step.time_step_s = 1e-7;
    return s;
  };
  Simulation<2> rigid(packing, scene(std::nullopt));
  Simulation<2> stiff(packing, scene(1e30));
  EXPECT_FALSE(rigid.plan().deformable);
  EXPECT_TRUE(stiff.plan().deformable);
  RunOptions run;
  run.max_steps = 2000;
  rigid.Run(run);
  stiff.Run(run);
  double largest_move = 0.0, largest_difference = 0.0;
  for (int q = 0; q < packing.size(); ++q) {
    largest_move =
        std::max(largest_move, (rigid.particles().position[q] - packing.centres[q]).norm());
    largest_difference = std::max(
        largest_difference, (rigid.particles().position[q] - stiff.particles().position[q]).norm());
    EXPECT_NEAR(rigid.particles().rotation_angle[q], stiff.particles().rotation_angle[q], 1e-15);
  }
  EXPECT_GT(largest_move, 1e-7);
  EXPECT_LE(largest_difference, 1e-15 * 0.02);  // round-off of coordinates ~ 0.02 m
  std::printf("rigid limit: largest move %.3e m, largest difference %.3e m\n", largest_move,
              largest_difference);
}

// The contact pass reads each particle's strain as a row r eps with doubled shear terms
// (scene_state.h, ContactDeformation): the dot product with the normal's products must be
// Madan's (2.53) r_i n.eps_i.n + r_j n.eps_j.n.
TEST(DdemContactDeformation, RowsGiveTheNormalDisplacementsOfTheContactPoints) {
  SymmetricTensor<2> a2(3e-4, -2e-4, 5e-5), b2(-1e-4, 4e-4, -7e-5);
  ContactDeformation<2> ra2, rb2;
  ra2.Set(a2, 1.5e-3);
  rb2.Set(b2, 0.7e-3);
  const Vector<2> n2 = Vector<2>(0.6, -0.8);
  EXPECT_NEAR(NormalDisplacementSum(ra2, rb2, n2),
              1.5e-3 * QuadraticForm(a2, n2) + 0.7e-3 * QuadraticForm(b2, n2), 1e-20);
  SymmetricTensor<3> a3, b3;
  a3 << 3e-4, -2e-4, 1e-4, 5e-5, -6e-5, 2e-5;
  b3 << -1e-4, 4e-4, -3e-4, -7e-5, 1e-5, 8e-5;
  ContactDeformation<3> ra3, rb3;
  ra3.Set(a3, 1.5e-3);
  rb3.Set(b3, 0.7e-3);
  const Vector<3> n3 = Vector<3>(0.48, -0.6, 0.64);
  EXPECT_NEAR(NormalDisplacementSum(ra3, rb3, n3),
              1.5e-3 * QuadraticForm(a3, n3) + 0.7e-3 * QuadraticForm(b3, n3), 1e-20);
  EXPECT_EQ(sizeof(ContactDeformation<3>), 64u);  // one cache line per particle
  EXPECT_EQ(alignof(ContactDeformation<3>), 64u);
}

// The strains the force iteration leaves are the ones the next step's contact pass uses:
// at the iteration's fixed point, the step reproduces the converged forces (it would not
// with the contact pass's copy of the strains of the step before the iteration).
TEST(DdemForceIteration, NextStepStartsFromTheIteratedStrains) {
  Simulation<2> row = Row(5e11);
  RunOptions one;
  one.max_steps = 1;
  row.Run(one);  // strains of a first step, then the iteration changes them
  ForceIterationOptions options;
  options.max_iterations = 5000;
  options.tolerance = 1e-13;
  options.watched_contact = 20;
  const ForceIterationSummary s = row.IterateDeformedContactForces(options);
  ASSERT_TRUE(s.converged) << s.termination;
  const double converged = s.watched_normal_force_n.back();
  row.Run(one);
  EXPECT_NEAR(row.contacts().normal_elastic_force[20], converged, 1e-9 * std::abs(converged));
}

}  // namespace
}  // namespace specimen
