// The stability analysis against the oracles of the sources: the closed forms of the DDEM
// convergence limit (A9: Madan (3.42), (3.78)), the finite-specimen limits of Madan Tables
// 3.2 and 3.3 (numerical columns), the critical time steps of the SC and HCP specimens for
// DEM and DDEM (A5, A6: Madan Figs. 3.7, 3.13) confirmed by real runs, the exact
// triangular-lattice limit (O6) confirmed by real runs, Ep -> infinity, a 3D case, and the
// solver's use of the analysis. The labels are those of docs/sources.md, the other expected
// values those of docs/stability.md, "Validation".

#include "stability/stability_analysis.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/error.h"
#include "tests/solver/madan_specimens.h"

namespace specimen {
namespace {

using namespace madan;

const double kMass = kDensity * kPi * kRadius * kRadius;  // 6.283e-3 kg per metre

StabilitySummary Analyse(const Packing<2>& packing, const SceneOptions<2>& scene) {
  StabilityOptions options;
  return AnalyseStability<2>(packing, scene, options);
}

// kt = 0, rigid or DDEM (plane strain), no loads or constraints.
SceneOptions<2> PlainScene(std::optional<double> modulus, double poisson) {
  SceneOptions<2> scene;
  scene.material.normal_stiffness_n_per_m = kNormalStiffness;
  scene.material.density_kg_per_m3 = kDensity;
  scene.material.particle_youngs_modulus_pa = modulus;
  scene.material.particle_poisson_ratio = poisson;
  return scene;
}

// A9: rho(B) of large SC and HCP blocks against the infinite-lattice closed forms. A finite
// block is slightly more permissive (boundary particles have fewer contacts).
TEST(StabilityClosedForms, A9LargeBlocksApproachTheLatticeFormulas) {
  for (const double nu : {0.05, 0.2, 0.35, 0.45}) {
    SCOPED_TRACE("nu_p = " + std::to_string(nu));
    const LatticeLimits formula = ClosedFormLimits(2, nu, PlaneModel::kPlaneStrain);
    EXPECT_NEAR(formula.square, kPi / (4 * (1 + nu)), 1e-12);
    const StabilitySummary sc =
        Analyse(SquareLatticePacking(30, 30, kRadius), PlainScene(std::nullopt, nu));
    const StabilitySummary hcp =
        Analyse(HexagonalLatticePacking(30, 30, 30, kRadius), PlainScene(std::nullopt, nu));
    // The Ritz value of lambda_max(S^) gives the block's own limit; the certified one is at
    // most eps = 0.4 % below it.
    const double sc_limit = kNormalStiffness / sc.convergence_eigenvalue.ritz_value;
    const double hcp_limit = kNormalStiffness / hcp.convergence_eigenvalue.ritz_value;
    EXPECT_GE(sc_limit, formula.square * 0.9999);
    EXPECT_LT(sc_limit, formula.square * 1.01);
    EXPECT_GE(hcp_limit, formula.hexagonal * 0.9999);
    EXPECT_LT(hcp_limit, formula.hexagonal * 1.01);
    EXPECT_LE(sc.admissible_kn_over_ep, sc_limit);
    EXPECT_GT(sc.admissible_kn_over_ep, 0.995 * sc_limit);
    std::printf("A9 nu_p %.2f: SC 30x30 %.5f (formula %.5f), HCP 30x30 %.5f (formula %.5f)\n", nu,
                sc_limit, formula.square, hcp_limit, formula.hexagonal);
  }
  // At kn/Ep = pi/(3 (1 + 0.35)) the HCP block has rho(B) = 0.997 at nu_p = 0.35 and 1.396
  // at nu_p = 0.05 (formulas (3.78): 1.000 and 1.400; docs/stability.md, "Validation").
  const double ep = kNormalStiffness / (kPi / (3 * 1.35));
  const Packing<2> block = HexagonalLatticePacking(30, 30, 30, kRadius);
  EXPECT_NEAR(Analyse(block, PlainScene(ep, 0.35)).spectral_radius_ritz, 0.997, 0.003);
  EXPECT_NEAR(Analyse(block, PlainScene(ep, 0.05)).spectral_radius_ritz, 1.396, 0.004);
  // Plane stress maps onto plane strain: nu' = nu / (1 + nu), Ep' = Ep (1 - nu'^2).
  const LatticeLimits stress = ClosedFormLimits(2, 0.3, PlaneModel::kPlaneStress);
  EXPECT_NEAR(stress.square, kPi / (4 * 1.3), 1e-12);  // SC: the same (1 + nu) either way
}

// Tables 3.2 and 3.3 (numerical columns): the finite-specimen limits rho(B) = 1 of the SC
// 9x20 and HCP 110-disc specimens, within 1 %.
TEST(StabilityClosedForms, MadanTables32And33FiniteSpecimens) {
  const double nus[] = {0.05, 0.10, 0.15, 0.20, 0.25, 0.30, 0.35, 0.40, 0.45};
  const double table_32[] = {0.761, 0.722, 0.693, 0.667, 0.636, 0.614, 0.588, 0.569, 0.551};
  const double table_33[] = {0.569, 0.614, 0.673, 0.751, 0.850, 0.823, 0.793, 0.764, 0.738};
  const Specimen sc = SquareSpecimen(), hcp = HexagonalSpecimen();
  for (int k = 0; k < 9; ++k) {
    const StabilitySummary s = Analyse(sc.packing, Scene(sc, std::nullopt, 1e-4, 0.0, nus[k]));
    const StabilitySummary h = Analyse(hcp.packing, Scene(hcp, std::nullopt, 1e-4, 0.0, nus[k]));
    EXPECT_NEAR(s.admissible_kn_over_ep / table_32[k], 1.0, 0.01) << "SC nu_p " << nus[k];
    EXPECT_NEAR(h.admissible_kn_over_ep / table_33[k], 1.0, 0.01) << "HCP nu_p " << nus[k];
    std::printf("Tables 3.2/3.3 nu_p %.2f: SC %.4f (thesis %.3f), HCP %.4f (thesis %.3f)\n", nus[k],
                s.admissible_kn_over_ep, table_32[k], h.admissible_kn_over_ep, table_33[k]);
  }
  // The thesis' stable / unstable Ep, 1.19e11 / 1.18e11 (SC, nu_p 0.35, Fig. 3.5), lie on
  // either side of rho(B) = 1 of the finite specimen: 0.9928 and 1.0012; HCP 0.99987 at
  // 8.83e10 (Fig. 3.11; docs/stability.md, "Validation").
  EXPECT_NEAR(Analyse(sc.packing, Scene(sc, 1.19e11, 1e-4, 0.0)).spectral_radius_ritz, 0.9928,
              2e-4);
  EXPECT_NEAR(Analyse(sc.packing, Scene(sc, 1.18e11, 1e-4, 0.0)).spectral_radius_ritz, 1.0012,
              2e-4);
  EXPECT_NEAR(Analyse(hcp.packing, Scene(hcp, 8.83e10, 1e-4, 0.0)).spectral_radius_ritz, 0.99987,
              2e-4);
}

// Undamped runs of a Madan specimen at a time step, from random velocities: "" when bounded
// over `steps`, else the divergence message.
std::string RunFromRandomVelocities(const Specimen& specimen, std::optional<double> modulus,
                                    double time_step, long steps) {
  SceneOptions<2> scene = Scene(specimen, modulus, 1e-4, 0.0);
  scene.time_step.time_step_s = time_step;
  scene.time_step.allow_above_critical = true;
  Simulation<2> simulation(specimen.packing, scene);
  std::mt19937_64 engine(7);
  std::normal_distribution<double> gaussian;
  for (int p = 0; p < specimen.packing.size(); ++p)
    simulation.SetVelocity(p, Vector<2>(1e-3 * gaussian(engine), 1e-3 * gaussian(engine)));
  RunOptions run;
  run.max_steps = steps;
  try {
    simulation.Run(run);
  } catch (const ComputationError& e) {
    return e.what();
  }
  return "";
}

// A5/A6: the predicted critical steps lie between the thesis' stable and unstable steps
// (Figs. 3.7, 3.13), match independent bisections with undamped explicit runs (SC DEM
// 3.00525e-7 = sqrt(m/kn) / sin(19 pi/40), the free-free 20-disc chain, cf. Madan (3.44);
// DDEM 3.00096e-7, -0.14 %; HCP DEM 2.4745e-7, DDEM 2.4640e-7, -0.42 %; docs/stability.md,
// "Validation") from the safe side, and real runs confirm them.
TEST(StabilityTimeStep, A5A6SquareAndHexagonalSpecimens) {
  struct Case {
    const char* name;
    Specimen specimen;
    double stable, unstable;     // thesis
    double bisected_dem, bisected_ddem;  // independent bisections
  };
  const Case cases[] = {
      {"SC", SquareSpecimen(), 2.9959e-7, 3.0559e-7, 3.00525e-7, 3.00096e-7},
      {"HCP", HexagonalSpecimen(), 2.4567e-7, 2.5166e-7, 2.4745e-7, 2.4640e-7},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const StabilitySummary dem =
        Analyse(c.specimen.packing, Scene(c.specimen, std::nullopt, 1e-4, 0));
    const StabilitySummary ddem = Analyse(c.specimen.packing, Scene(c.specimen, 2e11, 1e-4, 0));
    ASSERT_TRUE(ddem.ddem_time_step_available);
    for (const double dt : {dem.critical_time_step_s, ddem.critical_time_step_s}) {
      EXPECT_GT(dt, c.stable);
      EXPECT_LT(dt, c.unstable);
    }
    EXPECT_NEAR(dem.critical_time_step_s, c.bisected_dem, 0.0005 * c.bisected_dem);
    EXPECT_LE(ddem.critical_time_step_s, c.bisected_ddem);  // the safe side of the bisection
    EXPECT_NEAR(ddem.critical_time_step_s, c.bisected_ddem, 0.001 * c.bisected_ddem);
    // The DDEM reduction (bisected: 0.14 % and 0.42 %).
    EXPECT_GT(ddem.ddem_reduction_percent, 0.1);
    EXPECT_LT(ddem.ddem_reduction_percent, 0.5);
    // Real runs: bounded at the predicted steps, diverging 0.5 % above.
    EXPECT_EQ(RunFromRandomVelocities(c.specimen, std::nullopt, dem.critical_time_step_s, 4000),
              "");
    EXPECT_EQ(RunFromRandomVelocities(c.specimen, 2e11, ddem.critical_time_step_s, 4000), "");
    EXPECT_NE(
        RunFromRandomVelocities(c.specimen, std::nullopt, 1.005 * dem.critical_time_step_s, 4000),
        "");
    EXPECT_NE(RunFromRandomVelocities(c.specimen, 2e11, 1.005 * ddem.critical_time_step_s, 4000),
              "");
    std::printf("%s: dt_cr DEM %.6e (bisected %.5e), DDEM %.6e (bisected %.5e), "
                "reduction %.3f %%\n",
                c.name, dem.critical_time_step_s, c.bisected_dem, ddem.critical_time_step_s,
                c.bisected_ddem, ddem.ddem_reduction_percent);
  }
}

// O6 (docs/sources.md, section 3): the triangular lattice with central springs has
// omega_max^2 = 6 kn / m; a free finite block comes close from the stable side. A run at 0.99
// of the predicted step stays bounded, one at 1.01 diverges.
TEST(StabilityTimeStep, O6TriangularLatticeLimit) {
  const Packing<2> block = HexagonalLatticePacking(20, 20, 20, kRadius);
  const StabilitySummary s = Analyse(block, PlainScene(std::nullopt, 0.0));
  const double infinite = 2.0 * std::sqrt(kMass / (6.0 * kNormalStiffness));
  EXPECT_GE(s.dem_time_step_ritz_s, infinite);
  EXPECT_LT(s.dem_time_step_ritz_s, 1.01 * infinite);
  EXPECT_LE(s.critical_time_step_s, s.dem_time_step_ritz_s);
  auto run = [&](double dt) {
    SceneOptions<2> scene = PlainScene(std::nullopt, 0.0);
    scene.time_step.time_step_s = dt;
    scene.time_step.allow_above_critical = true;
    Simulation<2> simulation(block, scene);
    std::mt19937_64 engine(3);
    std::normal_distribution<double> gaussian;
    for (int p = 0; p < block.size(); ++p)
      simulation.SetVelocity(p, Vector<2>(1e-3 * gaussian(engine), 1e-3 * gaussian(engine)));
    RunOptions options;
    options.max_steps = 3000;
    try {
      simulation.Run(options);
    } catch (const ComputationError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(run(0.99 * s.critical_time_step_s), "");
  const std::string failure = run(1.01 * s.critical_time_step_s);
  EXPECT_NE(failure.find("diverged"), std::string::npos) << failure;
  // The exact infinite-lattice limit 2 sqrt(m / 6 kn) itself: the free block is bounded at
  // 0.99 of it and diverges at 1.01 of it (its own limit lies within 1 % above).
  EXPECT_EQ(run(0.99 * infinite), "");
  EXPECT_NE(run(1.01 * infinite).find("diverged"), std::string::npos);
  std::printf("O6: predicted %.6e s, infinite lattice %.6e s (ratio %.4f); 1.01 x: %s\n",
              s.critical_time_step_s, infinite, s.critical_time_step_s / infinite,
              failure.substr(0, failure.find(':')).c_str());
}

TEST(StabilityTimeStep, StiffParticlesGiveTheDemLimit) {
  const Specimen hcp = HexagonalSpecimen();
  const StabilitySummary dem = Analyse(hcp.packing, Scene(hcp, std::nullopt, 1e-4, 0));
  const StabilitySummary stiff = Analyse(hcp.packing, Scene(hcp, 1e30, 1e-4, 0));
  ASSERT_TRUE(stiff.ddem_time_step_available);
  EXPECT_NEAR(stiff.ddem_time_step_ritz_s, dem.dem_time_step_ritz_s,
              1e-9 * dem.dem_time_step_ritz_s);
  EXPECT_LT(stiff.spectral_radius, 1e-18);
  EXPECT_EQ(stiff.verdict, "stable");
}

// 3D: a simple cubic block of spheres. DEM: the axial chains of N spheres give
// dt_cr = sqrt(m/kn) / sin((N - 1) pi / (2N)) (free-free chain). DDEM: the limit on kn/(Ep R)
// approaches pi / (3 (1 + nu)) (stability_closed_forms.h) from above.
TEST(StabilityTimeStep, SimpleCubicSpheres) {
  const int n = 8;
  const Packing<3> block = CubicLatticePacking(n, n, n, kRadius);
  SceneOptions<3> scene;
  scene.material.normal_stiffness_n_per_m = kNormalStiffness;
  scene.material.density_kg_per_m3 = kDensity;
  scene.material.particle_poisson_ratio = 0.3;
  scene.material.particle_youngs_modulus_pa = kNormalStiffness / (0.4 * kRadius);  // kn/(Ep R) 0.4
  const StabilitySummary s = AnalyseStability<3>(block, scene, StabilityOptions());
  const double mass = kDensity * 4.0 / 3.0 * kPi * std::pow(kRadius, 3);
  const double chain = std::sqrt(mass / kNormalStiffness) / std::sin((n - 1) * kPi / (2.0 * n));
  EXPECT_NEAR(s.dem_time_step_ritz_s, chain, 1e-9 * chain);
  EXPECT_LE(s.dem_critical_time_step_s, chain);
  EXPECT_GT(s.dem_critical_time_step_s, 0.997 * chain);
  const double formula = kPi / (3 * 1.3);
  EXPECT_NEAR(ClosedFormLimits(3, 0.3, PlaneModel::kPlaneStrain).square, formula, 1e-12);
  const double limit = kNormalStiffness / (kRadius * s.convergence_eigenvalue.ritz_value);
  EXPECT_GE(limit, formula);
  EXPECT_LT(limit, 1.05 * formula);
  EXPECT_NEAR(s.group_length_m, kRadius, 1e-15);
  EXPECT_TRUE(s.ddem_time_step_available);
  EXPECT_LT(s.ddem_critical_time_step_s, s.dem_critical_time_step_s);
}

TEST(StabilityVerdict, StableMarginalUnstable) {
  const Specimen sc = SquareSpecimen();
  SceneOptions<2> scene = Scene(sc, 2e11, 1e-4, 0.0);
  StabilityOptions options;
  options.proposed_time_step_s = 2.5e-7;
  StabilitySummary s = AnalyseStability<2>(sc.packing, scene, options);
  EXPECT_EQ(s.verdict, "stable") << s.verdict_message;
  options.proposed_time_step_s = 0.98 * s.critical_time_step_s;
  s = AnalyseStability<2>(sc.packing, scene, options);
  EXPECT_EQ(s.verdict, "marginal") << s.verdict_message;
  EXPECT_NEAR(s.margin_percent, 2.0, 1e-9);
  EXPECT_EQ(s.binding_limit, "critical time step (DDEM)");
  options.proposed_time_step_s = 3.0559e-7;
  s = AnalyseStability<2>(sc.packing, scene, options);
  EXPECT_EQ(s.verdict, "unstable");
  EXPECT_LT(s.margin_percent, 0.0);
  // rho(B) beyond 1 at any step.
  scene = Scene(sc, 1.18e11, 1e-4, 0.0);
  options.proposed_time_step_s = 1e-7;
  s = AnalyseStability<2>(sc.packing, scene, options);
  EXPECT_EQ(s.verdict, "unstable");
  EXPECT_EQ(s.binding_limit, "DDEM convergence rho(B) < 1");
  EXPECT_FALSE(s.ddem_time_step_available);
  // Between the required 0.95 and 1: marginal.
  scene = Scene(sc, 1.22e11, 1e-4, 0.0);
  s = AnalyseStability<2>(sc.packing, scene, options);
  EXPECT_EQ(s.verdict, "marginal") << s.verdict_message;
  EXPECT_GT(s.spectral_radius, 0.95);
}

TEST(StabilityTimeStep, DashpotsAndLocalDampingLowerTheLimit) {
  // One disc between two walls (k each): omega^2 = 2k/m. Lagged dashpot c = 2 xi sqrt(m k)
  // per wall: the boundary z = -1 gives dt = 2 (sqrt(1 + xi'^2) - xi') / omega with xi' the
  // modal ratio c_total / (2 m omega) = sqrt(2) xi (Labra (2.53)); local damping:
  // 1 / sqrt(1 + alpha).
  Packing<2> one(Domain<2>::Rectangle(-1, -1, 1, 1));
  one.centres = {Vector<2>(0, 0)};
  one.radii = {kRadius};
  SceneOptions<2> scene = PlainScene(std::nullopt, 0.0);
  for (const double side : {-1.0, 1.0}) {
    WallOptions<2> w;
    w.name = side < 0 ? "left" : "right";
    w.normal = Vector<2>(-side, 0);
    w.point = Vector<2>(side * kRadius, 0);
    w.normal_stiffness_n_per_m = kNormalStiffness;
    scene.walls.push_back(w);
  }
  FixedDofs<2> y;
  y.name = "y";
  y.particles = {0};
  y.fix_translation = {false, true};
  scene.fixed_dofs = {y};
  scene.material.normal_dashpot_ratio = 0.3;
  scene.material.translational_damping = 0.2;
  const StabilitySummary s = Analyse(one, scene);
  const double omega = std::sqrt(2 * kNormalStiffness / kMass);
  const double xi = 0.3 * std::sqrt(2.0);
  const double expected = 2 / omega * (std::sqrt(1 + xi * xi) - xi) / std::sqrt(1.2);
  EXPECT_NEAR(s.critical_time_step_s, expected, 1e-6 * expected);
}

// Walls act only in compression (impacts): the factor on the linear limit is graded by the
// damping and dimension (the benchmark's wall scans), and an explicit option value replaces it.
TEST(StabilityWalls, DampedUnilateralFactor) {
  EXPECT_EQ(DampedUnilateralFactor(0.0, 2), 0.85);
  EXPECT_EQ(DampedUnilateralFactor(0.0499, 2), 0.85);
  EXPECT_EQ(DampedUnilateralFactor(0.05, 2), 0.94);
  EXPECT_EQ(DampedUnilateralFactor(0.0999, 2), 0.94);
  EXPECT_EQ(DampedUnilateralFactor(0.1, 2), 1.0);
  EXPECT_EQ(DampedUnilateralFactor(0.5, 2), 1.0);
  // 3D failed 1 % and 3 % beyond the 2D factors' steps at alpha 0.05 and 0.1.
  EXPECT_EQ(DampedUnilateralFactor(0.0, 3), 0.85);
  EXPECT_EQ(DampedUnilateralFactor(0.05, 3), 0.92);
  EXPECT_EQ(DampedUnilateralFactor(0.1, 3), 0.96);
  EXPECT_EQ(DampedUnilateralFactor(0.2999, 3), 0.96);
  EXPECT_EQ(DampedUnilateralFactor(0.3, 3), 1.0);
  EXPECT_EQ(DampedUnilateralFactor(0.7, 3), 1.0);  // the virtual laboratory's damping
  // The SC specimen between two walls 10 kn (top and bottom rows touching them).
  const Specimen sc = SquareSpecimen();
  SceneOptions<2> scene = PlainScene(std::nullopt, 0.35);
  double top = 0.0;
  for (const Vector<2>& c : sc.packing.centres) top = std::max(top, c.y());
  for (const double side : {-1.0, 1.0}) {
    WallOptions<2> w;
    w.name = side < 0 ? "bottom" : "top";
    w.normal = Vector<2>(0, -side);
    w.point = Vector<2>(0, side < 0 ? -kRadius : top + kRadius);
    w.normal_stiffness_n_per_m = 10 * kNormalStiffness;
    scene.walls.push_back(w);
  }
  struct Case {
    double alpha, dashpot, option, factor;
  };
  const Case cases[] = {{0.0, 0.0, 0.0, 0.85},  {0.05, 0.0, 0.0, 0.94}, {0.0, 0.07, 0.0, 0.94},
                        {0.1, 0.0, 0.0, 1.0},   {0.0, 0.0, 0.8, 0.8},   {0.05, 0.0, 0.97, 0.97},
                        {0.2, 0.0, 0.8, 1.0}};
  for (const Case& c : cases) {
    SCOPED_TRACE("alpha " + std::to_string(c.alpha) + ", xi " + std::to_string(c.dashpot) +
                 ", option " + std::to_string(c.option));
    scene.material.translational_damping = scene.material.rotational_damping = c.alpha;
    scene.material.normal_dashpot_ratio = scene.material.tangential_dashpot_ratio = c.dashpot;
    StabilityOptions options;
    options.unilateral_contact_factor = c.option;
    const StabilitySummary s = AnalyseStability<2>(sc.packing, scene, options);
    EXPECT_GT(s.wall_links, 0);
    EXPECT_EQ(s.unilateral_factor, c.factor);
    EXPECT_NEAR(s.critical_time_step_s, c.factor * s.linear_critical_time_step_s,
                1e-12 * s.linear_critical_time_step_s);
  }
  StabilityOptions invalid;
  invalid.unilateral_contact_factor = 1.5;
  std::string error;
  EXPECT_FALSE(invalid.IsValid(&error));
  EXPECT_NE(error.find("unilateral_contact_factor"), std::string::npos) << error;
}

// The solver takes its step from the analysis and refuses beyond-limit DDEM parameters.
TEST(StabilityIntegration, SimulationUsesTheAnalysis) {
  const Specimen sc = SquareSpecimen();
  SceneOptions<2> scene = Scene(sc, 2e11, 1e-4, 0.0);
  scene.time_step.from_stability_analysis = true;
  Simulation<2> simulation(sc.packing, scene);
  const StabilitySummary s = Analyse(sc.packing, Scene(sc, 2e11, 1e-4, 0.0));
  EXPECT_NEAR(simulation.critical_time_step().critical_time_step_s, s.critical_time_step_s,
              1e-12 * s.critical_time_step_s);
  EXPECT_NEAR(simulation.time_step_s(), 0.7 * s.critical_time_step_s,
              1e-12 * s.critical_time_step_s);
  EXPECT_NE(simulation.critical_time_step().method.find("stability analysis"), std::string::npos);
  // rho(B) = 1.0012 > 1: refused, naming rho(B) and the admissible kn/(Ep l).
  SceneOptions<2> beyond = Scene(sc, 1.18e11, 1e-4, 0.0);
  beyond.time_step.from_stability_analysis = true;
  try {
    Simulation<2> refused(sc.packing, beyond);
    FAIL() << "rho(B) > 1 was accepted";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("rho(B) = 1.001"), std::string::npos) << message;
    EXPECT_NE(message.find("admissible below 0.59"), std::string::npos) << message;
    EXPECT_NE(message.find("allow_above_critical"), std::string::npos) << message;
  }
  // Forced: it runs, diverges, and the message names what grew and the analysis.
  beyond.time_step.allow_above_critical = true;
  Simulation<2> forced(sc.packing, beyond);
  RunOptions run;
  run.max_steps = 20000;
  try {
    forced.Run(run);
    FAIL() << "rho(B) > 1 did not diverge";
  } catch (const ComputationError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("diverged at step"), std::string::npos) << message;
    EXPECT_NE(message.find("grew"), std::string::npos) << message;
    EXPECT_NE(message.find("Stability analysis of the scene"), std::string::npos) << message;
    EXPECT_NE(message.find("rho(B) 1.001"), std::string::npos) << message;
    // The step the run took, against the analysis' dt_cr (the default 0.7 of it).
    EXPECT_NE(message.find("% of dt_cr"), std::string::npos) << message;
    EXPECT_NE(message.find(" is 70 % of dt_cr"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace specimen
