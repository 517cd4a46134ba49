// The cheap cases of the stiff and extreme benchmark (issue 5; tools/bench/stability_bench.py
// runs the full grid): generated polydisperse packings (r_max/r_min = 10), stiff and soft
// tangential springs, near-incompressible particles, kn/(Ep l) close to the limit,
// Ep -> infinity, particles of radius 1e-5 m, 2D and 3D. For each, the prediction must be on
// the safe side and within 3 %: a real undamped solver run from random velocities stays
// bounded at the predicted (certified) critical step and diverges at 1.03 times it.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "common/error.h"
#include "generator/generate.h"
#include "solver/simulation.h"
#include "solver/stability_analysis.h"

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

}  // namespace
}  // namespace specimen
