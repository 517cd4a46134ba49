#include "calibrate/inversion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

namespace specimen {
namespace {

// Maps sampled from known smooth functions on a grid, fitted like real sweep results.
ResponseSurface Sample(const std::vector<std::vector<double>>& axes,
                       const std::function<double(const std::vector<double>&)>& f) {
  std::vector<std::vector<double>> points(1);
  for (const auto& axis : axes) {
    std::vector<std::vector<double>> next;
    for (const auto& p : points)
      for (double v : axis) {
        auto q = p;
        q.push_back(v);
        next.push_back(q);
      }
    points = next;
  }
  Eigen::MatrixXd x(points.size(), axes.size());
  Eigen::VectorXd y(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    for (size_t k = 0; k < axes.size(); ++k) x(i, k) = points[i][k];
    y[i] = f(points[i]);
  }
  return ResponseSurface::Fit(x, y);
}

std::vector<double> Linspace(double a, double b, int n) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(a + (b - a) * i / (n - 1));
  return v;
}

PackingDescriptors Packing2D() {
  PackingDescriptors d;
  d.dimension = 2;
  d.porosity = 0.092;
  d.coordination = 5.98;
  d.mean_radius_squared = 0.04e-6;
  d.mean_branch_length = 0.4e-3;
  d.mean_branch_length_squared = 0.17e-6;
  return d;
}

TargetMaterial Labra() {
  TargetMaterial t;
  t.youngs_modulus_pa = 18.691e9;
  t.poisson_ratio = 0.20;
  t.ucs_pa = 127.83e6;
  t.tensile_strength_pa = 12.30e6;
  t.density_kg_per_m3 = 2580;
  return t;
}

// Rigid-particle maps over (kt/kn, Rt/Rn): nu = (1 - a)/4, ratio = Psi_c / Psi_t grows with b.
MapSet RigidMaps() {
  MapSet maps;
  maps.inputs = {MicroRatio::kStiffnessRatio, MicroRatio::kStrengthRatio};
  const auto axes = std::vector<std::vector<double>>{Linspace(0, 1, 6), Linspace(1, 10, 6)};
  maps.poisson_ratio = Sample(axes, [](const auto& p) { return (1 - p[0]) / 4; });
  maps.elastic_group = Sample(axes, [](const auto& p) { return 0.3 * (1 + p[0]) * (5 - p[0]) / 16; });
  maps.compressive_group = Sample(axes, [](const auto& p) { return 0.2 + 0.5 * p[0] + 0.05 * p[1]; });
  maps.tensile_group = Sample(axes, [](const auto& p) { return 0.05 + 0.01 * p[0] + 0.001 * p[1]; });
  return maps;
}

TEST(InvertMaps, RecoversAReachableTargetExactly) {
  const MapSet maps = RigidMaps();
  const auto target = Labra();
  const auto r = InvertMaps(maps, Packing2D(), target, InversionOptions());
  EXPECT_NEAR(r.ratios.tangential_to_normal_stiffness, 0.2, 1e-4);
  EXPECT_TRUE(r.strength_ratio_reached) << r.FullReport();
  EXPECT_TRUE(r.poisson_reached) << r.FullReport();
  EXPECT_NEAR(r.error_poisson, 0.0, 1e-3);
  EXPECT_NEAR(r.error_ucs, 0.0, 1e-9);
  EXPECT_NEAR(r.error_tensile, 0.0, 2e-3);
  // kn from the elastic group: E r~ / (Psi_E nc (1 - e)).
  const auto d = Packing2D();
  const double psi_e = 0.3 * 1.2 * 4.8 / 16;
  EXPECT_NEAR(r.normal_stiffness, NormalStiffnessFromElasticGroup(d, target.youngs_modulus_pa, psi_e),
              1e-3 * r.normal_stiffness);
  EXPECT_NEAR(r.tangential_stiffness / r.normal_stiffness, r.ratios.tangential_to_normal_stiffness, 1e-12);
  EXPECT_NEAR(r.bond_shear_strength / r.bond_tensile_strength, r.ratios.shear_to_tensile_strength, 1e-12);
  EXPECT_TRUE(r.notes.empty());
}

TEST(InvertMaps, UnreachableStrengthRatioIsReportedWithTheHonouredStrength) {
  const MapSet maps = RigidMaps();
  auto target = Labra();
  target.tensile_strength_pa = target.ucs_pa / 40.0;  // ratio 40: far beyond the maps
  const auto r = InvertMaps(maps, Packing2D(), target, InversionOptions());
  EXPECT_FALSE(r.strength_ratio_reached);
  EXPECT_NEAR(r.error_ucs, 0.0, 1e-9);       // Rn from sigma_c by default
  EXPECT_GT(std::abs(r.error_tensile), 0.1);  // sigma_t misses, and says so
  ASSERT_FALSE(r.notes.empty());
  EXPECT_NE(r.notes[0].find("not reachable"), std::string::npos) << r.notes[0];
  EXPECT_NE(r.notes[0].find("compressive"), std::string::npos) << r.notes[0];
  InversionOptions tensile;
  tensile.honour = HonouredStrength::kTensile;
  const auto t = InvertMaps(maps, Packing2D(), target, tensile);
  EXPECT_NEAR(t.error_tensile, 0.0, 1e-9);
}

// DDEM maps: nu rises above the rigid-particle limit with kn/(Ep l) when nu_p > 0.25; the
// stability bound caps kn/(Ep l) at 0.3 (a stand-in for rho(B) <= 0.9).
MapSet DeformableMaps() {
  MapSet maps;
  maps.inputs = {MicroRatio::kStiffnessRatio, MicroRatio::kParticleCompliance, MicroRatio::kParticlePoisson};
  maps.fixed.shear_to_tensile_strength = 10.0;
  const auto axes = std::vector<std::vector<double>>{Linspace(0, 1, 5), Linspace(0, 0.6, 5), Linspace(0, 0.49, 5)};
  maps.poisson_ratio = Sample(axes, [](const auto& p) { return (1 - p[0]) / 4 + 0.5 * p[1] * (p[2] - 0.25); });
  maps.elastic_group = Sample(axes, [](const auto& p) { return 0.3 / (1 + p[1]); });
  maps.compressive_group = Sample(axes, [](const auto& p) { return 0.6 + 0.2 * p[0]; });
  maps.tensile_group = Sample(axes, [](const auto& p) { return 0.06 + 0.0 * p[0]; });
  return maps;
}

TEST(InvertMaps, DeformableParticlesReachAPoissonRatioAboveTheRigidLimitWithinTheBound) {
  const MapSet maps = DeformableMaps();
  auto target = Labra();
  target.poisson_ratio = 0.27;  // above 1/4
  target.tensile_strength_pa = target.ucs_pa / 10.2;  // kt/kn = 0.06 on these maps
  InversionOptions options;
  options.admissible_particle_compliance = [](double) { return 0.3; };
  const auto r = InvertMaps(maps, Packing2D(), target, options);
  EXPECT_TRUE(r.poisson_reached) << r.FullReport();
  EXPECT_LE(r.ratios.normal_stiffness_to_particle, 0.3 + 1e-8);
  EXPECT_GT(r.particle_youngs_modulus, 0.0);
  EXPECT_NEAR(r.particle_youngs_modulus, r.normal_stiffness / r.ratios.normal_stiffness_to_particle, 1e-6);

  target.poisson_ratio = 0.32;  // needs kn/(Ep l) beyond the bound
  const auto beyond = InvertMaps(maps, Packing2D(), target, options);
  EXPECT_FALSE(beyond.poisson_reached);
  EXPECT_LE(beyond.ratios.normal_stiffness_to_particle, 0.3 + 1e-8);
  EXPECT_FALSE(beyond.notes.empty());
}

// Verification corrections of nu (CorrectPoisson) on the DDEM maps above, where
// d nu / d(kt/kn) = -1/4 and d nu / d(kn/(Ep l)) = (nu_p - 1/4) / 2.
MicroRatios Ddem(double kt_over_kn, double compliance) {
  MicroRatios r;
  r.tangential_to_normal_stiffness = kt_over_kn;
  r.shear_to_tensile_strength = 10.0;
  r.normal_stiffness_to_particle = compliance;
  r.particle_poisson_ratio = 0.45;
  return r;
}

TEST(CorrectPoisson, MovesKtOverKnByTheMapsSlope) {
  const MapSet maps = DeformableMaps();
  const auto c = CorrectPoisson(maps, {{Ddem(0.5, 0.1), 0.20}}, 0.22);
  EXPECT_NEAR(c.next.tangential_to_normal_stiffness, 0.5 - 0.02 / 0.25, 1e-6);
  EXPECT_NEAR(c.next.normal_stiffness_to_particle, 0.1, 1e-12);
  EXPECT_NE(c.what.find("kt/kn"), std::string::npos) << c.what;
}

TEST(CorrectPoisson, UsesTheMeasuredSecantWhenOnlyKtOverKnMoved) {
  // Two rounds: nu fell by 0.01 over +0.1 of kt/kn (the real specimen: -0.1 per unit, the
  // maps say -0.25); to raise nu by 0.01 the secant asks for -0.1 of kt/kn.
  const MapSet maps = DeformableMaps();
  const auto c = CorrectPoisson(maps, {{Ddem(0.4, 0.1), 0.21}, {Ddem(0.5, 0.1), 0.20}}, 0.21);
  EXPECT_NEAR(c.next.tangential_to_normal_stiffness, 0.4, 1e-6);
  // A secant of the wrong sign (noise) is not trusted: the maps' slope is used.
  const auto noisy = CorrectPoisson(maps, {{Ddem(0.4, 0.1), 0.19}, {Ddem(0.5, 0.1), 0.20}}, 0.21);
  EXPECT_NEAR(noisy.next.tangential_to_normal_stiffness, 0.5 - 0.01 / 0.25, 1e-6);
}

TEST(CorrectPoisson, DeformableParticlesTakeTheStepKtOverKnCannot) {
  // kt/kn is at the box's lower end (0), nu must still rise: kn/(Ep l) takes the step,
  // 0.02 / ((0.45 - 0.25) / 2) = 0.2, and stays within the box (the stability bound).
  const MapSet maps = DeformableMaps();
  const auto c = CorrectPoisson(maps, {{Ddem(0.0, 0.1), 0.25}}, 0.27);
  EXPECT_NEAR(c.next.tangential_to_normal_stiffness, 0.0, 1e-12);
  EXPECT_NEAR(c.next.normal_stiffness_to_particle, 0.3, 1e-6) << c.what;
  EXPECT_NE(c.what.find("kn/(Ep l)"), std::string::npos) << c.what;
  // A step beyond the box stops at its end.
  const auto far = CorrectPoisson(maps, {{Ddem(0.0, 0.5), 0.25}}, 0.30);
  EXPECT_NEAR(far.next.normal_stiffness_to_particle, 0.6, 1e-9);
  // Rigid maps have no such lever: kt/kn stays at its end.
  const auto rigid = CorrectPoisson(RigidMaps(), {{Ddem(0.0, 0.0), 0.24}}, 0.26);
  EXPECT_NEAR(rigid.next.tangential_to_normal_stiffness, 0.0, 1e-12);
}



// Verification corrections of sigma_c / sigma_t (CorrectStrengthRatio) on the rigid maps,
// where at kt/kn = 0.5, Rt/Rn = 4: d ln(Psi_c / Psi_t) / d(Rt/Rn) = 0.05/0.65 - 0.001/0.059.
MicroRatios Rigid(double kt_over_kn, double rt_over_rn) {
  MicroRatios r;
  r.tangential_to_normal_stiffness = kt_over_kn;
  r.shear_to_tensile_strength = rt_over_rn;
  return r;
}

TEST(CorrectStrengthRatio, MovesRtOverRnByTheMapsLogSlope) {
  const MapSet maps = RigidMaps();
  const double slope = 0.05 / 0.65 - 0.001 / 0.059;
  const auto c = CorrectStrengthRatio(maps, Rigid(0.5, 4.0), {{Rigid(0.5, 4.0), 10.0}}, 10.5);
  EXPECT_NEAR(c.next.shear_to_tensile_strength, 4.0 + std::log(1.05) / slope, 2e-3) << c.what;
  EXPECT_NEAR(c.next.tangential_to_normal_stiffness, 0.5, 1e-12);
  EXPECT_NE(c.what.find("Rt/Rn"), std::string::npos) << c.what;
  // The kt/kn already chosen for this round (the nu correction) is kept.
  const auto both = CorrectStrengthRatio(maps, Rigid(0.4, 4.0), {{Rigid(0.5, 4.0), 10.0}}, 10.5);
  EXPECT_NEAR(both.next.tangential_to_normal_stiffness, 0.4, 1e-12);
  EXPECT_GT(both.next.shear_to_tensile_strength, 4.0);
  // Too low a ratio lowers Rt/Rn; a step beyond the box stops at its end (at most half of it).
  const auto down = CorrectStrengthRatio(maps, Rigid(0.5, 4.0), {{Rigid(0.5, 4.0), 10.0}}, 9.5);
  EXPECT_LT(down.next.shear_to_tensile_strength, 4.0);
  const auto far = CorrectStrengthRatio(maps, Rigid(0.5, 9.0), {{Rigid(0.5, 9.0), 10.0}}, 30.0);
  EXPECT_NEAR(far.next.shear_to_tensile_strength, 10.0, 1e-9);
  EXPECT_GT(far.unremoved_share, 0.5);
  EXPECT_LT(far.unremoved_share, 1.0);
  EXPECT_NEAR(c.unremoved_share, 0.0, 1e-9);
  // At the end of the box, pushing further: nothing moves, the whole error stays.
  const auto stuck = CorrectStrengthRatio(maps, Rigid(0.5, 10.0), {{Rigid(0.5, 10.0), 10.0}}, 30.0);
  EXPECT_NEAR(stuck.next.shear_to_tensile_strength, 10.0, 1e-12);
  EXPECT_NEAR(stuck.unremoved_share, 1.0, 1e-12);
}

TEST(CorrectStrengthRatio, UsesTheSecantAndLeavesMapsWithoutTheLever) {
  // Two rounds with only Rt/Rn moved: ln ratio rose by ln(1.1) over +1 (the maps say 0.06):
  // to gain ln(1.05) more the secant asks for ln(1.05)/ln(1.1) = 0.512.
  const MapSet maps = RigidMaps();
  const auto c = CorrectStrengthRatio(maps, Rigid(0.5, 4.0),
                                      {{Rigid(0.5, 3.0), 10.0}, {Rigid(0.5, 4.0), 11.0}}, 11.55);
  EXPECT_NEAR(c.next.shear_to_tensile_strength, 4.0 + std::log(1.05) / std::log(1.1), 1e-9);
  // DDEM maps of a fixed Rt/Rn have no such lever.
  const auto fixed = CorrectStrengthRatio(DeformableMaps(), Ddem(0.5, 0.1), {{Ddem(0.5, 0.1), 9.0}}, 10.0);
  EXPECT_NEAR(fixed.next.shear_to_tensile_strength, 10.0, 1e-12);
  EXPECT_TRUE(fixed.what.empty());
  EXPECT_NEAR(fixed.unremoved_share, 1.0, 1e-12);
}

}  // namespace
}  // namespace specimen
