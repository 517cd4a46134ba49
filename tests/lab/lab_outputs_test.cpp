// The conventions of run-test's reports (docs/exports.md, "Units and names in the output
// files"): units in the names, per metre of thickness in 2D, a check not run reported as not
// run, and a missing fit as null rather than 0.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "lab/lab_envelope.h"
#include "lab/lab_test.h"

namespace specimen {
namespace {

LabTestResult Result(int dimension, LabTestKind kind) {
  LabTestResult r;
  r.dimension = dimension;
  r.kind = kind;
  r.peak_force_n = 1234.0;
  r.peak_control = 5e7;
  r.wall_seconds = 2.5;
  r.energy.kinetic_j = 0.25;
  return r;
}

TEST(LabReportNames, ForcesAndEnergiesArePerMetreOfThicknessIn2D) {
  const nlohmann::json plane = Result(2, LabTestKind::kUniaxialCompression).ToJson();
  EXPECT_EQ(plane["peak_force_n_per_m"], 1234.0);
  EXPECT_FALSE(plane.contains("peak_force_n"));
  EXPECT_EQ(plane["peak_control_pa"], 5e7);
  EXPECT_EQ(plane["energy"]["kinetic_j_per_m"], 0.25);
  EXPECT_FALSE(plane["energy"].contains("kinetic_j"));
  EXPECT_TRUE(plane["energy"].contains("relative_imbalance"));  // no unit: unchanged
  EXPECT_EQ(plane["wall_time_s"], 2.5);

  const nlohmann::json solid = Result(3, LabTestKind::kUniaxialCompression).ToJson();
  EXPECT_EQ(solid["peak_force_n"], 1234.0);
  EXPECT_EQ(solid["energy"]["kinetic_j"], 0.25);

  // The Brazilian test is controlled by the platen force.
  EXPECT_EQ(Result(2, LabTestKind::kBrazilian).ToJson()["peak_control_n_per_m"], 5e7);
  EXPECT_EQ(Result(3, LabTestKind::kBrazilian).ToJson()["peak_control_n"], 5e7);
}

TEST(LabReportChecks, AQuasiStaticCheckNotRunIsNeitherPassedNorFailed) {
  LabTestResult r = Result(2, LabTestKind::kUniaxialCompression);
  const nlohmann::json not_run = r.ToJson()["quasi_static_check"];
  EXPECT_EQ(not_run["status"], "not run");
  EXPECT_TRUE(not_run["passed"].is_null());
  EXPECT_NE(not_run["reason"].get<std::string>().find("not requested"), std::string::npos);
  EXPECT_TRUE(not_run["modulus_change"].is_null());
  EXPECT_NE(r.FullReport().find("quasi-static check (half rate)     not run: not requested"),
            std::string::npos)
      << r.FullReport();

  r.quasi_static.performed = true;
  r.quasi_static.modulus_change = 0.002;
  r.quasi_static.passed = true;
  const nlohmann::json passed = r.ToJson()["quasi_static_check"];
  EXPECT_EQ(passed["status"], "passed");
  EXPECT_EQ(passed["passed"], true);
  EXPECT_TRUE(passed["reason"].is_null());
  EXPECT_EQ(passed["modulus_change"], 0.002);
  r.quasi_static.passed = false;
  EXPECT_EQ(r.ToJson()["quasi_static_check"]["status"], "failed");
  EXPECT_EQ(r.ToJson()["quasi_static_check"]["passed"], false);
}

TEST(LabReportChecks, AnEnvelopeWithoutAFitHasNoFittedNumbers) {
  ConfinedEnvelope envelope;
  envelope.fit_message = "needs two distinct confinements";
  const nlohmann::json fit = envelope.ToJson()["fit"];
  EXPECT_EQ(fit["valid"], false);
  for (const char* key : {"intercept_pa", "slope", "cohesion_pa", "friction_angle_deg", "rms_residual_pa"})
    EXPECT_TRUE(fit[key].is_null()) << key;
  EXPECT_EQ(fit["message"], "needs two distinct confinements");
}

}  // namespace
}  // namespace specimen
