// Bad input to the virtual laboratory: a specimen shape the packing does not fill,
// a test on the wrong shape, a negative confinement, a modulus window outside (0, 1), and a
// strength test that never reaches a peak within its strain limit - reported in the result,
// not hung and not thrown. Every invalid input is refused before any simulation work.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <string>

#include "common/error.h"
#include "generator/generate.h"
#include "lab/lab_envelope.h"
#include "lab/lab_measurement.h"
#include "lab/lab_scene_file.h"
#include "lab/lab_specimen.h"
#include "lab/lab_test.h"

namespace specimen {
namespace {

MaterialParameters Material() {
  MaterialParameters m;
  m.normal_stiffness_n_per_m = 1e10;
  m.tangential_stiffness_n_per_m = 2.5e9;
  m.density_kg_per_m3 = 2000.0;
  return m;
}

class LabBadInput : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    GeneratorOptions options = DefaultGeneratorOptions<2>();
    options.particle_count = 300;
    options.seed = 2;
    packing_ = new Packing<2>(
        GeneratePacking<2>(Domain<2>::Rectangle(0, 0, 0.01, 0.01), options, nullptr));
  }
  static void TearDownTestSuite() {
    delete packing_;
    packing_ = nullptr;
  }

  // Runs the test expecting an InputError whose message holds every one of `words`, and
  // that it was refused at once (no simulation: well under a second).
  static void ExpectRefused(const Packing<2>& packing, const LabTestOptions& options,
                            const std::vector<std::string>& words) {
    const auto start = std::chrono::steady_clock::now();
    try {
      RunLabTest<2>(packing, Material(), options);
      ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
      const std::string message = e.what();
      for (const std::string& w : words)
        EXPECT_NE(message.find(w), std::string::npos) << "'" << w << "' not in: " << message;
    }
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
              1.0);
  }

  static Packing<2>* packing_;
};
Packing<2>* LabBadInput::packing_ = nullptr;

TEST_F(LabBadInput, ShapeThePackingDoesNotFill) {
  // The particles fill 10 x 10 mm; the domain claims 20 x 10 mm.
  Packing<2> wider = *packing_;
  wider.domain = Domain<2>::Rectangle(0, 0, 0.02, 0.01);
  ExpectRefused(wider, LabTestOptions(), {"do not fill", "x max"});
  // A Brazilian test needs a disc.
  LabTestOptions brazilian;
  brazilian.kind = LabTestKind::kBrazilian;
  ExpectRefused(*packing_, brazilian, {"brazilian", "disc", "rectangle"});
}

TEST_F(LabBadInput, NegativeConfinement) {
  LabTestOptions options;
  options.kind = LabTestKind::kConfinedCompression;
  options.confining_stress_pa = -1e6;
  ExpectRefused(*packing_, options, {"confining_stress_pa", ">= 0"});
  // The envelope refuses it too, before its first test.
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(RunConfinedEnvelope<2>(*packing_, Material(), options, {1e6, -2e6, 4e6}),
               InputError);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
}

TEST_F(LabBadInput, ModulusWindowOutsideZeroOne) {
  for (const auto& [low, high] : {std::pair{0.0, 0.5}, std::pair{0.1, 1.0}, std::pair{-0.1, 0.5},
                                  std::pair{0.6, 0.5}, std::pair{0.1, 1.5}}) {
    SCOPED_TRACE(std::to_string(low) + " - " + std::to_string(high));
    LabTestOptions options;
    options.modulus_window_low = low;
    options.modulus_window_high = high;
    ExpectRefused(*packing_, options, {"modulus_window"});
  }
}

TEST_F(LabBadInput, TimeStepSafetyFactorOutsideItsRange) {
  for (const double factor : {0.0, -0.5, 0.96, 1.0}) {
    SCOPED_TRACE(factor);
    LabTestOptions options;
    options.time_step_safety_factor = factor;
    ExpectRefused(*packing_, options, {"time_step_safety_factor", "(0, 0.95]"});
  }
}

// The option reaches the solver: the step is that share of the certified critical step.
TEST_F(LabBadInput, TimeStepIsTheSafetyFactorOfTheCriticalStep) {
  for (const double factor : {0.7, 0.5, 0.95}) {
    SCOPED_TRACE(factor);
    LabTestOptions options;
    options.strain_limit = 2e-5;
    options.time_step_safety_factor = factor;
    const LabTestResult r = RunLabTest<2>(*packing_, Material(), options);
    EXPECT_NEAR(r.time_step_s, factor * r.critical_time_step_s, 1e-12 * r.critical_time_step_s);
  }
}

