// The UCS and Brazilian tests on a six-spring lattice specimen against closed forms: the
// linear portion returns the input E and nu (plane strain, nu 0 to 0.45); with the lattice
// filling the rectangle the UCS stress is homogeneous, so the UCS is the triangles' own
// Mohr-Coulomb strength 2 c cos(phi) / (1 - sin(phi)); the Brazilian disc between jaws with a
// loading arc splits at the input tensile strength, its centre's stress at the peak (Hondros).

#include "lab/lattice_lab_test.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"
#include "generator/generate.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;

const Packing<2>& Square() {
  static const Packing<2> packing = [] {
    GeneratorOptions options = DefaultGeneratorOptions<2>();
    options.particle_count = 800;
    options.seed = 5;
    return GeneratePacking<2>(Domain<2>::Rectangle(0.0, 0.0, 0.02, 0.02), options, nullptr);
  }();
  return packing;
}

const Packing<2>& Disc() {
  static const Packing<2> packing = [] {
    GeneratorOptions options = DefaultGeneratorOptions<2>();
    options.particle_count = 800;
    options.seed = 5;
    return GeneratePacking<2>(Domain<2>::Disc(Vector<2>(0.01, 0.01), 0.01), options, nullptr);
  }();
  return packing;
}

LatticeMaterial Material(double nu) {
  LatticeMaterial m;
  m.elasticity = IsotropicPlaneElasticity(30e9, nu, PlaneModel::kPlaneStrain);
  m.density_kg_per_m3 = 2650.0;
  m.strength = {8e6, 25e6, 30.0};
  return m;
}

TEST(LatticeLab, LinearPortionReturnsTheInputConstants) {
  for (double nu : {0.0, 0.25, 0.45}) {
    LatticeMaterial m = Material(nu);
    m.strength = {1e12, 1e12, 30.0};  // no failure
    LabTestOptions options;
    options.strain_limit = 1e-3;
    const LabTestResult r = RunLatticeLabTest(Square(), m, options);
    ASSERT_TRUE(r.linear_elastic.measured) << "nu " << nu;
    // 1.5 %: the free sides' lateral expansion lags the load a little on this small square
    // (the default 5,000-disc specimen is within 1 %: tools/bench/lattice_bench.md).
    EXPECT_NEAR(r.linear_elastic.youngs_modulus_pa / 30e9, 1.0, 0.015) << "nu " << nu;
    EXPECT_NEAR(r.linear_elastic.poisson_ratio, nu, 0.015 * std::max(nu, 0.1)) << "nu " << nu;
    EXPECT_EQ(r.broken_in_tension + r.broken_in_shear, 0);
  }
}

// The UCS stress is homogeneous up to the inertia of the loading: the peak approaches the
// closed form as the rate falls (measured 0.976, 0.986, 0.996 of it at rate groups 5e-5,
// 2.5e-5, 1e-5).
TEST(LatticeLab, UcsIsTheTrianglesShearStrength) {
  const LatticeMaterial m = Material(0.25);
  const double expected = m.strength.TriangleCompressiveStrength();  // 2 c cos(phi) / (1 - sin(phi))
  LabTestOptions options;
  options.sample_interval_steps = 20;
  const LabTestResult fast = RunLatticeLabTest(Square(), m, options);
  options.loading_rate_group = 1e-5;
  const LabTestResult slow = RunLatticeLabTest(Square(), m, options);
  for (const LabTestResult* r : {&fast, &slow}) {
    ASSERT_TRUE(r->peak_reached) << r->termination_message;
    EXPECT_EQ(r->termination, LabTermination::kPostPeak);
    EXPECT_GT(r->broken_in_shear, r->broken_in_tension);
    EXPECT_LE(r->peak_stress_pa, expected * 1.001);
  }
  EXPECT_NEAR(slow.peak_stress_pa / expected, 1.0, 0.025);
  EXPECT_LT(std::abs(slow.peak_stress_pa / expected - 1.0), 0.5 * std::abs(fast.peak_stress_pa / expected - 1.0));
}

