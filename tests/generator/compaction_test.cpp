// The compaction stage (force-biased growth and locking) on configurations with known answers.
#include "generator/compaction.h"

#include <gtest/gtest.h>

#include <random>

#include "generator/packing.h"

namespace specimen {
namespace {

// Smallest gap over all pairs and smallest distance to the boundary minus the radius.
template <int Dim>
double SmallestClearance(const Domain<Dim>& domain, const std::vector<Vector<Dim>>& x,
                         const std::vector<double>& r) {
  double smallest = 1e300;
  for (size_t i = 0; i < x.size(); ++i) {
    smallest = std::min(smallest, domain.SignedDistance(x[i]) - r[i]);
    for (size_t j = i + 1; j < x.size(); ++j)
      smallest = std::min(smallest, (x[i] - x[j]).norm() - r[i] - r[j]);
  }
  return smallest;
}

// A simple cubic lattice of spheres of radius 0.25 at spacing 1 in a box of side 4: the
// largest common radius is 0.5 (every sphere touches its neighbours and the walls).
TEST(Compaction, SimpleCubicLatticeGrowsToTouching) {
  const auto box = Domain<3>::Box(Vector<3>(0, 0, 0), Vector<3>(4, 4, 4));
  std::vector<Vector<3>> x;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) x.emplace_back(0.5 + i, 0.5 + j, 0.5 + k);
  std::vector<double> r(x.size(), 0.25);
  CompactionOptions options;
  options.length_scale = 0.25;
  const CompactionSummary summary = CompactPacking<3>(box, options, x, r);
  // Within the schedule's relative tolerance (1e-4) of touching.
  EXPECT_NEAR(summary.growth_factor, 2.0, 2.0 * options.tolerance);
  for (double radius : r) EXPECT_NEAR(radius, 0.5, 0.5 * options.tolerance);
  EXPECT_GE(SmallestClearance<3>(box, x, r), -1e-12);
}

// A loose random set of spheres (10 % of the box, overlaps allowed) is driven to a jammed
// packing: nothing overlaps or protrudes, r_max / r_min is kept, and the solid fraction is
// that of a random packing (random close packing of equal spheres: 0.64; walls lower it).
TEST(Compaction, LooseRandomSpheresJamWithoutOverlap) {
  const auto box = Domain<3>::Box(Vector<3>(0, 0, 0), Vector<3>(6, 6, 6));
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> position(0.3, 5.7), size(0.5, 1.0);
  std::vector<Vector<3>> x;
  std::vector<double> r;
  double volume = 0.0;
  while (volume < 0.1 * box.Volume()) {
    x.emplace_back(position(rng), position(rng), position(rng));
    r.push_back(0.3 * size(rng));
    volume += ParticleVolume<3>(r.back());
  }
  const std::vector<double> before = r;
  CompactionOptions options;
  options.length_scale = 0.25;
  const CompactionSummary summary = CompactPacking<3>(box, options, x, r);
  EXPECT_FALSE(summary.kept_input);
  EXPECT_GE(SmallestClearance<3>(box, x, r), -1e-12);
  double solid = 0.0;
  for (size_t i = 0; i < r.size(); ++i) {
    EXPECT_NEAR(r[i] / before[i], summary.growth_factor, 1e-12);
    solid += ParticleVolume<3>(r[i]);
  }
  const double fraction = solid / box.Volume();
  EXPECT_GT(fraction, 0.50) << summary.sweeps << " sweeps";
  EXPECT_LT(fraction, 0.66);
}

// A packing that cannot grow (touching discs of a hexagonal lattice, pinned by the walls
// of a tight rectangle along x) is returned unchanged.
TEST(Compaction, JammedInputIsKept) {
  const auto strip = Domain<2>::Rectangle(0, 0, 6, 1);
  std::vector<Vector<2>> x;
  for (int i = 0; i < 6; ++i) x.emplace_back(0.5 + i, 0.5);
  std::vector<double> r(x.size(), 0.5);
  const auto x0 = x;
  CompactionOptions options;
  options.length_scale = 0.5;
  const CompactionSummary summary = CompactPacking<2>(strip, options, x, r);
  EXPECT_TRUE(summary.kept_input);
  EXPECT_EQ(x, x0);
  for (double radius : r) EXPECT_DOUBLE_EQ(radius, 0.5);
}

}  // namespace
}  // namespace specimen
