#include "generator/neighbour_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "common/error.h"

namespace specimen {
namespace {

template <int Dim>
std::vector<Vector<Dim>> RandomCentres(int count, double extent, std::uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> uniform(0.0, extent);
  std::vector<Vector<Dim>> centres(count);
  for (auto& x : centres)
    for (int axis = 0; axis < Dim; ++axis) x[axis] = uniform(random);
  return centres;
}

template <int Dim>
std::vector<std::array<int, 2>> BruteForcePairs(const std::vector<Vector<Dim>>& centres,
                                                double cutoff) {
  std::vector<std::array<int, 2>> pairs;
  for (int i = 0; i < static_cast<int>(centres.size()); ++i)
    for (int j = i + 1; j < static_cast<int>(centres.size()); ++j)
      if ((centres[i] - centres[j]).norm() < cutoff) pairs.push_back({i, j});
  return pairs;
}

template <int Dim>
void ExpectPairsMatchBruteForce(int count, double extent, double cell_size, double cutoff,
                                std::uint32_t seed) {
  const auto centres = RandomCentres<Dim>(count, extent, seed);
  const NeighbourGrid<Dim> grid(centres, cell_size);
  std::vector<std::array<int, 2>> found;
  grid.ForEachPairWithin(cutoff, [&](int i, int j) {
    ASSERT_LT(i, j);
    found.push_back({i, j});
  });
  const size_t visited = found.size();
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  EXPECT_EQ(found.size(), visited) << "a pair was visited twice";
  EXPECT_EQ(found, BruteForcePairs<Dim>(centres, cutoff));
}

TEST(NeighbourGrid, PairsMatchBruteForce2D) {
  ExpectPairsMatchBruteForce<2>(2000, 10.0, 0.3, 0.3, 1);
  ExpectPairsMatchBruteForce<2>(2000, 10.0, 0.5, 0.2, 2);  // cutoff below the cell size
  ExpectPairsMatchBruteForce<2>(1000, 10.0, 0.2, 0.5, 3);  // cutoff above: wider stencil
}

TEST(NeighbourGrid, PairsMatchBruteForce3D) {
  ExpectPairsMatchBruteForce<3>(2000, 5.0, 0.4, 0.4, 4);
  ExpectPairsMatchBruteForce<3>(1500, 5.0, 0.25, 0.6, 5);
}

TEST(NeighbourGrid, SparseSetKeepsMemoryLinear) {
  // Two clusters far apart: a grid at the requested size would have 1e12 cells.
  std::vector<Vector<3>> centres = {{0, 0, 0}, {0.5, 0, 0}, {1e4, 1e4, 1e4}, {1e4, 1e4, 1e4 + 0.5}};
  const NeighbourGrid<3> grid(centres, 0.01);
  EXPECT_LE(grid.cell_count(), 64);
  EXPECT_GE(grid.cell_size(), 0.01);
  std::vector<std::array<int, 2>> found;
  grid.ForEachPairWithin(1.0, [&](int i, int j) { found.push_back({i, j}); });
  std::sort(found.begin(), found.end());
  EXPECT_EQ(found, (std::vector<std::array<int, 2>>{{0, 1}, {2, 3}}));
}

TEST(NeighbourGrid, NearQueryMatchesBruteForce) {
  const auto centres2 = RandomCentres<2>(3000, 10.0, 6);
  const NeighbourGrid<2> grid2(centres2, 0.4);
  const auto centres3 = RandomCentres<3>(3000, 5.0, 7);
  const NeighbourGrid<3> grid3(centres3, 0.4);
  std::mt19937 random(8);
  std::uniform_real_distribution<double> uniform(-1.0, 11.0);  // also outside the set's box
  for (int query = 0; query < 50; ++query) {
    const Vector<2> x(uniform(random), uniform(random));
    const double cutoff = query % 2 == 0 ? 0.4 : 1.1;
    std::vector<int> found, expected;
    grid2.ForEachNear(x, cutoff, [&](int j) { found.push_back(j); });
    for (int j = 0; j < static_cast<int>(centres2.size()); ++j)
      if ((centres2[j] - x).norm() < cutoff) expected.push_back(j);
    std::sort(found.begin(), found.end());
    EXPECT_EQ(found, expected);

    const Vector<3> y(uniform(random) / 2, uniform(random) / 2, uniform(random) / 2);
    found.clear();
    expected.clear();
    grid3.ForEachNear(y, cutoff, [&](int j) { found.push_back(j); });
    for (int j = 0; j < static_cast<int>(centres3.size()); ++j)
      if ((centres3[j] - y).norm() < cutoff) expected.push_back(j);
    std::sort(found.begin(), found.end());
    EXPECT_EQ(found, expected);
  }
}

TEST(NeighbourGrid, DegenerateSets) {
  const std::vector<Vector<2>> none;
  const NeighbourGrid<2> empty(none, 1.0);
  int visits = 0;
  empty.ForEachPairWithin(1.0, [&](int, int) { ++visits; });
  empty.ForEachNear(Vector<2>(0, 0), 1.0, [&](int) { ++visits; });
  EXPECT_EQ(visits, 0);
  // All centres at one point: every pair, each once.
  const std::vector<Vector<2>> same(5, Vector<2>(1.0, 2.0));
  const NeighbourGrid<2> grid(same, 0.1);
  grid.ForEachPairWithin(0.1, [&](int, int) { ++visits; });
  EXPECT_EQ(visits, 10);
  EXPECT_THROW(NeighbourGrid<2>(same, 0.0), InputError);
}

template <int Dim>
void ExpectOverlappingPairsMatchBruteForce(std::uint32_t seed) {
  const auto centres = RandomCentres<Dim>(1500, 6.0, seed);
  std::mt19937 random(seed + 100);
  std::uniform_real_distribution<double> radius(0.02, 0.25);  // radius ratio 12.5
  std::vector<double> radii(centres.size());
  for (double& r : radii) r = radius(random);
  for (double min_overlap : {0.0, 0.05}) {
    std::vector<std::array<int, 2>> expected;
    for (int i = 0; i < static_cast<int>(centres.size()); ++i)
      for (int j = i + 1; j < static_cast<int>(centres.size()); ++j)
        if ((centres[j] - centres[i]).norm() - radii[i] - radii[j] < -min_overlap)
          expected.push_back({i, j});
    EXPECT_FALSE(expected.empty());
    EXPECT_EQ(OverlappingPairs<Dim>(centres, radii, min_overlap), expected);
  }
}

TEST(NeighbourGrid, OverlappingPairsMatchBruteForce) {
  ExpectOverlappingPairsMatchBruteForce<2>(11);
  ExpectOverlappingPairsMatchBruteForce<3>(12);
  EXPECT_THROW(OverlappingPairs<2>(std::vector<Vector<2>>(3), std::vector<double>(2, 1.0)),
               InputError);
}

}  // namespace
}  // namespace specimen