// The disc splits in tension, with a post-peak. Between jaws with the default loading arc
// 2 alpha = 30 degrees the first failure is at the centre and the strength, the centre's
// stress k 2 F / (pi D) (Hondros: k = (sin 2 alpha - alpha) / sin alpha), is the triangles'
// sigma_t (measured 0.985 sigma_t here). A point load (flat platens on the nodes they touch)
// splits the disc below sigma_t (0.62 here): the discrete stress next to the elastic platen
// zones runs ahead of the centre's; without those zones the contact triangles break first.
TEST(LatticeLab, BrazilianSplitsInTensionAtTheTrianglesStrength) {
  const LatticeMaterial m = Material(0.25);
  LabTestOptions options;
  options.kind = LabTestKind::kBrazilian;
  options.sample_interval_steps = 20;
  const LabTestResult r = RunLatticeLabTest(Disc(), m, options);
  ASSERT_TRUE(r.peak_reached) << r.termination_message;
  EXPECT_EQ(r.termination, LabTermination::kPostPeak);
  const double alpha = 15.0 * kPi / 180.0, k = (std::sin(2.0 * alpha) - alpha) / std::sin(alpha);
  EXPECT_NEAR(r.tensile_strength_pa, k * 2.0 * r.peak_force_n / (kPi * 0.02), 1e-9 * r.tensile_strength_pa);
  EXPECT_GT(r.broken_in_tension, 10 * r.broken_in_shear);
  EXPECT_NEAR(r.tensile_strength_pa / m.strength.tensile_strength_pa, 1.0, 0.03);

  LatticeProtocol point;
  point.loading_arc_deg = 0.0;
  const LabTestResult p = RunLatticeLabTest(Disc(), m, options, point);
  EXPECT_NEAR(p.tensile_strength_pa, 2.0 * p.peak_force_n / (kPi * 0.02), 1e-9 * p.tensile_strength_pa);
  EXPECT_GT(p.tensile_strength_pa, 0.5 * m.strength.tensile_strength_pa);
  EXPECT_LT(p.tensile_strength_pa, 0.8 * m.strength.tensile_strength_pa);
  LatticeProtocol bare = point;
  bare.platen_zone_share = 0.0;
  EXPECT_LT(RunLatticeLabTest(Disc(), m, options, bare).tensile_strength_pa, 0.7 * p.tensile_strength_pa);
}

// A low-friction material whose triangles' sigma_t exceeds c (phi 5 degrees, sigma_t / c 2.5)
// fails in shear. Under a point load the largest shear along the loaded diameter lies next to
// the contacts, far above the centre's (1 / (4 sin alpha (1 - sin alpha)) times it for Hondros's
// pressure), so the strength ratio UCS / sigma_B stays near 9-10; the loading arc moves the
// failure to the centre region (measured: sigma_B 1.55 times the point load's, ratio 5.8
// against 9.0).
TEST(LatticeLab, TheLoadingArcLowersTheFloorOfTheStrengthRatio) {
  LatticeMaterial m = Material(0.25);
  m.strength = {10e6, 4e6, 5.0};
  LabTestOptions options;
  options.kind = LabTestKind::kBrazilian;
  options.sample_interval_steps = 20;
  const LabTestResult arc = RunLatticeLabTest(Disc(), m, options);
  LatticeProtocol point;
  point.loading_arc_deg = 0.0;
  const LabTestResult flat = RunLatticeLabTest(Disc(), m, options, point);
  ASSERT_TRUE(arc.peak_reached && flat.peak_reached);
  EXPECT_GT(arc.broken_in_shear, 10 * arc.broken_in_tension);
  EXPECT_GT(arc.tensile_strength_pa, 1.4 * flat.tensile_strength_pa);
  const double ucs = m.strength.TriangleCompressiveStrength();
  EXPECT_LT(ucs / arc.tensile_strength_pa, 7.0);
  EXPECT_GT(ucs / flat.tensile_strength_pa, 8.0);
}

// A brittle rock (sigma_t / d22 4.2e-5, c / sigma_t 17). At the bonded tests' rate group 5e-5
// the platens' wave stress d22 g exceeds sigma_t and the wave breaks triangles by itself: the
// Brazilian strength comes out a third above its quasi-static value (on the default 5,064-disc
// square the UCS fell to 29 % of the closed form; on this small one by 2.7 %). With the
// protocol's cap on the rate the UCS is the triangles' Mohr-Coulomb strength within 1 %, at
// least twice as close as uncapped (measured: 0.7 % against 2.7 %), and the Brazilian strength
// changes by less than 1 % at half the rate.
TEST(LatticeLab, TheRateIsCappedSoThatTheStrengthsAreQuasiStatic) {
  LatticeMaterial m = Material(0.25);
  m.strength = {1.5e6, 25e6, 30.0};
  const double closed_form = m.strength.TriangleCompressiveStrength();
  LabTestOptions options;
  LatticeProtocol uncapped;
  uncapped.compression_wave_share = uncapped.brazilian_wave_share = 0.0;

  const LabTestResult ucs = RunLatticeLabTest(Square(), m, options);
  ASSERT_TRUE(ucs.peak_reached) << ucs.termination_message;
  EXPECT_NEAR(ucs.loading_rate_group, 0.25 * 1.5e6 / m.elasticity.d22, 1e-12);
  const LabTestResult ucs_fast = RunLatticeLabTest(Square(), m, options, uncapped);
  EXPECT_DOUBLE_EQ(ucs_fast.loading_rate_group, 5e-5);
  const double error = std::abs(ucs.peak_stress_pa / closed_form - 1.0);
  EXPECT_LT(error, 0.01);
  EXPECT_LT(error, 0.5 * std::abs(ucs_fast.peak_stress_pa / closed_form - 1.0));

  options.kind = LabTestKind::kBrazilian;
  options.check_quasi_static = true;
  const LabTestResult bts = RunLatticeLabTest(Disc(), m, options);
  ASSERT_TRUE(bts.peak_reached) << bts.termination_message;
  ASSERT_TRUE(bts.quasi_static.performed);
  EXPECT_DOUBLE_EQ(bts.quasi_static.half_rate_group, 0.5 * bts.loading_rate_group);
  EXPECT_TRUE(bts.quasi_static.passed) << "peak change " << bts.quasi_static.peak_change;
  options.check_quasi_static = false;
  const LabTestResult bts_fast = RunLatticeLabTest(Disc(), m, options, uncapped);
  EXPECT_GT(bts_fast.tensile_strength_pa, 1.2 * bts.tensile_strength_pa);

  // The step budget counts the half-rate repeat: a budget 1.5 times the test's own is refused
  // before the first step (the repeat needs twice as many), not after the first run.
  double needed = 0.0;
  options.max_steps = 1;
  try {
    RunLatticeLabTest(Disc(), m, options);
  } catch (const InputError& e) {
    const std::string text = e.what();
    needed = std::stod(text.substr(text.find("about ") + 6));
  }
  ASSERT_GT(needed, 100.0);
  options.max_steps = static_cast<long>(1.5 * needed);
  options.check_quasi_static = true;
  try {
    RunLatticeLabTest(Disc(), m, options);
    ADD_FAILURE() << "a budget below the test and its repeat was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("half-rate repeat"), std::string::npos) << e.what();
  }
}

