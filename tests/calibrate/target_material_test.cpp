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

// An orthotropic target (the lattice model): E and nu become its apparent plane-strain constants
// along the loading axis y, from the compliance of its D.
TEST(TargetMaterial, OrthotropicTargetGivesTheApparentConstantsAlongY) {
  const std::string text = R"(
[material]
name = "slate"
youngs_modulus_1 = 60e9
youngs_modulus_2 = 30e9
poisson_ratio_12 = 0.25
shear_modulus_12 = 15e9
youngs_modulus_3 = 60e9
poisson_ratio_13 = 0.2
poisson_ratio_23 = 0.125
ucs = 100e6
tensile_strength = 8e6
density = 2700
)";
  const TargetMaterial m = ParseTargetMaterial(text, "slate");
  ASSERT_TRUE(m.orthotropic.has_value());
  // Axis 2 along y, plane strain eps_zz = 0: S22' = S22 - S23^2 / S33, S12' = S12 - S13 S23 / S33.
  const double s22 = 1.0 / 30e9, s33 = 1.0 / 60e9, s23 = -0.125 / 30e9, s12 = -0.25 / 60e9, s13 = -0.2 / 60e9;
  const double s22p = s22 - s23 * s23 / s33, s12p = s12 - s13 * s23 / s33;
  // E, nu: the isotropic pair of the same in-plane response, E' = E / (1 - nu^2), nu' = nu / (1 - nu).
  const double nu_in = -s12p / s22p, nu = nu_in / (1.0 + nu_in);
  EXPECT_NEAR(m.poisson_ratio, nu, 1e-12);
  EXPECT_NEAR(m.youngs_modulus_pa, (1.0 / s22p) * (1.0 - nu * nu), 1e-9 * 30e9);
  // At 90 degrees axis 1 lies along y.
  const TargetMaterial turned = ParseTargetMaterial(text + "axis_angle = 90\n", "slate");
  const double s11p = 1.0 / 60e9 - s13 * s13 / s33, s21p = -0.25 / 60e9 - s13 * s23 / s33;
  const double nu_turned = (-s21p / s11p) / (1.0 - s21p / s11p);
  EXPECT_NEAR(turned.youngs_modulus_pa, (1.0 / s11p) * (1.0 - nu_turned * nu_turned), 1e-6 * 60e9);
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
  ExpectRejected(base + "youngs_modulus_1 = 6e10\n", "not both");
  ExpectRejected("[material]\nyoungs_modulus_1 = 6e10\nyoungs_modulus_2 = 3e10\npoisson_ratio_12 = 0.2\n"
                 "shear_modulus_12 = 1e10\nucs = 1e8\ntensile_strength = 8e6\ndensity = 2700\n",
                 "'youngs_modulus_3' is missing");
  ExpectRejected("x = 1\n", "unknown key 'x'");
  EXPECT_THROW(LoadTargetMaterial("/nonexistent/material.toml"), FileError);
  // A directory is a file error, not a material without its table.
  EXPECT_THROW(LoadTargetMaterial(std::filesystem::temp_directory_path().string()), FileError);
}

}  // namespace
}  // namespace specimen