// Unbreakable bonds: the UCS can never peak. It stops at the strain limit and says so.
TEST_F(LabBadInput, NoPeakWithinTheStrainLimitIsReported) {
  LabTestOptions options;
  options.strain_limit = 5e-4;
  const auto start = std::chrono::steady_clock::now();
  const LabTestResult r = RunLabTest<2>(*packing_, Material(), options);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 30.0);
  EXPECT_FALSE(r.peak_reached);
  EXPECT_EQ(r.termination, LabTermination::kStrainLimit);
  EXPECT_NE(r.termination_message.find("without a peak"), std::string::npos)
      << r.termination_message;
  EXPECT_GE(r.curve.back().boundary_strain, options.strain_limit);
  EXPECT_LT(r.curve.back().boundary_strain, 1.2 * options.strain_limit);
  // The elastic constants are still measured, on the window of the largest stress.
  EXPECT_TRUE(r.elastic.measured);
  EXPECT_NE(r.BriefReport().find("no peak"), std::string::npos) << r.BriefReport();
}

TEST_F(LabBadInput, StrainMarginThatLeavesNoRegion) {
  // 20 mean radii inside a 10 x 10 mm specimen of 300 discs (r ~ 0.3 mm) leaves nothing: a
  // UCS, whose E and nu come from that region, is refused naming the margin ...
  LabTestOptions ucs;
  ucs.strain_boundary_margin = 20.0;
  ExpectRefused(*packing_, ucs, {"strain_boundary_margin", "leaves"});
  EXPECT_THROW(DescribeSpecimen<2>(*packing_, LabTestKind::kUniaxialCompression, 20.0), InputError);
  EXPECT_EQ(DescribeSpecimen<2>(*packing_, LabTestKind::kUniaxialCompression, 2.0)
                .strain_margin_mean_radii,
            2.0);
}

TEST(LabSpecimenRegion, BrazilianDiscTooThinForTheMarginUsesTheWholeSkeleton) {
  // ... while a Brazilian test, whose strength is the platen force (Labra (4.38)), measures
  // its curve over the whole skeleton (rattlers still left out).
  GeneratorOptions options = DefaultGeneratorOptions<2>();
  options.particle_count = 200;
  options.seed = 3;
  const Packing<2> disc =
      GeneratePacking<2>(Domain<2>::Disc(Vector<2>(0.005, 0.005), 0.005), options, nullptr);
  const LabSpecimen<2> s = DescribeSpecimen<2>(disc, LabTestKind::kBrazilian, 20.0);
  EXPECT_EQ(s.strain_margin_mean_radii, 0.0);
  int inside = 0;
  for (int q = 0; q < disc.size(); ++q)
    inside += s.strain_region.empty() || s.strain_region[q] ? 1 : 0;
  EXPECT_EQ(inside, disc.size() - s.rattlers);
}

TEST(LabMohrCoulomb, NeedsTwoDistinctConfinements) {
  EXPECT_THROW(FitMohrCoulomb({1e6}, {5e7}), InputError);
  EXPECT_THROW(FitMohrCoulomb({1e6, 1e6}, {5e7, 5.1e7}), InputError);
  EXPECT_THROW(FitMohrCoulomb({1e6, 2e6}, {5e7}), InputError);
  // sigma_1 = 2 c cos(phi)/(1 - sin phi) + sigma_3 (1 + sin phi)/(1 - sin phi), phi = 30 deg:
  // slope 3, intercept 2 c sqrt(3): c = 10 MPa gives 34.64 MPa.
  const double a = 2e7 * std::sqrt(3.0);
  const MohrCoulombFit fit = FitMohrCoulomb({0.0, 5e6, 1e7}, {a, a + 1.5e7, a + 3e7});
  ASSERT_TRUE(fit.valid);
  EXPECT_NEAR(fit.friction_angle_deg, 30.0, 1e-9);
  EXPECT_NEAR(fit.cohesion_pa, 1e7, 1e-3);
}

// A 2D setting on a 3D specimen is refused, not ignored.
TEST(LabSceneFile, PlaneModelWithA3DSpecimenIsRefused) {
  const std::string scene =
      "[specimen]\ndomain = \"box 0 0 0 0.01 0.01 0.01\"\ncount = 500\n[material]\nnormal_stiffness = 1e7\n"
      "density = 2000\nparticle_youngs_modulus = 1e9\nparticle_poisson_ratio = 0.2\nplane_model = \"plane_strain\"\n"
      "[test]\nkind = \"ucs\"\n";
  try {
    ParseLabScene(scene, "scene.toml");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("plane_model is a 2D setting"), std::string::npos) << e.what();
  }
  // Without it the scene is fine.
  std::string ok = scene;
  ok.erase(ok.find("plane_model"), std::string("plane_model = \"plane_strain\"\n").size());
  EXPECT_NO_THROW(ParseLabScene(ok, "scene.toml"));
}

}  // namespace
}  // namespace specimen
