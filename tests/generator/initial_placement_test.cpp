// Steps 1 and 2 of the generator: the node size distribution (power law) and the random
// sequential addition of node spheres.
#include "generator/initial_placement.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "generator/packing.h"

namespace specimen {
namespace {

// Closed forms of E[s^k] for a density ~ s^-exponent on [1, S].
TEST(PowerLaw, MomentsMatchClosedForms) {
  const double spread = 8.0;
  // Log-uniform (exponent 1): E[s^3] = (S^3 - 1) / (3 ln S).
  EXPECT_NEAR(PowerLawMoment(spread, 1.0, 3.0), (std::pow(spread, 3) - 1.0) / (3.0 * std::log(spread)), 1e-12);
  // Uniform (exponent 0): E[s] = (1 + S) / 2.
  EXPECT_NEAR(PowerLawMoment(spread, 0.0, 1.0), 0.5 * (1.0 + spread), 1e-12);
  // Exponent 3, k = 3: the integrand is 1, so E[s^3] = (S - 1) / ((1 - S^-2) / 2).
  EXPECT_NEAR(PowerLawMoment(spread, 3.0, 3.0), (spread - 1.0) / (0.5 * (1.0 - 1.0 / (spread * spread))), 1e-12);
  // Exponent 4, k = 3: the integrand is 1/s, E[s^3] = ln S / ((1 - S^-3) / 3).
  EXPECT_NEAR(PowerLawMoment(spread, 4.0, 3.0), std::log(spread) / ((1.0 - std::pow(spread, -3.0)) / 3.0), 1e-12);
  // No spread: every size is 1.
  EXPECT_EQ(PowerLawMoment(1.0, 3.5, 3.0), 1.0);
}

TEST(PowerLaw, InverseTransformCoversTheRangeAndMatchesTheMoments) {
  const double spread = 8.0, exponent = 3.5;
  EXPECT_NEAR(PowerLawSize(spread, exponent, 0.0), 1.0, 1e-12);
  EXPECT_NEAR(PowerLawSize(spread, exponent, 1.0), spread, 1e-9);
  EXPECT_NEAR(PowerLawSize(spread, 1.0, 0.5), std::sqrt(spread), 1e-12);  // log-uniform median
  double previous = 0.0;
  for (double u = 0.0; u <= 1.0; u += 0.01) {
    const double s = PowerLawSize(spread, exponent, u);
    EXPECT_GT(s, previous);
    previous = s;
  }
  // Sample moments of 200,000 draws (fixed seed) within 1 % of the exact ones.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double m1 = 0.0, m3 = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double s = PowerLawSize(spread, exponent, unit(rng));
    m1 += s / n;
    m3 += s * s * s / n;
  }
  EXPECT_NEAR(m1 / PowerLawMoment(spread, exponent, 1.0), 1.0, 0.01);
  EXPECT_NEAR(m3 / PowerLawMoment(spread, exponent, 3.0), 1.0, 0.01);
}

// The node spheres of a power-law spread lie inside the domain, do not overlap, span the
// spread and fill the requested fraction (nearly all of them find a place at 30 %).
TEST(RandomSequentialNodes, PowerLawSpheresInACylinder) {
  const auto cylinder = Domain<3>::Cylinder(0, 0, 0.5, 0, 1);
  std::mt19937_64 rng(3);
  const NodeSet<3> nodes = RandomSequentialNodes<3>(cylinder, 2000, 8.0, 3.5, 0.30, 200, rng);
  const auto& x = nodes.positions;
  const auto& rho = nodes.exclusion_radii;
  ASSERT_GE(x.size(), 1990u);
  double volume = 0.0;
  for (size_t i = 0; i < x.size(); ++i) {
    EXPECT_GE(cylinder.SignedDistance(x[i]), rho[i] * (1 - 1e-12));
    for (size_t j = i + 1; j < x.size(); ++j) EXPECT_GE((x[i] - x[j]).norm(), rho[i] + rho[j]);
    volume += ParticleVolume<3>(rho[i]);
  }
  const auto [smallest, largest] = std::minmax_element(rho.begin(), rho.end());
  EXPECT_LE(*largest / *smallest, 8.0 * (1 + 1e-12));
  EXPECT_GT(*largest / *smallest, 5.0);
  EXPECT_NEAR(volume / cylinder.Volume(), 0.30, 0.01);
}

}  // namespace
}  // namespace specimen
