// Lattice oracles: Madan's SC specimen under uniaxial load (A2 DEM, A3 DDEM, A4 energy
// audit; Madan section 4.4, Tables 4.2-4.3) and the hexagonal packing of equal discs under
// homogeneous strain (O7; the labels are those of docs/sources.md). Expected values are the
// sources' closed forms and tables, never numbers this code produced.

#include <gtest/gtest.h>

#include <cmath>

#include "solver/homogenisation.h"
#include "solver/scene_state.h"
#include "tests/solver/madan_specimens.h"

namespace specimen {
namespace {

using namespace madan;

struct StaticResult {
  Spans spans;
  EnergyBalance energy;
  RunSummary summary;
};

// Loads ramped over ramp_s, local damping 0.3 (the thesis damps with contact dashpots,
// xi_n = 5, Madan section 4.4; the static state does not depend on the damping), run until
// the unbalanced force ratio is below 1e-11.
StaticResult RunSquareToStatic(std::optional<double> particle_modulus, double ramp_s) {
  const Specimen specimen = SquareSpecimen();
  Simulation<2> simulation(specimen.packing, Scene(specimen, particle_modulus, ramp_s, 0.3));
  RunOptions run;
  run.max_steps = 400000;
  run.min_steps = std::lround(ramp_s / simulation.time_step_s()) + 10;
  run.static_force_ratio = 1e-9;
  StaticResult result;
  result.summary = simulation.Run(run);
  result.spans = MeasureSpans(specimen, simulation.particles());
  result.energy = simulation.Energy();
  return result;
}

// A2: SC DEM, dH = 19 f / kn = 2.71429e-6 m, E = kn / l = 70.0 GPa, nu = 0.
TEST(MadanSquareLattice, A2RigidParticles) {
  const StaticResult r = RunSquareToStatic(std::nullopt, 1e-4);
  ASSERT_EQ(r.summary.termination, TerminationReason::kStatic) << r.summary.FullReport();
  const double dh = -r.spans.height_change_m;
  const double strain_y = -dh / 0.038, strain_x = r.spans.width_change_m / 0.016;
  const double e = (9.0 * kRowForce / 0.018) / (dh / 0.038);
  EXPECT_NEAR(dh, 2.71429e-6, 0.001 * 2.71429e-6);
  EXPECT_NEAR(dh, SquareTheory(std::nullopt).height_change_m, 1e-7 * dh);
  EXPECT_NEAR(e, 70.0e9, 0.001 * 70.0e9);
  EXPECT_NEAR(-strain_x / strain_y, 0.0, 1e-9);
  // The stages of a rigid, unbreakable, kt = 0 scene.
  const auto& stages = r.summary.stages;
  EXPECT_EQ(std::count(stages.begin(), stages.end(), "ddem_particle_strain"), 0);
  // DEM: the audit closes (W_ext = 1/2 F dH = E_el + damping losses).
  EXPECT_NEAR(r.energy.contact_elastic_j, 9 * 19 * kRowForce * kRowForce / (2 * kNormalStiffness),
              1e-6 * r.energy.contact_elastic_j);
  EXPECT_LT(r.energy.RelativeImbalance(), 1e-3) << r.energy.Table("  ");
}

// A3: SC DDEM, nu_p = 0.35, plane strain, loads in the particle stress: thesis Table 4.2
// rows, compared with the exact closed forms (2.67), (2.72), (4.26), (4.27) within 0.1 %
// and with the thesis' rounded numbers within their last digit.
TEST(MadanSquareLattice, A3DeformableParticles) {
  struct Row {
    double kn_over_ep, dh, nu, e_gpa;
  };
  const Row rows[] = {{0.0875, 2.9796e-6, 0.048, 63.77},
                      {0.175, 3.2450e-6, 0.088, 58.55},
                      {0.35, 3.7757e-6, 0.151, 50.32}};
  for (const Row& row : rows) {
    SCOPED_TRACE("kn/Ep = " + std::to_string(row.kn_over_ep));
    const double ep = kNormalStiffness / row.kn_over_ep;
    const StaticResult r = RunSquareToStatic(ep, 1e-4);
    ASSERT_EQ(r.summary.termination, TerminationReason::kStatic) << r.summary.FullReport();
    const SquareClosedForm theory = SquareTheory(ep);
    const double dh = -r.spans.height_change_m;
    const double strain_y = -dh / 0.038, strain_x = r.spans.width_change_m / 0.016;
    const double nu = -strain_x / strain_y;
    const double e = (9.0 * kRowForce / 0.018) / (dh / 0.038);
    EXPECT_NEAR(dh, theory.height_change_m, 0.001 * theory.height_change_m);
    EXPECT_NEAR(nu, theory.poisson, 0.001 * theory.poisson);
    EXPECT_NEAR(e, theory.youngs_modulus_pa, 0.001 * theory.youngs_modulus_pa);
    EXPECT_NEAR(dh, row.dh, 0.00005e-6);
    EXPECT_NEAR(nu, row.nu, 0.0005);
    EXPECT_NEAR(e / 1e9, row.e_gpa, 0.005);
    std::printf(
        "A3 kn/Ep = %.4f: dH = %.5e m (theory %.5e), nu = %.5f (%.5f), E = %.4f GPa (%.4f)\n",
        row.kn_over_ep, dh, theory.height_change_m, nu, theory.poisson, e / 1e9,
        theory.youngs_modulus_pa / 1e9);
  }
}

// A4: energy audit of A3 at kn/Ep = 0.35 (thesis Table 4.3): E_el,c = 0.1221 J,
// E_el,p = 0.0503 J, W_ext = 0.1699 J within 2 %. The thesis' W_ext = 1/2 F dH (4.29) is the
// work on the centre displacements; the load points also move with the particle deformation
// (eps s), and with that work included the audit closes (the thesis' sum was 1.5 % off).
// The load is ramped slowly (0.5 ms) so that the path work approaches the static value.
TEST(MadanSquareLattice, A4EnergyAudit) {
  const StaticResult r = RunSquareToStatic(kNormalStiffness / 0.35, 5e-4);
  ASSERT_EQ(r.summary.termination, TerminationReason::kStatic) << r.summary.FullReport();
  const EnergyBalance& e = r.energy;
  const double centre_work = e.load_work_j - e.load_deformation_work_j;
  EXPECT_NEAR(e.contact_elastic_j, 0.1221, 0.02 * 0.1221) << e.Table("  ");
  EXPECT_NEAR(e.particle_elastic_j, 0.0503, 0.02 * 0.0503) << e.Table("  ");
  EXPECT_NEAR(centre_work, 0.1699, 0.02 * 0.1699) << e.Table("  ");
  // The deformation work of the 18 loaded particles: 1/2 f R eps_yy each, with
  // eps_yy = (1 - nu^2) 2 f / (pi R Ep) (plane strain) = 0.0025 J.
  const double eps = (1 - kParticlePoisson * kParticlePoisson) * 2 * kRowForce /
                     (kPi * kRadius * kNormalStiffness / 0.35);
  EXPECT_NEAR(e.load_deformation_work_j, 18 * 0.5 * kRowForce * kRadius * eps, 0.02 * 0.0025);
  EXPECT_LT(e.RelativeImbalance(), 0.002) << e.Table("  ");
  std::printf(
      "A4: E_el,c = %.5f J, E_el,p = %.5f J, W_ext (centres) = %.5f J, W_ext (load "
      "points) = %.5f J, damping %.5f J, imbalance %.3f %%\n",
      e.contact_elastic_j, e.particle_elastic_j, centre_work, e.load_work_j,
      e.damping_dissipation_j, 100 * e.RelativeImbalance());
}

// O7: a hexagonal packing of equal discs with kn, kt under homogeneous (uniaxial) strain.
// The boundary discs are driven on the affine field (translations, and zero spin, which is the
// affine spin of a symmetric strain), the interior relaxes (damped) to it: by central symmetry
// every interior disc is in equilibrium there, forces and moments; the
// interior stress over the Voronoi cells (2 sqrt(3) R^2 each) gives lambda and mu, hence
//   E = 2 sqrt(3) kn (kn + kt) / (3 kn + kt),  nu = (kn - kt) / (3 kn + kt)   (per unit l).
TEST(HexagonalPacking, O7ElasticConstantsFromKnKt) {
  constexpr int kRows = 15, kDiscs = 14;
  const double radius = 1e-3, kn = 7e10, strain = -1e-6;
  const Packing<2> packing = HexagonalLatticePacking(kRows, kDiscs, kDiscs, radius);
  // Boundary: first and last row, first and last disc of every row.
  std::vector<int> boundary, interior;
  Vector<2> centre = Vector<2>::Zero();
  for (const auto& x : packing.centres) centre += x / packing.size();
  for (int r = 0, index = 0; r < kRows; ++r)
    for (int c = 0; c < kDiscs; ++c, ++index)
      (r == 0 || r == kRows - 1 || c == 0 || c == kDiscs - 1 ? boundary : interior)
          .push_back(index);
  for (const double ratio : {0.0, 0.25, 1.0}) {
    SCOPED_TRACE("kt/kn = " + std::to_string(ratio));
    const double kt = ratio * kn;
    SceneOptions<2> scene;
    scene.material.normal_stiffness_n_per_m = kn;
    scene.material.tangential_stiffness_n_per_m = kt;
    scene.material.density_kg_per_m3 = 2000;
    scene.material.translational_damping = 0.3;
    scene.material.rotational_damping = 0.3;
    // Affine velocity v = rate (0, y - yc) for 20 us (triangle amplitude), then held.
    const double ramp = 2e-5, rate = strain / ramp;
    FixedDofs<2> driven;
    driven.name = "affine boundary";
    driven.particles = boundary;
    driven.fix_translation = {true, true};
    driven.fix_rotation = true;  // the affine field has no spin; free boundary spins would not be
    for (int q : boundary)
      driven.particle_velocities.push_back(
          Vector<2>(0.0, rate * (packing.centres[q].y() - centre.y())));
    driven.amplitude.points = {{0.0, 0.0}, {ramp / 2, 2.0}, {ramp, 0.0}};
    scene.fixed_dofs = {driven};
    Simulation<2> simulation(packing, scene);
    RunOptions run;
    run.max_steps = 200000;
    run.min_steps = std::lround(ramp / simulation.time_step_s()) + 10;
    run.static_force_ratio = 1e-7;
    const RunSummary summary = simulation.Run(run);
    ASSERT_EQ(summary.termination, TerminationReason::kStatic) << summary.FullReport();
    // The strain actually imposed, from the top boundary disc's displacement.
    const int top = boundary.back();
    const double imposed = (simulation.particles().position[top].y() - packing.centres[top].y()) /
                           (packing.centres[top].y() - centre.y());
    EXPECT_NEAR(imposed, strain, 0.01 * std::abs(strain));
    const double cell = 2.0 * std::sqrt(3.0) * radius * radius;
    const Eigen::Matrix2d stress =
        LoveWeberStress<2>(simulation.state(), interior, cell * interior.size());
    const double lambda = stress(0, 0) / imposed;
    const double mu = (stress(1, 1) - stress(0, 0)) / (2.0 * imposed);
    const double e = 4.0 * mu * (lambda + mu) / (lambda + 2.0 * mu);
    const double nu = lambda / (lambda + 2.0 * mu);
    const double e_expected = 2.0 * std::sqrt(3.0) * kn * (kn + kt) / (3.0 * kn + kt);
    const double nu_expected = (kn - kt) / (3.0 * kn + kt);
    EXPECT_NEAR(e, e_expected, 0.005 * e_expected);
    EXPECT_NEAR(nu, nu_expected, 0.005 * std::max(std::abs(nu_expected), 0.01));
    EXPECT_NEAR(stress(0, 1), 0.0, 1e-6 * std::abs(stress(1, 1)));
    std::printf("O7 kt/kn = %.2f: E = %.6e Pa (closed form %.6e), nu = %.6f (%.6f), %ld steps\n",
                ratio, e, e_expected, nu, nu_expected, summary.steps);
  }
}

}  // namespace
}  // namespace specimen
