#include "calibrate/dimensionless_groups.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "calibrate/voigt_estimate.h"

namespace specimen {
namespace {

// Labra Table 4.10 / 4.11 (3D verification assembly): nc 9.3921, e 27.450 %, r~ = 0.8431 mm,
// kn = 27.889 MN/m, E = 18.691 GPa  ->  Psi_E = E r~ / (kn nc (1 - e)) = 0.0829 (section
// 4.4.2, Tables 4.10-4.12; docs/sources.md, "Numbers reproduced").
TEST(DimensionlessGroups, LabraThreeDimensionalElasticGroup) {
  PackingDescriptors d;
  d.dimension = 3;
  d.porosity = 0.27450;
  d.coordination = 9.3921;
  // Any <r^3>, <l^2> with 4 <r^3> / <l^2> = 0.8431 mm.
  d.mean_branch_length_squared = 4 * 0.8431e-3 * 0.8431e-3;
  d.mean_radius_cubed = 0.8431e-3 * d.mean_branch_length_squared / 4;
  EXPECT_NEAR(d.CharacteristicRadius(), 0.8431e-3, 1e-15);
  EXPECT_NEAR(ElasticGroup(d, 18.691e9, 27.889e6), 0.0829, 5e-4);
  const double kn = NormalStiffnessFromElasticGroup(d, 18.691e9, 0.0829);
  EXPECT_NEAR(kn, 27.889e6, 0.01 * 27.889e6);
}

// Labra's 2D worked example (section 4.4.1): Psi_c = 0.710, sigma_c = 127.83 MPa, nc 5.9841,
// e 9.2121 %, A~/t = 0.1497 mm (the value his numbers imply) -> Rn = 4.9623 kN.
TEST(DimensionlessGroups, LabraTwoDimensionalStrengthGroup) {
  PackingDescriptors d;
  d.dimension = 2;
  d.porosity = 0.092121;
  d.coordination = 5.9841;
  d.mean_branch_length = 1.0e-3;
  d.mean_radius_squared = 0.1497e-3 * d.mean_branch_length / 2;
  EXPECT_NEAR(d.CharacteristicArea(), 0.1497e-3, 1e-15);
  EXPECT_NEAR(BondStrengthFromStrengthGroup(d, 127.83e6, 0.710), 4962.3, 5.0);
}

// The Voigt estimate of an isotropic 3D fabric in improved form: (2 + 3a) / (2 pi (4 + a)).
TEST(DimensionlessGroups, VoigtIn3DMatchesTheClosedForm) {
  // e = 0.3, nc = 8 and equal spheres r = 1 with l = 2: V = 4 pi N / (3 (1 - e)).
  const double e = 0.3, nc = 8.0, r = 1.0, l = 2.0;
  PackingDescriptors d;
  d.dimension = 3;
  d.porosity = e;
  d.coordination = nc;
  d.mean_radius_cubed = r * r * r;
  d.mean_branch_length_squared = l * l;
  // Fabric sums of an isotropic 3D fabric: <n^4> = 1/5, <n1^2 n2^2> = 1/15, with
  // c = Nc <l^2> / V = (nc/2) l^2 (1 - e) 3 / (4 pi r^3).
  const double c = 0.5 * nc * l * l * (1 - e) * 3 / (4 * 3.14159265358979323846 * r * r * r);
  FabricStiffnessSums sums{c / 5, c / 15, c * (1.0 / 3 - 1.0 / 5), -c / 15};
  for (double a : {0.0, 0.19248, 1.0}) {
    const double kn = 1e7;
    const auto elastic = VoigtElasticConstants(sums, kn, a * kn);
    EXPECT_NEAR(ElasticGroup(d, elastic.youngs_modulus_pa, kn),
                (2 + 3 * a) / (2 * 3.14159265358979323846 * (4 + a)), 1e-12);
  }
}

TEST(DimensionlessGroups, ScaledDensityMatchesLabraTables) {
  EXPECT_NEAR(ScaledDensity(2580, 0.092121), 2841.8, 0.05);  // Table 4.8
  EXPECT_NEAR(ScaledDensity(2580, 0.2745), 3556.2, 0.05);    // Table 4.11
}

TEST(DimensionlessGroups, DescriptorsRoundTripThroughJson) {
  PackingDescriptors d;
  d.dimension = 3;
  d.particles = 123;
  d.porosity = 0.3;
  d.coordination = 8.1;
  d.mean_radius = 0.01;
  d.radius_ratio = 9.5;
  d.mean_radius_squared = 1e-4;
  d.mean_radius_cubed = 1e-6;
  d.mean_branch_length = 0.02;
  d.mean_branch_length_squared = 4.1e-4;
  const auto back = DescriptorsFromJson(nlohmann::json::parse(DescriptorsToJson(d).dump()));
  EXPECT_EQ(back.particles, 123);
  EXPECT_DOUBLE_EQ(back.mean_branch_length_squared, 4.1e-4);
  EXPECT_THROW(DescriptorsFromJson(nlohmann::json::parse("{\"dimension\": 2}")), std::exception);
}

}  // namespace
}  // namespace specimen
