#include "calibrate/target_material.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "common/error.h"

namespace specimen {
namespace {

const char* kLabra = R"(
[material]
name = "rock"
youngs_modulus = 18.691e9
poisson_ratio = 0.20
ucs = 127.83e6
tensile_strength = 12.30e6
density = 2580.0
)";

TEST(TargetMaterial, ReadsTheBundledLabraRock) {
  const auto m = LoadTargetMaterial(std::string(SPECIMEN_SOURCE_DIR) + "/data/materials/labra2012_rock.toml");
  EXPECT_DOUBLE_EQ(m.youngs_modulus_pa, 18.691e9);
  EXPECT_DOUBLE_EQ(m.poisson_ratio, 0.20);
  EXPECT_DOUBLE_EQ(m.ucs_pa, 127.83e6);
  EXPECT_DOUBLE_EQ(m.tensile_strength_pa, 12.30e6);
  EXPECT_DOUBLE_EQ(m.density_kg_per_m3, 2580.0);
  EXPECT_NEAR(m.StrengthRatio(), 10.3927, 1e-4);  // Labra section 4.4.1
  EXPECT_FALSE(m.friction_angle_deg.has_value());
  const auto g = LoadTargetMaterial(std::string(SPECIMEN_SOURCE_DIR) + "/data/materials/granitic_gneiss_1.toml");
  EXPECT_NEAR(g.StrengthRatio(), 14.44, 0.01);
}

TEST(TargetMaterial, OptionalFrictionAngleAndConfinedStrengths) {
  const auto m = ParseTargetMaterial(std::string(kLabra) + R"(friction_angle = 35
[[confined]]
confinement = 5e6
peak_stress = 160e6
[[confined]]
confinement = 10e6
peak_stress = 190e6
)", "test");
  ASSERT_TRUE(m.friction_angle_deg.has_value());
  EXPECT_DOUBLE_EQ(*m.friction_angle_deg, 35.0);
  ASSERT_EQ(m.confined.size(), 2u);
  EXPECT_DOUBLE_EQ(m.confined[1].peak_stress_pa, 190e6);
}

void ExpectRejected(const std::string& text, const std::string& must_mention) {
  try {
    ParseTargetMaterial(text, "bad.toml");
    FAIL() << "accepted:\n" << text;
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(must_mention), std::string::npos) << e.what();
  }
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  text.replace(text.find(from), from.size(), to);
  return text;
}

TEST(TargetMaterial, BadInputNamesTheFieldAndRange) {
  const std::string base = kLabra;
  ExpectRejected(Replace(base, "youngs_modulus = 18.691e9", "youngs_modulus = -1"), "youngs_modulus");
  ExpectRejected(Replace(base, "poisson_ratio = 0.20", "poisson_ratio = 0.5"), "(-1, 0.5)");
  ExpectRejected(Replace(base, "poisson_ratio = 0.20", "poisson_ratio = -1.2"), "poisson_ratio");
  ExpectRejected(Replace(base, "ucs = 127.83e6", "ucs = 10e6"), "larger than the tensile strength");
  ExpectRejected(Replace(base, "density = 2580.0", "density = -2580.0"), "density");
  ExpectRejected(Replace(base, "density = 2580.0", ""), "'density' is missing");
  ExpectRejected(Replace(base, "density = 2580.0", "density = \"heavy\""), "must be a number");
  ExpectRejected(Replace(base, "density = 2580.0", "densty = 2580.0"), "unknown key 'densty'");
  ExpectRejected(base + "friction_angle = 95\n", "(0, 90)");
  ExpectRejected(base + "[[confined]]\nconfinement = -1\npeak_stress = 1e8\n", "confinement");
  ExpectRejected("[material\n", "line 1");
  ExpectRejected("x = 1\n", "unknown key 'x'");
  EXPECT_THROW(LoadTargetMaterial("/nonexistent/material.toml"), FileError);
  // A directory is a file error, not a material without its table.
  EXPECT_THROW(LoadTargetMaterial(std::filesystem::temp_directory_path().string()), FileError);
}

}  // namespace
}  // namespace specimen
