// The cheap cases of the stiff and extreme benchmark (tools/bench/stability_bench.py
// runs the full grid): generated polydisperse packings (r_max/r_min = 10), stiff and soft
// tangential springs, near-incompressible particles, kn/(Ep l) close to the limit,
// Ep -> infinity, particles of radius 1e-5 m, 2D and 3D. For each, the prediction must be on
// the safe side and within 3 %: a real undamped solver run from random velocities stays
// bounded at the predicted (certified) critical step and diverges at 1.03 times it. Also: the
// DDEM step of normal springs without inner solves (the pencil) equals the inner-solve one,
// and a small 2D packing between walls 10 kn (impacts) runs bounded at the recommended step.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "common/error.h"
#include "generator/generate.h"
#include "solver/simulation.h"
#include "stability/stability_analysis.h"

namespace specimen {
namespace {

constexpr double kNormalStiffness = 7e10;

template <int Dim>
Packing<Dim> Generated(int count, double mean_radius) {
  GeneratorOptions options;
  options.particle_count = count;
  options.radius_ratio = 10.0;
  options.seed = 5;
  GeneratorSummary summary;
  const double side = mean_radius * std::pow(count, 1.0 / Dim) * (Dim == 2 ? 1.9 : 1.75);
  if constexpr (Dim == 2) {
    return GeneratePacking(Domain<2>::Rectangle(0, 0, side, side), options, &summary);
  } else {
    return GeneratePacking(Domain<3>::Box(Vector<3>::Zero(), Vector<3>::Constant(side)), options,
                           &summary);
  }
}

struct Case {
  std::string name;
  double kt_ratio = 0.0;
  double nu_p = 0.35;
  double limit_fraction = 0.0;  // kn/(Ep l) as this share of the packing's limit; 0: rigid
  double youngs_modulus = 0.0;  // > 0: this Ep instead
};

template <int Dim>
SceneOptions<Dim> SceneOf(const Case& c, double youngs_modulus) {
  SceneOptions<Dim> scene;
  scene.material.normal_stiffness_n_per_m = kNormalStiffness;
  scene.material.tangential_stiffness_n_per_m = c.kt_ratio * kNormalStiffness;
  scene.material.density_kg_per_m3 = 2000.0;
  scene.material.particle_poisson_ratio = c.nu_p;
  if (youngs_modulus > 0.0) scene.material.particle_youngs_modulus_pa = youngs_modulus;
  return scene;
}

// "" when a run of `steps` from random velocities (and spins) stays bounded.
template <int Dim>
std::string Run(const Packing<Dim>& packing, SceneOptions<Dim> scene, double time_step,
                long steps) {
  scene.time_step.time_step_s = time_step;
  scene.time_step.allow_above_critical = true;
  scene.time_step.from_stability_analysis = false;  // the step is given
  Simulation<Dim> simulation(packing, scene);
  std::mt19937_64 engine(11);
  std::normal_distribution<double> gaussian;
  for (int p = 0; p < packing.size(); ++p) {
    Vector<Dim> v;
    for (int a = 0; a < Dim; ++a) v[a] = 1e-3 * gaussian(engine);
    simulation.SetVelocity(p, v);
    if (scene.material.tangential_stiffness_n_per_m > 0.0) {
      Angular<Dim> w;
      if constexpr (Dim == 2) {
        w = 1e-3 / packing.radii[p] * gaussian(engine);
      } else {
        for (int a = 0; a < 3; ++a) w[a] = 1e-3 / packing.radii[p] * gaussian(engine);
      }
      simulation.SetAngularVelocity(p, w);
    }
  }
  RunOptions run;
  run.max_steps = steps;
  try {
    simulation.Run(run);
  } catch (const ComputationError& e) {
    return e.what();
  }
  return "";
}

template <int Dim>
void Check(const Packing<Dim>& packing, const Case& c, long steps = 4000) {
  SCOPED_TRACE(c.name);
  double modulus = c.youngs_modulus;
  if (c.limit_fraction > 0.0) {
    const StabilitySummary rigid =
        AnalyseStability<Dim>(packing, SceneOf<Dim>(c, 0.0), StabilityOptions());
    modulus = rigid.convergence_eigenvalue.ritz_value / c.limit_fraction;  // rho(B) = fraction
  }
  const SceneOptions<Dim> scene = SceneOf<Dim>(c, modulus);
  const StabilitySummary s = AnalyseStability<Dim>(packing, scene, StabilityOptions());
  const double predicted = s.critical_time_step_s;
  const std::string at = Run<Dim>(packing, scene, predicted, steps);
  const std::string above = Run<Dim>(packing, scene, 1.03 * predicted, steps);
  EXPECT_EQ(at, "") << "unsafe: the predicted step " << predicted << " s diverged";
  EXPECT_NE(above, "") << "more than 3 % below the limit: 1.03 x " << predicted
                       << " s stayed bounded";
  std::printf("%dD %-34s %4d particles: dt_cr %.5e s (Ritz %.5e)%s; rho(B) %.3f\n", Dim,
              c.name.c_str(), packing.size(), predicted,
              s.ddem_time_step_available ? s.ddem_time_step_ritz_s : s.dem_time_step_ritz_s,
              s.ddem_time_step_available
                  ? (", DDEM -" + std::to_string(s.ddem_reduction_percent).substr(0, 5) + " %")
                        .c_str()
                  : "",
              s.spectral_radius);
}

TEST(StabilityExtremeCases, GeneratedDiscsRadiusRatioTen) {
  const Packing<2> packing = Generated<2>(150, 1e-4);
  Check(packing, {"DEM kt = 0"});
  Check(packing, {"DEM kt/kn = 1.25", 1.25});
  Check(packing, {"DDEM nu_p 0 at 0.5 of the limit", 0.0, 0.0, 0.5});
  Check(packing, {"DDEM nu_p 0.499 at 0.5 of the limit", 0.0, 0.499, 0.5});
  Check(packing, {"DDEM nu_p 0.25 at 0.9 of the limit", 0.0, 0.25, 0.9});
  Check(packing, {"DDEM Ep = 1e30 (-> DEM)", 0.0, 0.35, 0.0, 1e30});
}

TEST(StabilityExtremeCases, EpToInfinityEqualsDem) {
  const Packing<2> packing = Generated<2>(150, 1e-4);
  Case rigid{"DEM"}, stiff{"Ep 1e30", 0.0, 0.35, 0.0, 1e30};
  const StabilitySummary dem =
      AnalyseStability<2>(packing, SceneOf<2>(rigid, 0.0), StabilityOptions());
  const StabilitySummary ddem =
      AnalyseStability<2>(packing, SceneOf<2>(stiff, 1e30), StabilityOptions());
  ASSERT_TRUE(ddem.ddem_time_step_available);
  EXPECT_NEAR(ddem.ddem_time_step_ritz_s, dem.dem_time_step_ritz_s,
              1e-9 * dem.dem_time_step_ritz_s);
  EXPECT_LT(ddem.spectral_radius, 1e-15);
}

TEST(StabilityExtremeCases, TinyParticles) {
  // Radius 1e-5 m: masses of 1e-7 kg against kn = 7e10 N/m, steps of 1e-9 s.
  const Packing<2> packing = Generated<2>(150, 1e-5);
  Check(packing, {"R ~ 1e-5 m, DEM kt/kn = 1", 1.0});
  Check(packing, {"R ~ 1e-5 m, DDEM nu_p 0.45", 0.0, 0.45, 0.5});
}

TEST(StabilityExtremeCases, GeneratedSpheres) {
  const Packing<3> packing = Generated<3>(120, 1e-4);
  Check(packing, {"DEM kt/kn = 1", 1.0});
  Check(packing, {"DDEM nu_p 0.49 at 0.5 of the limit", 0.0, 0.49, 0.5});
}

// The DDEM step of case `c` (kn/(Ep l) at c.limit_fraction of the packing's limit) three
// ways: the pencil with exact Lanczos, the inner solves with exact Lanczos, and the pencil
// certified (exact_dimension 0).
struct PencilRuns {
  StabilitySummary pencil, inner, certified;
};

template <int Dim>
PencilRuns RunPencilAndInnerSolves(const Packing<Dim>& packing, const Case& c,
                                   double inner_tolerance,
                                   const std::vector<WallOptions<Dim>>& walls = {}) {
  SceneOptions<Dim> rigid_scene = SceneOf<Dim>(c, 0.0);
  rigid_scene.walls = walls;
  const StabilitySummary rigid = AnalyseStability<Dim>(packing, rigid_scene, StabilityOptions());
  SceneOptions<Dim> scene = SceneOf<Dim>(c, rigid.convergence_eigenvalue.ritz_value / c.limit_fraction);
  scene.walls = walls;
  PencilRuns runs;
  StabilityOptions options;
  options.lanczos.exact_dimension = 2000;
  runs.pencil = AnalyseStability<Dim>(packing, scene, options);
  options.ddem_inner_solves = true;
  options.inner_tolerance = inner_tolerance;
  runs.inner = AnalyseStability<Dim>(packing, scene, options);
  StabilityOptions certified;
  certified.lanczos.exact_dimension = 0;
  runs.certified = AnalyseStability<Dim>(packing, scene, certified);
  EXPECT_TRUE(runs.pencil.ddem_time_step_available);
  EXPECT_FALSE(runs.pencil.ddem_time_step_inner_solves);
  EXPECT_TRUE(runs.inner.ddem_time_step_inner_solves);
  EXPECT_TRUE(runs.pencil.ddem_eigenvalue.exact);
  EXPECT_FALSE(runs.certified.ddem_time_step_inner_solves);
  return runs;
}

// kt = 0, no dashpots: the pencil (no inner solves) and the inner-solve operator give the
// same DDEM step. Exact Lanczos (small systems): the Ritz values agree to 1e-6 (the inner
// solves to 1e-12); certified (exact_dimension 0, a few hundred unknowns): both on the safe
// side of the exact value and within the tolerance.
template <int Dim>
void CheckPencil(const Packing<Dim>& packing, double limit_fraction, double nu_p) {
  SCOPED_TRACE(std::to_string(Dim) + "D, " + std::to_string(limit_fraction) + " of the limit");
  const PencilRuns runs = RunPencilAndInnerSolves<Dim>(
      packing, Case{"pencil", 0.0, nu_p, limit_fraction}, 1e-12);
  const double exact = runs.inner.ddem_time_step_ritz_s;
  EXPECT_NEAR(runs.pencil.ddem_time_step_ritz_s, exact, 1e-6 * exact);
  EXPECT_NEAR(runs.pencil.ddem_critical_time_step_s, runs.inner.ddem_critical_time_step_s,
              1e-6 * exact);
  EXPECT_GT(runs.pencil.ddem_reduction_percent, 1.0);
  const StabilitySummary& bound = runs.certified;
  EXPECT_LE(bound.ddem_critical_time_step_s, exact);
  EXPECT_GE(bound.ddem_critical_time_step_s,
            exact / std::sqrt(1.0 + 2.0 * StabilityOptions().ddem_relative_tolerance));
  EXPECT_NEAR(bound.ddem_time_step_ritz_s, exact, 1e-3 * exact);
  std::printf("%dD pencil: dt %.8e s, inner solves %.8e s; certified %.6e s (%d steps)\n", Dim,
              runs.pencil.ddem_time_step_ritz_s, exact, bound.ddem_critical_time_step_s,
              bound.ddem_eigenvalue.iterations);
}

TEST(StabilityExtremeCases, PencilEqualsInnerSolves) {
  CheckPencil(Generated<2>(150, 1e-4), 0.5, 0.25);
  CheckPencil(Generated<2>(150, 1e-4), 0.95, 0.45);
  CheckPencil(Generated<3>(120, 1e-4), 0.9, 0.25);
}

// kt > 0, no dashpots: the pencil bounds the symmetric part H_s of the boundary operator by
// H_u = H_s + A_t^T G^T P G A_t / 4 (solver/stability_limits.cpp), without inner solves. Exact
// Lanczos on both: the pencil's step is never above the inner-solve one (the safe side) and
// within 0.5 % of it; certified: on the safe side of it and within the tolerance.
template <int Dim>
void CheckTangentialPencil(const Packing<Dim>& packing, double kt_ratio, double limit_fraction,
                           const std::vector<WallOptions<Dim>>& walls = {}) {
  SCOPED_TRACE(std::to_string(Dim) + "D, kt/kn " + std::to_string(kt_ratio) + ", " +
               std::to_string(limit_fraction) + " of the limit, " + std::to_string(walls.size()) +
               " walls");
  const PencilRuns runs = RunPencilAndInnerSolves<Dim>(
      packing, Case{"tangential pencil", kt_ratio, 0.35, limit_fraction}, 1e-10, walls);
  if (!walls.empty()) {
    EXPECT_GT(runs.pencil.wall_links, 0);
  }
  const double exact = runs.inner.ddem_time_step_ritz_s;
  EXPECT_LE(runs.pencil.ddem_time_step_ritz_s, exact * (1.0 + 1e-9));
  EXPECT_GE(runs.pencil.ddem_time_step_ritz_s, exact * (1.0 - 0.005));
  const StabilitySummary& bound = runs.certified;
  EXPECT_LE(bound.ddem_critical_time_step_s, exact);
  EXPECT_GE(bound.ddem_critical_time_step_s,
            exact * (1.0 - 0.005) /
                std::sqrt(1.0 + 2.0 * StabilityOptions().ddem_relative_tolerance));
  std::printf("%dD tangential pencil: dt %.8e s, inner solves %.8e s (%.3f %% below); certified "
              "%.6e s (%d steps)\n",
              Dim, runs.pencil.ddem_time_step_ritz_s, exact,
              100.0 * (1.0 - runs.pencil.ddem_time_step_ritz_s / exact),
              bound.ddem_critical_time_step_s, bound.ddem_eigenvalue.iterations);
}

TEST(StabilityExtremeCases, TangentialPencilBoundsTheInnerSolves) {
  CheckTangentialPencil(Generated<2>(80, 1e-4), 1.0, 0.5);
  CheckTangentialPencil(Generated<3>(60, 1e-4), 1.25, 0.7);
  // Walls 10 kn with friction: a fixed bottom (ground) and a force-driven top (a degree of
  // freedom of its own), touching the particles within the bond tolerance. The top wall is
  // light (a tenth of a mean particle), so that its motion is in the top mode.
  const Packing<2> packing = Generated<2>(80, 1e-4);
  double bottom = packing.centres[0].y() - packing.radii[0], top = packing.centres[0].y() + packing.radii[0];
  double mass = 0.0;
  for (int p = 0; p < packing.size(); ++p) {
    bottom = std::min(bottom, packing.centres[p].y() - packing.radii[p]);
    top = std::max(top, packing.centres[p].y() + packing.radii[p]);
    mass += 2000.0 * 3.14159265358979 * packing.radii[p] * packing.radii[p];
  }
  std::vector<WallOptions<2>> walls(2);
  for (int k = 0; k < 2; ++k) {
    walls[k].name = k == 0 ? "bottom" : "top";
    walls[k].normal = Vector<2>(0.0, k == 0 ? 1.0 : -1.0);
    walls[k].point = Vector<2>(0.0, k == 0 ? bottom : top);
    walls[k].normal_stiffness_n_per_m = 10 * kNormalStiffness;
    walls[k].friction_coefficient = 0.5;
    walls[k].tangential_stiffness_n_per_m = 5 * kNormalStiffness;
  }
  walls[1].drive = WallDrive::kForce;
  walls[1].mass_kg = 0.1 * mass / packing.size();
  CheckTangentialPencil(packing, 1.0, 0.5, walls);
}

// Walls 10 kn on every side of a small 2D packing, undamped: the wall contacts open and close
// (impacts), and the analysis holds the scene to 0.85 x the linear limit
// (DampedUnilateralFactor). The walls are pressed in smoothly by 1e-3 mean radii, then the
// particles get random velocities: at the recommended step the run stays bounded (kinetic
// energy within 1e4 x its level after the press-in, no wall contact chattering).
TEST(StabilityExtremeCases, WallsAtTheRecommendedStep) {
  const Packing<2> packing = Generated<2>(150, 1e-4);
  Vector<2> lower = packing.centres[0], upper = packing.centres[0];
  for (int p = 0; p < packing.size(); ++p)
    for (int a = 0; a < 2; ++a) {
      lower[a] = std::min(lower[a], packing.centres[p][a] - packing.radii[p]);
      upper[a] = std::max(upper[a], packing.centres[p][a] + packing.radii[p]);
    }
  const double preload = 1e-3 * VolumeMeanRadius<2>(packing.radii);
  // walls: at the packing's box, moving in by `preload`; pressed: at their final position
  // (the analysis' scene: the contacts of the loaded runs).
  SceneOptions<2> walls = SceneOf<2>(Case{"walls"}, 0.0), pressed = walls;
  for (int k = 0; k < 4; ++k) {
    const int axis = k / 2;
    const bool high = k % 2 == 1;
    WallOptions<2> w;
    w.name = "wall " + std::to_string(k);
    w.normal = Vector<2>::Zero();
    w.normal[axis] = high ? -1.0 : 1.0;
    w.point = Vector<2>::Zero();
    w.point[axis] = high ? upper[axis] : lower[axis];
    w.normal_stiffness_n_per_m = 10 * kNormalStiffness;
    w.velocity = preload * w.normal;  // times the pulse amplitude [1/s]
    walls.walls.push_back(w);
    w.point += preload * w.normal;
    w.velocity = Vector<2>::Zero();
    pressed.walls.push_back(w);
  }
  pressed.contacts.bond_gap_tolerance = 0.0;
  const StabilitySummary s = AnalyseStability<2>(packing, pressed, StabilityOptions());
  EXPECT_GT(s.wall_links, 0);
  EXPECT_EQ(s.unilateral_factor, 0.85);
  const double dt = s.recommended_time_step_s;
  for (const long ramp : {2000L, 4000L}) {
    SCOPED_TRACE("press-in over " + std::to_string(ramp) + " steps");
    SceneOptions<2> scene = walls;
    scene.time_step.time_step_s = dt;
    scene.time_step.allow_above_critical = true;
    scene.time_step.from_stability_analysis = false;
    const double ramp_s = ramp * dt;
    for (WallOptions<2>& w : scene.walls)
      w.velocity_amplitude.points = {{0.0, 0.0}, {0.5 * ramp_s, 2.0 / ramp_s}, {ramp_s, 0.0}};
    Simulation<2> simulation(packing, scene);
    RunOptions run;
    run.max_steps = ramp;
    ASSERT_NO_THROW(simulation.Run(run));
    // Wall contacts loaded after the press-in: they must stay closed.
    std::vector<std::pair<int, int>> loaded;
    for (int w = 0; w < simulation.wall_count(); ++w)
      for (size_t k = 0; k < simulation.wall(w).particle.size(); ++k)
        if (simulation.wall(w).normal_elastic_force[k] < -1e-3 * kNormalStiffness * preload)
          loaded.push_back({w, simulation.wall(w).particle[k]});
    EXPECT_GT(loaded.size(), 4u);
    std::mt19937_64 engine(11);
    std::normal_distribution<double> gaussian;
    for (int p = 0; p < packing.size(); ++p) {
      Vector<2> v = simulation.particles().velocity[p];
      v += Vector<2>(1e-4 * gaussian(engine), 1e-4 * gaussian(engine));
      simulation.SetVelocity(p, v);
    }
    int openings = 0;
    run.max_steps = 3000;
    run.observe_interval = 1;
    run.observer = [&] {
      for (const auto& [w, particle] : loaded) {
        const WallState<2>& wall = simulation.wall(w);
        const auto at = std::lower_bound(wall.particle.begin(), wall.particle.end(), particle);
        if (at == wall.particle.end() || *at != particle ||
            wall.normal_elastic_force[at - wall.particle.begin()] >= 0.0)
          ++openings;
      }
    };
    run.max_steps = 100;
    ASSERT_NO_THROW(simulation.Run(run));
    const double reference = simulation.Energy().kinetic_j;
    run.max_steps = 3000;
    EXPECT_NO_THROW(simulation.Run(run));
    EXPECT_LT(simulation.Energy().kinetic_j, 1e4 * reference);
    EXPECT_EQ(openings, 0);
  }
  std::printf("walls 10 kn, undamped: linear limit %.5e s, x %.2f, recommended %.5e s\n",
              s.linear_critical_time_step_s, s.unilateral_factor, dt);
}

}  // namespace
}  // namespace specimen
