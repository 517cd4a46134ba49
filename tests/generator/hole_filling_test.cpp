#include "generator/hole_filling.h"

#include <gtest/gtest.h>

#include <cmath>

namespace specimen {
namespace {

// Descartes: three mutually tangent unit circles hold an inner circle of radius
// 2/sqrt(3) - 1 = 0.1547, centred at their centroid.
TEST(ApolloniusSphere, InnerSoddyCircleOfThreeUnitCircles) {
  const double h = std::sqrt(3.0);
  const std::vector<Vector<2>> centres = {{0, 0}, {2, 0}, {1, h}};
  Vector<2> c;
  double radius = 0;
  ASSERT_TRUE(ApolloniusSphere<2>(centres, {1, 1, 1}, {}, {}, &c, &radius));
  EXPECT_NEAR(radius, 2 / std::sqrt(3.0) - 1, 1e-12);
  EXPECT_NEAR(c.x(), 1.0, 1e-12);
  EXPECT_NEAR(c.y(), h / 3, 1e-12);
}

// Four mutually tangent unit spheres (regular tetrahedron, edge 2) hold a sphere of radius
// sqrt(3/2) - 1 = 0.2247.
TEST(ApolloniusSphere, SphereInTheTetrahedralHole) {
  const std::vector<Vector<3>> centres = {
      {0, 0, 0}, {2, 0, 0}, {1, std::sqrt(3.0), 0}, {1, 1 / std::sqrt(3.0), 2 * std::sqrt(2.0 / 3.0)}};
  Vector<3> c;
  double radius = 0;
  ASSERT_TRUE(ApolloniusSphere<3>(centres, {1, 1, 1, 1}, {}, {}, &c, &radius));
  EXPECT_NEAR(radius, std::sqrt(1.5) - 1, 1e-12);
  for (const auto& p : centres) EXPECT_NEAR((p - c).norm(), 1 + radius, 1e-12);
}

// Two unit circles on the floor, touching: the circle in the cusp between them and the
// floor has radius 1/4 (Descartes with a line, curvature 0).
TEST(ApolloniusSphere, CircleBetweenTwoCirclesAndAWall) {
  Vector<2> c;
  double radius = 0;
  ASSERT_TRUE(ApolloniusSphere<2>({{0, 1}, {2, 1}}, {1, 1}, {{0, 0}}, {{0, -1}}, &c, &radius));
  EXPECT_NEAR(radius, 0.25, 1e-12);
  EXPECT_NEAR(c.x(), 1.0, 1e-12);
  EXPECT_NEAR(c.y(), 0.25, 1e-12);
}

TEST(FillHoles, FillsTheHoleOfAHexagonalTriple) {
  const auto domain = Domain<2>::Rectangle(-10, -10, 10, 10);
  const double h = std::sqrt(3.0);
  std::vector<Vector<2>> x = {{0, 0}, {2, 0}, {1, h}};
  std::vector<double> r = {1, 1, 1};
  const auto graph = BuildContactGraph<2>(domain, x, r, 0.0, /*with_cells=*/true);
  HoleFillingOptions options;
  options.min_radius = 0.1;
  options.max_radius = 1.0;
  EXPECT_EQ(FillHoles<2>(domain, graph, options, x, r), 1);
  ASSERT_EQ(x.size(), 4u);
  EXPECT_NEAR(r[3], 2 / std::sqrt(3.0) - 1, 1e-12);
  options.min_radius = 0.2;  // the hole is smaller: nothing inserted
  x.resize(3);
  r.resize(3);
  EXPECT_EQ(FillHoles<2>(domain, graph, options, x, r), 0);
}

}  // namespace
}  // namespace specimen
