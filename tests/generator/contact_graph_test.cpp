#include "generator/contact_graph.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace specimen {
namespace {

bool HasEdge(const ContactGraph<2>& g, int i, int j) {
  return std::binary_search(g.edges.begin(), g.edges.end(),
                            std::array<int, 2>{std::min(i, j), std::max(i, j)});
}

TEST(ContactGraph, SquareOfFourPicksTheShorterDiagonalByWeight) {
  // Four equal discs on a unit square's corners: the Delaunay diagonal is ambiguous. Make
  // discs 0 and 2 larger: the regular triangulation must then connect 0-2, not 1-3.
  const auto domain = Domain<2>::Rectangle(-10, -10, 10, 10);
  const std::vector<Vector<2>> x = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const std::vector<double> r = {0.6, 0.4, 0.6, 0.4};
  const auto g = BuildContactGraph<2>(domain, x, r, 0.0);
  EXPECT_EQ(g.edges.size(), 5u);
  EXPECT_TRUE(HasEdge(g, 0, 2));
  EXPECT_FALSE(HasEdge(g, 1, 3));
  const std::vector<double> r2 = {0.4, 0.6, 0.4, 0.6};
  const auto g2 = BuildContactGraph<2>(domain, x, r2, 0.0);
  EXPECT_TRUE(HasEdge(g2, 1, 3));
  EXPECT_FALSE(HasEdge(g2, 0, 2));
}

TEST(ContactGraph, HiddenParticleIsTiedToItsCover) {
  // A small disc deep inside a big one is hidden in the regular triangulation; it must
  // still get edges (to the particles covering it) so the optimiser can push it out.
  const auto domain = Domain<2>::Rectangle(-10, -10, 10, 10);
  const std::vector<Vector<2>> x = {{0, 0}, {3, 0}, {0, 3}, {0.1, 0.1}};
  const std::vector<double> r = {1.5, 1.5, 1.5, 0.1};
  const auto g = BuildContactGraph<2>(domain, x, r, 0.0);
  EXPECT_EQ(g.hidden_particles, 1);
  EXPECT_TRUE(HasEdge(g, 0, 3));
}

TEST(ContactGraph, BoundaryTiesFollowPowerCells) {
  // A row of three discs along the bottom wall of a box, and one disc above the middle one.
  const auto domain = Domain<2>::Rectangle(0, 0, 6, 10);
  const std::vector<Vector<2>> x = {{1, 1}, {3, 1}, {5, 1}, {3, 3}};
  const std::vector<double> r(4, 1.0);
  const auto g = BuildContactGraph<2>(domain, x, r, 3.0);
  auto tied = [&](int particle, int facet) {
    return std::binary_search(g.boundary_ties.begin(), g.boundary_ties.end(),
                              std::pair<int, int>{particle, facet});
  };
  // Facet 0 is the bottom edge (0,0)-(6,0) of the counter-clockwise rectangle.
  EXPECT_TRUE(tied(0, 0));
  EXPECT_TRUE(tied(1, 0));
  EXPECT_TRUE(tied(2, 0));
  EXPECT_FALSE(tied(3, 0));  // screened from the bottom wall by disc 1
  // Left wall (facet 3): disc 0 touches it, disc 2 does not.
  EXPECT_TRUE(tied(0, 3));
  EXPECT_FALSE(tied(2, 3));
}

TEST(ContactGraph, TetrahedronIn3D) {
  const auto domain = Domain<3>::Box(Vector<3>(-5, -5, -5), Vector<3>(5, 5, 5));
  const std::vector<Vector<3>> x = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const std::vector<double> r(4, 0.5);
  const auto g = BuildContactGraph<3>(domain, x, r, 0.0);
  EXPECT_EQ(g.edges.size(), 6u);
  const auto cells = RegularTriangulationCells<3>(x, r);
  EXPECT_EQ(cells.size(), 1u);
}

}  // namespace
}  // namespace specimen