// The confined (biaxial) test: sigma_3 on the sides, then the platens. The linear portion
// returns the input E and nu; the peak sigma_1 approaches the triangles' Mohr-Coulomb envelope
// sigma_1 = sigma_3 (1 + sin phi) / (1 - sin phi) + 2 c cos phi / (1 - sin phi), the stress
// being homogeneous up to the inertia of the loading.
TEST(LatticeLab, BiaxialFollowsTheTrianglesEnvelope) {
  LatticeMaterial m = Material(0.25);
  LabTestOptions options;
  options.kind = LabTestKind::kConfinedCompression;
  options.confining_stress_pa = 10e6;
  options.sample_interval_steps = 20;
  options.loading_rate_group = 1e-5;
  const LabTestResult r = RunLatticeLabTest(Square(), m, options);
  ASSERT_TRUE(r.peak_reached) << r.termination_message;
  const double phi = m.strength.friction_angle_deg * kPi / 180.0;
  const double envelope =
      (options.confining_stress_pa * (1.0 + std::sin(phi)) + 2.0 * m.strength.cohesion_pa * std::cos(phi)) /
      (1.0 - std::sin(phi));
  EXPECT_NEAR(r.peak_stress_pa / envelope, 1.0, 0.03);
  EXPECT_LE(r.peak_stress_pa, envelope * 1.001);
  EXPECT_DOUBLE_EQ(r.confining_stress_pa, 10e6);
  ASSERT_TRUE(r.linear_elastic.measured);
  EXPECT_NEAR(r.linear_elastic.youngs_modulus_pa / 30e9, 1.0, 0.015);
  EXPECT_NEAR(r.linear_elastic.poisson_ratio, 0.25, 0.015 * 0.25);
}

TEST(LatticeLab, BadInputIsRefused) {
  LabTestOptions options;
  options.kind = LabTestKind::kPureShear;
  EXPECT_THROW(RunLatticeLabTest(Square(), Material(0.2), options), InputError);
  options.kind = LabTestKind::kConfinedCompression;
  EXPECT_THROW(RunLatticeLabTest(Disc(), Material(0.2), options), InputError);  // not a rectangle
  options.kind = LabTestKind::kBrazilian;
  EXPECT_THROW(RunLatticeLabTest(Square(), Material(0.2), options), InputError);  // not a disc
  LatticeMaterial bad = Material(0.2);
  bad.strength.cohesion_pa = -1.0;
  std::string error;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_NE(error.find("cohesion"), std::string::npos);
  EXPECT_THROW(RunLatticeLabTest(Square(), bad, LabTestOptions{}), InputError);
  bad = Material(0.2);
  bad.density_kg_per_m3 = 0.0;
  EXPECT_THROW(RunLatticeLabTest(Square(), bad, LabTestOptions{}), InputError);
  LatticeProtocol protocol;
  protocol.platen_zone_share = 0.5;
  EXPECT_FALSE(protocol.IsValid(&error));
  EXPECT_NE(error.find("platen_zone"), std::string::npos);
  protocol = LatticeProtocol{};
  protocol.loading_arc_deg = 75.0;
  EXPECT_FALSE(protocol.IsValid(&error));
  EXPECT_NE(error.find("loading_arc"), std::string::npos);
  protocol = LatticeProtocol{};
  protocol.brazilian_wave_share = -0.1;
  EXPECT_FALSE(protocol.IsValid(&error));
  EXPECT_NE(error.find("brazilian_wave_share"), std::string::npos);
}

}  // namespace
}  // namespace specimen
