#include "generator/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <random>

#include "common/error.h"
#include "generator/ball_clip_volume.h"
#include "generator/neighbour_grid.h"
#include "reference_integration.h"

namespace specimen {
namespace {

using reference::kPi;

// Contacts as the generator makes them: every candidate pair within `cutoff` whose gap is
// within `tolerance` mean radii of zero.
template <int Dim>
void SetContactsWithin(Packing<Dim>& packing, double cutoff, double tolerance) {
  std::vector<std::array<int, 2>> candidates;
  NeighbourGrid<Dim>(packing.centres, cutoff).ForEachPairWithin(cutoff, [&](int i, int j) {
    candidates.push_back({i, j});
  });
  SetContactsFromCandidates(packing, candidates, tolerance);
}

template <int Dim>
std::vector<int> ContactsPerParticle(const Packing<Dim>& packing) {
  std::vector<int> count(packing.size(), 0);
  for (const auto& c : packing.contacts) {
    ++count[c[0]];
    ++count[c[1]];
  }
  return count;
}

// Every hexagonal-lattice disc (radius r, touching neighbours) whose centre lies in the
// rectangle [0, 2 r columns] x [0, 2 sqrt(3) r rows]: all discs that meet the rectangle.
Packing<2> HexagonalLatticeInRectangle(double r, int columns, int rows) {
  const double width = 2.0 * r * columns, height = 2.0 * std::sqrt(3.0) * r * rows;
  Packing<2> packing(Domain<2>::Rectangle(0.0, 0.0, width, height));
  for (int j = 0; j <= 2 * rows; ++j)
    for (double x = (j % 2) * r; x <= width * (1 + 1e-12); x += 2.0 * r) {
      packing.centres.push_back(Vector<2>(x, j * std::sqrt(3.0) * r));
      packing.radii.push_back(r);
    }
  SetContactsWithin(packing, 2.01 * r, 1e-6);
  return packing;
}

TEST(PackingMetrics, HexagonalLatticeInRectangleHasTheLatticePorosity) {
  const double r = 0.7;
  const Packing<2> packing = HexagonalLatticeInRectangle(r, 12, 7);
  MetricsOptions options;
  options.orientation_bins = 7;  // bins of 25.7 deg: 0, 60 and 120 deg fall well inside
  const auto m = ComputePackingMetrics(packing, options);
  // The rectangle is a union of periodic cells, each covered to pi / (2 sqrt 3).
  EXPECT_NEAR(m.corrected_porosity, 1.0 - kPi / (2.0 * std::sqrt(3.0)), 1e-12);
  EXPECT_EQ(m.corrected_porosity_error, 0.0);
  EXPECT_LT(m.nominal_porosity, m.corrected_porosity);  // cut discs counted whole
  EXPECT_EQ(m.overlapping_pairs, 0);                    // touching is not overlapping
  EXPECT_EQ(m.max_overlap, 0.0);
  EXPECT_NEAR(m.mean_radius, r, 1e-15);
  EXPECT_NEAR(m.mean_branch_length, 2.0 * r, 1e-12);
  const auto contacts = ContactsPerParticle(packing);
  int interior = 0;
  for (int i = 0; i < packing.size(); ++i)
    if (packing.domain.SignedDistance(packing.centres[i]) >= 2.0 * r - 1e-9) {
      ++interior;
      EXPECT_EQ(contacts[i], 6) << "particle " << i;
    }
  EXPECT_GT(interior, 100);
  // Branch directions 0, 60, 120 deg only, and as many at 60 as at 120 (mirror symmetry).
  const auto& rose = m.orientation_histograms.at(0);
  ASSERT_EQ(rose.size(), 7u);
  for (int bin : {1, 3, 5, 6}) EXPECT_EQ(rose[bin], 0.0);
  EXPECT_EQ(rose[2], rose[4]);
  EXPECT_NEAR(rose[0] + rose[2] + rose[4], m.contact_count, 1e-9);
  EXPECT_NEAR(m.fabric_eigenvalues[0], 0.5, 0.02);
  EXPECT_NEAR(m.fabric_eigenvalues[1], 0.5, 0.02);
}

TEST(PackingMetrics, OverlappingHexagonalLatticeHasTheHexagonCoverage) {
  // Spacing s < 2 r: power cells are the lattice hexagons (three power lines through each
  // vertex), and power lines of discs across the boundary lie on the boundary itself.
  const double s = 1.0, r = 0.54;
  const int columns = 6, rows = 4;
  const double width = s * columns, height = std::sqrt(3.0) * s * rows;
  Packing<2> packing(Domain<2>::Rectangle(0.0, 0.0, width, height));
  for (int j = -2; j <= 2 * rows + 2; ++j)
    for (int i = -2; i <= columns + 2; ++i) {
      const Vector<2> x(s * i + 0.5 * s * (j % 2 != 0), 0.5 * std::sqrt(3.0) * s * j);
      if (packing.domain.SignedDistance(x) > -r) {  // every disc that meets the rectangle
        packing.centres.push_back(x);
        packing.radii.push_back(r);
      }
    }
  const double h = 0.5 * s;  // apothem of the hexagon
  const double segment = r * r * std::acos(h / r) - h * std::sqrt(r * r - h * h);
  const double coverage = (kPi * r * r - 6.0 * segment) / (0.5 * std::sqrt(3.0) * s * s);
  const auto m = ComputePackingMetrics(packing);
  EXPECT_NEAR(m.corrected_porosity, 1.0 - coverage, 1e-12);
  EXPECT_NEAR(m.max_overlap, (2.0 * r - s) / r, 1e-12);
}

TEST(PackingMetrics, OverlappingSimpleCubicLatticeHasTheCubeCoverage) {
  // Spacing a < 2 r < sqrt(2) a: each power cell is the cube, ball ∩ cube = ball - 6 caps.
  const double a = 1.0, r = 0.6;
  const int cells = 3;
  Packing<3> packing(Domain<3>::Box(Vector<3>::Zero(), Vector<3>::Constant(a * cells)));
  for (int i = 0; i <= cells; ++i)
    for (int j = 0; j <= cells; ++j)
      for (int k = 0; k <= cells; ++k) {
        packing.centres.push_back(a * Vector<3>(i, j, k));
        packing.radii.push_back(r);
      }
  const double h = 0.5 * a;
  const double cap = kPi * std::pow(r - h, 2) * (2.0 * r + h) / 3.0;
  const double coverage = (4.0 / 3.0 * kPi * std::pow(r, 3) - 6.0 * cap) / std::pow(a, 3);
  const auto m = ComputePackingMetrics(packing);
  EXPECT_GT(m.corrected_porosity_error, 0.0);  // boundary spheres are bracketed
  EXPECT_LE(m.corrected_porosity_error, MetricsOptions().corrected_porosity_tolerance);
  EXPECT_NEAR(m.corrected_porosity, 1.0 - coverage, m.corrected_porosity_error + 1e-13);
}

TEST(PackingMetrics, SymmetricHexagonalPatchHasIsotropicFabric) {
  // Lattice discs within a circle around a lattice point: six-fold symmetric contacts.
  const double r = 1.0;
  Packing<2> packing(Domain<2>::Rectangle(-20, -20, 20, 20));
  for (int j = -8; j <= 8; ++j)
    for (int i = -8; i <= 8; ++i) {
      const Vector<2> x(2.0 * r * i + r * j, std::sqrt(3.0) * r * j);
      if (x.norm() <= 9.0 * r) {
        packing.centres.push_back(x);
        packing.radii.push_back(r);
      }
    }
  SetContactsWithin(packing, 2.01 * r, 1e-6);
  const auto m = ComputePackingMetrics(packing);
  EXPECT_NEAR(m.fabric_eigenvalues[0], 0.5, 1e-12);
  EXPECT_NEAR(m.fabric_eigenvalues[1], 0.5, 1e-12);
  EXPECT_NEAR(m.fabric(0, 1), 0.0, 1e-12);
  EXPECT_NEAR(m.fabric.trace(), 1.0, 1e-12);  // Labra (3.20)
  // No overlaps and every disc inside the domain: union = sum of the discs.
  EXPECT_NEAR(m.corrected_porosity, m.nominal_porosity, 1e-13);
  EXPECT_EQ(m.protruding_particles, 0);
}

TEST(PackingMetrics, SimpleCubicLatticeInBoxHasTheLatticePorosity) {
  const double r = 0.5;
  const int cells = 5;
  Packing<3> packing(Domain<3>::Box(Vector<3>::Zero(), Vector<3>::Constant(2.0 * r * cells)));
  for (int i = 0; i <= cells; ++i)
    for (int j = 0; j <= cells; ++j)
      for (int k = 0; k <= cells; ++k) {
        packing.centres.push_back(2.0 * r * Vector<3>(i, j, k));
        packing.radii.push_back(r);
      }
  SetContactsWithin(packing, 2.01 * r, 1e-6);
  const auto m = ComputePackingMetrics(packing);
  // Face spheres are halves (closed form); edge and corner spheres are bracketed.
  EXPECT_LE(m.corrected_porosity_error, MetricsOptions().corrected_porosity_tolerance);
  EXPECT_NEAR(m.corrected_porosity, 1.0 - kPi / 6.0, m.corrected_porosity_error + 1e-14);
  EXPECT_NEAR(m.corrected_porosity, 1.0 - kPi / 6.0, 1e-3);
  const auto contacts = ContactsPerParticle(packing);
  for (int i = 0; i < packing.size(); ++i)
    if (packing.domain.SignedDistance(packing.centres[i]) >= 2.0 * r - 1e-9) {
      EXPECT_EQ(contacts[i], 6);
    }
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(m.fabric_eigenvalues[k], 1.0 / 3.0, 1e-12);
  EXPECT_EQ(m.overlapping_pairs, 0);
}

TEST(PackingMetrics, OverlappingDiscPairMatchesTheLens) {
  const double r1 = 1.0, r2 = 0.6, d = 1.2;
  Packing<2> packing(Domain<2>::Rectangle(-5, -5, 5, 5));
  packing.centres = {Vector<2>(-0.3, 0.1), Vector<2>(-0.3 + d * 0.6, 0.1 + d * 0.8)};
  packing.radii = {r1, r2};
  packing.contacts = {{0, 1}};
  const auto m = ComputePackingMetrics(packing);
  const double union_area = kPi * (r1 * r1 + r2 * r2) - reference::LensArea(r1, r2, d);
  EXPECT_NEAR(m.corrected_porosity, 1.0 - union_area / 100.0, 1e-15);
  const double mean_radius = std::sqrt((r1 * r1 + r2 * r2) / 2.0);
  EXPECT_EQ(m.overlapping_pairs, 1);
  EXPECT_NEAR(m.max_overlap, (r1 + r2 - d) / mean_radius, 1e-14);
  EXPECT_NEAR(m.mean_overlap, m.max_overlap, 1e-15);
  EXPECT_NEAR(m.nominal_porosity, 1.0 - kPi * (r1 * r1 + r2 * r2) / 100.0, 1e-15);
  EXPECT_EQ(m.mean_contact_gap, 0.0);  // the only contact overlaps
}

TEST(PackingMetrics, OverlappingSpherePairMatchesTheLens) {
  const double r1 = 1.0, r2 = 0.7, d = 1.3;
  Packing<3> packing(Domain<3>::Box(Vector<3>::Constant(-4), Vector<3>::Constant(4)));
  const Vector<3> direction = Vector<3>(1, 2, -2) / 3.0;
  packing.centres = {Vector<3>(0.2, -0.1, 0.3), Vector<3>(0.2, -0.1, 0.3) + d * direction};
  packing.radii = {r1, r2};
  // Closed-form lens of two spheres.
  const double lens = kPi * std::pow(r1 + r2 - d, 2) *
                      (d * d + 2 * d * (r1 + r2) - 3 * std::pow(r1 - r2, 2)) / (12 * d);
  const double expected = 4.0 / 3.0 * kPi * (std::pow(r1, 3) + std::pow(r2, 3)) - lens;
  double bound = -1.0;
  const double volume = ClippedUnionVolume(packing, MetricsOptions(), &bound);
  EXPECT_EQ(bound, 0.0);  // one cap each: closed form
  EXPECT_NEAR(volume, expected, 1e-13);
}

TEST(PackingMetrics, ThreeOverlappingDiscsAtAWallMatchIntegration) {
  // Three mutually overlapping discs of different sizes, cut by the bottom wall.
  Packing<2> packing(Domain<2>::Rectangle(0, 0, 6, 4));
  packing.centres = {Vector<2>(2.0, 0.5), Vector<2>(2.9, 0.9), Vector<2>(2.4, 1.6)};
  packing.radii = {0.8, 0.6, 0.7};
  std::vector<reference::Circle> circles;
  for (int i = 0; i < 3; ++i)
    circles.push_back({packing.centres[i].x(), packing.centres[i].y(), packing.radii[i]});
  std::vector<double> breaks;
  for (const auto& c : circles) reference::AddLevelCrossings(c, 0.0, &breaks);
  const double expected = reference::UnionArea(
      circles, [](double) { return std::pair<double, double>(0.0, 4.0); }, breaks, 0.0, 6.0);
  EXPECT_NEAR(ClippedUnionVolume(packing, MetricsOptions(), nullptr), expected, 1e-12);
  // Power-diagram pieces do not double count: the union is below the sum of clipped discs.
  EXPECT_LT(expected, kPi * (0.64 + 0.36 + 0.49));
}

TEST(PackingMetrics, DiscsAtTheReflexCornerOfAnLShape) {
  // L-shaped polygon given clockwise; the notch is the square [1, 2] x [1, 2].
  const auto domain = Domain<2>::Polygon({{0, 0}, {0, 2}, {1, 2}, {1, 1}, {2, 1}, {2, 0}});
  auto column = [](double x) { return std::pair<double, double>(0.0, x <= 1.0 ? 2.0 : 1.0); };
  {  // centred on the reflex corner: three quarters of the disc
    Packing<2> packing(domain);
    packing.centres = {Vector<2>(1, 1)};
    packing.radii = {0.5};
    EXPECT_NEAR(ClippedUnionVolume(packing, MetricsOptions(), nullptr), 0.75 * kPi * 0.25, 1e-14);
  }
  {  // off-centre, plus an overlapping neighbour whose power line crosses the corner region
    Packing<2> packing(domain);
    packing.centres = {Vector<2>(1.2, 0.9), Vector<2>(0.7, 1.3)};
    packing.radii = {0.4, 0.35};
    std::vector<reference::Circle> circles = {{1.2, 0.9, 0.4}, {0.7, 1.3, 0.35}};
    std::vector<double> breaks = {1.0};
    for (const auto& c : circles)
      for (double level : {0.0, 1.0, 2.0}) reference::AddLevelCrossings(c, level, &breaks);
    const double expected = reference::UnionArea(circles, column, breaks, 0.0, 2.0);
    EXPECT_NEAR(ClippedUnionVolume(packing, MetricsOptions(), nullptr), expected, 1e-12);
  }
}

TEST(PackingMetrics, PowerLineOnTheDomainBoundaryIsNotCountedTwice) {
  // A disc and its mirror image across the left wall overlap: their power line is the wall.
  const double r = 0.3, h = 0.2;
  const double inside = kPi * r * r - (r * r * std::acos(h / r) - h * std::sqrt(r * r - h * h));
  for (const auto& domain :
       {Domain<2>::Rectangle(0, 0, 2, 2),                                         // convex
        Domain<2>::Polygon({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}})}) {  // L-shape
    Packing<2> packing(domain);
    packing.centres = {Vector<2>(h, 0.5), Vector<2>(-h, 0.5)};
    packing.radii = {r, r};
    EXPECT_NEAR(ClippedUnionVolume(packing, MetricsOptions(), nullptr), inside, 1e-14)
        << domain.ShapeName();
  }
}

TEST(PackingMetrics, ThreeOverlappingSpheresMatchIntegration) {
  // Caps that overlap each other (no closed form) and a sphere whose centre is covered.
  const std::vector<std::pair<Eigen::Vector3d, double>> balls = {
      {Eigen::Vector3d(0.0, 0.0, 0.0), 1.0},
      {Eigen::Vector3d(1.1, 0.3, -0.2), 0.8},
      {Eigen::Vector3d(0.5, 0.9, 0.4), 0.7},
      {Eigen::Vector3d(0.45, 0.35, 0.1), 0.5}};
  Packing<3> packing(Domain<3>::Box(Vector<3>::Constant(-5), Vector<3>::Constant(5)));
  for (const auto& [c, r] : balls) {
    packing.centres.push_back(c);
    packing.radii.push_back(r);
  }
  MetricsOptions options;
  options.corrected_porosity_tolerance = 1e-9;
  options.max_slices_per_sphere = 20000;
  double bound = -1.0;
  const double volume = ClippedUnionVolume(packing, options, &bound);
  EXPECT_GT(bound, 0.0);
  EXPECT_LE(bound, 1e-9 * packing.domain.Volume());
  EXPECT_NEAR(volume, reference::UnionOfBallsVolume(balls), bound + 1e-9);
}

TEST(PackingMetrics, SphereOnACylinderRim) {
  // Centred on the rim: by symmetry half of ball ∩ (infinite) cylinder.
  const double distance = 2.0, radius = 2.0;  // the centre lies on the mantle
  Packing<3> packing(Domain<3>::Cylinder(0.0, 0.0, radius, -4.0, 1.5));
  packing.centres = {Vector<3>(0.0, -distance, 1.5)};
  packing.radii = {1.0};
  const double event = std::sqrt(1.0 - std::pow(radius - distance, 2));
  const double ball_in_cylinder =
      reference::IntegratePiecewise({-event, event}, -1.0, 1.0, [&](double z) {
        return reference::LensArea(std::sqrt(std::max(0.0, 1.0 - z * z)), radius, distance);
      });
  MetricsOptions options;
  options.corrected_porosity_tolerance = 1e-8;
  double bound = -1.0;
  const double volume = ClippedUnionVolume(packing, options, &bound);
  EXPECT_NEAR(volume, 0.5 * ball_in_cylinder, bound + 1e-12);
  EXPECT_LE(bound, 1e-8 * packing.domain.Volume());
}

TEST(PackingMetrics, RandomDiscsInAnLShapeMatchIntegration) {
  // Heavy, random overlaps (hidden discs, centres covered by neighbours) across the edges
  // and the reflex corner of a non-convex domain.
  const auto domain = Domain<2>::Polygon({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}});
  std::mt19937 random(99);
  std::uniform_real_distribution<double> position(-0.2, 2.2), radius(0.05, 0.35);
  for (int trial = 0; trial < 5; ++trial) {
    Packing<2> packing(domain);
    std::vector<reference::Circle> circles;
    std::vector<double> breaks = {1.0};
    while (packing.size() < 40) {
      const Vector<2> x(position(random), position(random));
      const double r = radius(random);
      if (domain.SignedDistance(x) < -r) continue;
      packing.centres.push_back(x);
      packing.radii.push_back(r);
      circles.push_back({x.x(), x.y(), r});
      for (double level : {0.0, 1.0, 2.0})
        reference::AddLevelCrossings(circles.back(), level, &breaks);
    }
    const double expected = reference::UnionArea(
        circles, [](double x) { return std::pair<double, double>(0.0, x <= 1.0 ? 2.0 : 1.0); },
        breaks, 0.0, 2.0);
    EXPECT_NEAR(ClippedUnionVolume(packing, MetricsOptions(), nullptr), expected, 1e-11)
        << "trial " << trial;
  }
}

TEST(PackingMetrics, RandomDiscsInADiscDomainMatchIntegration) {
  const reference::Circle boundary{0.3, -0.2, 1.5};
  const auto domain = Domain<2>::Disc(Vector<2>(boundary.x, boundary.y), boundary.r);
  std::mt19937 random(5);
  std::uniform_real_distribution<double> position(-1.6, 1.6), radius(0.05, 0.4);
  Packing<2> packing(domain);
  std::vector<reference::Circle> circles;
  std::vector<double> breaks;
  while (packing.size() < 40) {
    const Vector<2> x(boundary.x + position(random), boundary.y + position(random));
    const double r = radius(random);
    if (domain.SignedDistance(x) < -r) continue;
    packing.centres.push_back(x);
    packing.radii.push_back(r);
    circles.push_back({x.x(), x.y(), r});
    reference::AddCircleCrossings(circles.back(), boundary, &breaks);
  }
  const double expected = reference::UnionArea(
      circles,
      [&](double x) {
        const double s =
            std::sqrt(std::max(0.0, boundary.r * boundary.r - std::pow(x - boundary.x, 2)));
        return std::pair<double, double>(boundary.y - s, boundary.y + s);
      },
      breaks, boundary.x - boundary.r, boundary.x + boundary.r);
  EXPECT_NEAR(ClippedUnionVolume(packing, MetricsOptions(), nullptr), expected, 1e-11);
}

TEST(PackingMetrics, RandomSpheresMatchIntegration) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> position(-0.8, 0.8), radius(0.3, 0.6);
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<std::pair<Eigen::Vector3d, double>> balls;
    Packing<3> packing(Domain<3>::Box(Vector<3>::Constant(-5), Vector<3>::Constant(5)));
    for (int k = 0; k < 7; ++k) {
      balls.push_back(
          {Eigen::Vector3d(position(random), position(random), position(random)), radius(random)});
      packing.centres.push_back(balls.back().first);
      packing.radii.push_back(balls.back().second);
    }
    MetricsOptions options;
    options.corrected_porosity_tolerance = 1e-8;
    double bound = -1.0;
    const double volume = ClippedUnionVolume(packing, options, &bound);
    EXPECT_LE(bound, 1e-8 * packing.domain.Volume());
    EXPECT_NEAR(volume, reference::UnionOfBallsVolume(balls), bound + 1e-9) << "trial " << trial;
  }
}

TEST(PackingMetrics, HiddenAndDuplicateParticlesAreCountedOnce) {
  Packing<2> plane(Domain<2>::Rectangle(-5, -5, 5, 5));
  plane.centres = {Vector<2>(0, 0), Vector<2>(0.2, 0.1), Vector<2>(0, 0), Vector<2>(3, 3),
                   Vector<2>(3, 3)};
  plane.radii = {1.0, 0.3, 1.0, 0.5, 0.5};  // 1 inside 0, 2 duplicates 0, 4 duplicates 3
  EXPECT_NEAR(ClippedUnionVolume(plane, MetricsOptions(), nullptr), kPi * 1.25, 1e-13);
  Packing<3> space(Domain<3>::Box(Vector<3>::Constant(-5), Vector<3>::Constant(5)));
  space.centres = {Vector<3>(0, 0, 0), Vector<3>(0.3, -0.2, 0.1), Vector<3>(0, 0, 0)};
  space.radii = {1.0, 0.4, 1.0};
  double bound = -1.0;
  EXPECT_NEAR(ClippedUnionVolume(space, MetricsOptions(), &bound), 4.0 / 3.0 * kPi, 1e-13);
  EXPECT_EQ(bound, 0.0);
}

TEST(PackingMetrics, ProtrusionThroughAWall) {
  Packing<2> packing(Domain<2>::Rectangle(0, 0, 10, 10));
  packing.centres = {Vector<2>(0.3, 5.0)};
  packing.radii = {1.0};
  const auto m = ComputePackingMetrics(packing);
  EXPECT_NEAR(m.max_protrusion, 0.7, 1e-15);
  EXPECT_EQ(m.protruding_particles, 1);
  const double segment = std::acos(0.3) - 0.3 * std::sqrt(1.0 - 0.09);  // cut off by x = 0
  EXPECT_NEAR(m.corrected_porosity, 1.0 - (kPi - segment) / 100.0, 1e-15);
}

TEST(PackingMetrics, DiscPartlyOutsideADiscDomain) {
  Packing<2> packing(Domain<2>::Disc(Vector<2>(1.0, -2.0), 5.0));
  const Vector<2> offset = 4.5 * Vector<2>(0.6, -0.8);
  packing.centres = {Vector<2>(1.0, -2.0) + offset, Vector<2>(1.0, -2.0)};
  packing.radii = {1.0, 1.0};
  const auto m = ComputePackingMetrics(packing);
  EXPECT_NEAR(m.max_protrusion, 0.5, 1e-14);
  EXPECT_EQ(m.protruding_particles, 1);
  const double inside = reference::LensArea(5.0, 1.0, 4.5) + kPi;
  EXPECT_NEAR(m.corrected_porosity, 1.0 - inside / (25.0 * kPi), 1e-14);
}

TEST(PackingMetrics, SpheresCentredOnBoxFacesEdgesAndCorners) {
  Packing<3> packing(Domain<3>::Box(Vector<3>::Zero(), Vector<3>(4, 5, 6)));
  packing.centres = {Vector<3>(2, 2.5, 0), Vector<3>(0, 0, 3), Vector<3>(4, 5, 6)};
  packing.radii = {1.0, 0.8, 1.2};
  MetricsOptions options;
  options.corrected_porosity_tolerance = 1e-6;
  double bound = -1.0;
  const double volume = ClippedUnionVolume(packing, options, &bound);
  const double expected =
      4.0 / 3.0 * kPi * (0.5 * 1.0 + 0.25 * std::pow(0.8, 3) + 0.125 * std::pow(1.2, 3));
  EXPECT_LE(bound, 1e-6 * 120.0);
  EXPECT_NEAR(volume, expected, bound + 1e-13);
}

TEST(PackingMetrics, SphereOnTheAxisOfANarrowerCylinder) {
  // A sphere wider than the cylinder: ball ∩ cylinder = tube of half-length s plus caps.
  const double r = 1.0, radius = 0.6, s = std::sqrt(r * r - radius * radius);
  Packing<3> packing(Domain<3>::Cylinder(0.5, -0.5, radius, -3.0, 3.0));
  packing.centres = {Vector<3>(0.5, -0.5, 0.2)};
  packing.radii = {r};
  MetricsOptions options;
  options.corrected_porosity_tolerance = 1e-6;
  double bound = -1.0;
  const double volume = ClippedUnionVolume(packing, options, &bound);
  const double expected =
      kPi * radius * radius * 2.0 * s + 2.0 * kPi * std::pow(r - s, 2) * (2 * r + s) / 3.0;
  EXPECT_LE(bound, 1e-6 * packing.domain.Volume());
  EXPECT_NEAR(volume, expected, bound + 1e-13);
}

TEST(PackingMetrics, SphereThroughACylinderMantleMatchesIntegration) {
  // Off-axis sphere crossing the mantle: slices are lenses of two circles.
  const double distance = 1.5, radius = 2.0;
  Packing<3> packing(Domain<3>::Cylinder(0.0, 0.0, radius, -5.0, 5.0));
  packing.centres = {Vector<3>(0.6 * distance, 0.8 * distance, 1.0)};
  packing.radii = {1.0};
  const double event = std::sqrt(1.0 - std::pow(radius - distance, 2));  // rho = R - d
  const double expected = reference::IntegratePiecewise({-event, event}, -1.0, 1.0, [&](double z) {
    return reference::LensArea(std::sqrt(std::max(0.0, 1.0 - z * z)), radius, distance);
  });
  MetricsOptions options;
  options.corrected_porosity_tolerance = 1e-7;
  double bound = -1.0;
  const double volume = ClippedUnionVolume(packing, options, &bound);
  EXPECT_LE(bound, 1e-7 * packing.domain.Volume());
  EXPECT_NEAR(volume, expected, bound + 1e-12);
  EXPECT_GT(bound, 0.0);
}

// The bracket of BallClipper is a guarantee: check it against an independent integral for
// random cuts, including planes through and beyond the centre and overlapping caps.
TEST(BallClipVolume, BoundHoldsForRandomCuts) {
  std::mt19937 random(2024);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  BallClipper clipper;
  int bracketed = 0;
  for (int trial = 0; trial < 40; ++trial) {
    BallClipProblem problem;
    std::vector<std::pair<Eigen::Vector3d, double>> planes;
    const int count = 1 + trial % 5;
    for (int k = 0; k < count; ++k) {
      Eigen::Vector3d n(uniform(random), uniform(random), uniform(random));
      if (trial % 7 == 0 && k == 0) n = Eigen::Vector3d(0, 0, 1);  // a horizontal cut
      n.normalize();
      const double h =
          trial % 3 == 0 ? 0.5 * uniform(random) : 0.3 + 0.6 * std::abs(uniform(random));
      problem.half_spaces.push_back({n, h});
      planes.push_back({n, h});
    }
    const double expected = reference::ClippedBallVolume(planes);
    for (double tolerance : {1e-3, 1e-6}) {
      const ClippedVolume result = clipper.Volume(problem, tolerance, 4000);
      if (result.slices > 0) ++bracketed;
      EXPECT_LE(result.error_bound, tolerance) << "trial " << trial;
      // The reference is accurate to ~1e-11.
      EXPECT_NEAR(result.volume, expected, result.error_bound + 1e-10) << "trial " << trial;
    }
  }
  EXPECT_GT(bracketed, 20);
}

TEST(BallClipVolume, BoundHoldsWithACylinderMantle) {
  // Independent reference: columns along z on a fine (x, y) grid; in each column the region
  // is the ball's chord cut by the planes, kept whole or dropped by the mantle test.
  std::mt19937 random(31);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  BallClipper clipper;
  for (int trial = 0; trial < 4; ++trial) {
    BallClipProblem problem;
    problem.use_mantle = true;
    problem.mantle_radius = 1.0 + std::abs(uniform(random));
    const double angle = 3.0 * uniform(random);
    problem.mantle_centre = (problem.mantle_radius + 0.5 * uniform(random)) *
                            Vector<2>(std::cos(angle), std::sin(angle));
    for (int k = 0; k < 1 + trial; ++k) {
      Vector<3> n(uniform(random), uniform(random), uniform(random));
      problem.half_spaces.push_back({n.normalized(), 0.2 + 0.6 * std::abs(uniform(random))});
    }
    const int cells = 1500;
    const double step = 2.0 / cells;
    double expected = 0.0;
    for (int a = 0; a < cells; ++a)
      for (int b = 0; b < cells; ++b) {
        const Vector<2> xy(-1.0 + (a + 0.5) * step, -1.0 + (b + 0.5) * step);
        if (xy.squaredNorm() >= 1.0 || (xy - problem.mantle_centre).norm() > problem.mantle_radius)
          continue;
        double low = -std::sqrt(1.0 - xy.squaredNorm()), high = -low;
        for (const HalfSpace& h : problem.half_spaces) {  // n_xy . xy + n_z z <= offset
          const double rest = h.offset - h.normal.head<2>().dot(xy);
          if (h.normal.z() > 0)
            high = std::min(high, rest / h.normal.z());
          else
            low = std::max(low, rest / h.normal.z());
        }
        expected += std::max(0.0, high - low) * step * step;
      }
    const ClippedVolume result = clipper.Volume(problem, 1e-3, 4000);
    EXPECT_GT(result.slices, 0);
    EXPECT_LE(result.error_bound, 1e-3);
    // The grid is accurate to ~3e-5 here (checked against a grid twice as fine).
    EXPECT_NEAR(result.volume, expected, result.error_bound + 5e-5) << "trial " << trial;
  }
}

TEST(BallClipVolume, EmptyAndDeeplyOverlappedRegions) {
  BallClipper clipper;
  // Two half-spaces with no common point inside the ball (a slab of negative width).
  BallClipProblem empty;
  empty.half_spaces = {{Vector<3>(1, 0, 0), -0.2}, {Vector<3>(-1, 0, 0), 0.1}};
  const ClippedVolume none = clipper.Volume(empty, 1e-6, 2000);
  EXPECT_EQ(none.volume, 0.0);
  EXPECT_EQ(none.error_bound, 0.0);
  // A thin wedge far from the centre (centre outside the region).
  BallClipProblem wedge;
  std::vector<std::pair<Eigen::Vector3d, double>> planes = {
      {Vector<3>(-1, 0, 0), -0.7}, {Vector<3>(0, 0.6, 0.8), 0.1}, {Vector<3>(0, -0.6, 0.8), 0.1}};
  for (const auto& [n, h] : planes) wedge.half_spaces.push_back({n, h});
  const ClippedVolume thin = clipper.Volume(wedge, 1e-6, 4000);
  EXPECT_NEAR(thin.volume, reference::ClippedBallVolume(planes), thin.error_bound + 1e-10);
  EXPECT_LE(thin.error_bound, 1e-6);
  EXPECT_GT(thin.volume, 0.05);
}

TEST(PackingMetrics, ContactStatisticsAndDescriptors) {
  // Five discs, four contacts: counts 3, 2, 2, 1, 0.
  Packing<2> packing(Domain<2>::Rectangle(-10, -10, 10, 10));
  packing.centres = {Vector<2>(0, 0), Vector<2>(2.1, 0), Vector<2>(0, 1.9), Vector<2>(-2.0, 0),
                     Vector<2>(6, 6)};
  packing.radii = {1.0, 1.0, 1.0, 1.0, 1.0};
  packing.contacts = {{0, 1}, {0, 2}, {0, 3}, {1, 2}};
  const auto m = ComputePackingMetrics(packing);
  EXPECT_EQ(m.contact_count, 4);
  EXPECT_DOUBLE_EQ(m.coordination_number, 2.0 * 4 / 5);
  EXPECT_DOUBLE_EQ(m.under_coordinated_fraction, 4.0 / 5.0);
  const double l12 = std::hypot(2.1, 1.9);
  // Gaps: 0.1 (0-1), -0.1 (0-2), 0 (0-3), l12 - 2 (1-2); open contacts: 0-1 and 1-2.
  EXPECT_NEAR(m.mean_contact_gap, (0.1 + l12 - 2.0) / 2.0, 1e-14);
  EXPECT_NEAR(m.max_contact_gap, l12 - 2.0, 1e-14);
  EXPECT_NEAR(m.mean_branch_length, (2.1 + 1.9 + 2.0 + l12) / 4.0, 1e-14);
  EXPECT_NEAR(m.mean_branch_length_squared, (2.1 * 2.1 + 1.9 * 1.9 + 4.0 + l12 * l12) / 4.0, 1e-13);
  EXPECT_EQ(m.overlapping_pairs, 1);  // 0-2 only
  EXPECT_NEAR(m.max_overlap, 0.1, 1e-14);
  // Radius moments with unequal radii.
  packing.radii = {1.0, 0.5, 0.8, 1.2, 0.3};
  const auto sizes = ComputePackingMetrics(packing);
  EXPECT_NEAR(sizes.mean_radius_squared, (1 + 0.25 + 0.64 + 1.44 + 0.09) / 5, 1e-15);
  EXPECT_NEAR(sizes.mean_radius_cubed, (1 + 0.125 + 0.512 + 1.728 + 0.027) / 5, 1e-15);
  EXPECT_NEAR(sizes.mean_radius, std::sqrt(sizes.mean_radius_squared), 1e-15);
  EXPECT_NEAR(sizes.radius_ratio, 4.0, 1e-15);
}

TEST(PackingMetrics, ThreeDimensionalOrientationHistogramsWeighProjections) {
  Packing<3> packing(Domain<3>::Box(Vector<3>::Constant(-5), Vector<3>::Constant(5)));
  const Vector<3> n = Vector<3>(1, 1, 0) / std::sqrt(2.0);
  packing.centres = {Vector<3>::Zero(), 2.0 * n};
  packing.radii = {1.0, 1.0};
  packing.contacts = {{0, 1}};
  MetricsOptions options;
  options.orientation_bins = 4;  // 45 deg bins
  const auto m = ComputePackingMetrics(packing, options);
  ASSERT_EQ(m.orientation_histograms.size(), 3u);
  EXPECT_NEAR(m.orientation_histograms[0][1], 1.0, 1e-15);                   // xy: 45 deg
  EXPECT_NEAR(m.orientation_histograms[1][0], 1.0 / std::sqrt(2.0), 1e-15);  // xz: 0 deg
  EXPECT_NEAR(m.orientation_histograms[2][0], 1.0 / std::sqrt(2.0), 1e-15);  // yz: 0 deg
  EXPECT_NEAR(m.fabric(0, 1), 0.5, 1e-15);
  EXPECT_NEAR(m.fabric_eigenvalues[0], 0.0, 1e-15);
  EXPECT_NEAR(m.fabric_eigenvalues[2], 1.0, 1e-15);
}

TEST(PackingMetrics, JsonAndReport) {
  const Packing<2> plane = HexagonalLatticeInRectangle(1.0, 3, 2);
  const auto m2 = ComputePackingMetrics(plane);
  const nlohmann::json json = MetricsToJson(m2);
  // Every number with a unit says it in its name; 2D volumes are areas.
  for (const char* key : {"dimension",
                          "particle_count",
                          "domain_area_m2",
                          "particle_area_m2",
                          "mean_radius_m",
                          "min_radius_m",
                          "max_radius_m",
                          "radius_ratio",
                          "nominal_porosity",
                          "corrected_porosity",
                          "corrected_porosity_error",
                          "contact_count",
                          "coordination_number",
                          "under_coordinated_fraction",
                          "overlapping_pairs",
                          "mean_overlap_per_r_mean",
                          "max_overlap_per_r_mean",
                          "mean_contact_gap_per_r_mean",
                          "max_contact_gap_per_r_mean",
                          "fabric",
                          "fabric_eigenvalues",
                          "orientation_histograms",
                          "max_protrusion_per_r_mean",
                          "protruding_particles",
                          "mean_radius_squared_m2",
                          "mean_radius_cubed_m3",
                          "mean_branch_length_m",
                          "mean_branch_length_squared_m2"})
    EXPECT_TRUE(json.contains(key)) << key;
  for (const char* unitless : {"domain_volume", "mean_radius", "max_overlap", "max_contact_gap"})
    EXPECT_FALSE(json.contains(unitless)) << unitless;
  EXPECT_DOUBLE_EQ(json["domain_area_m2"].get<double>(), m2.domain_volume);
  EXPECT_EQ(json["fabric"].size(), 2u);
  EXPECT_EQ(json["orientation_histograms"]["weights"][0].size(), 36u);
  EXPECT_DOUBLE_EQ(json["corrected_porosity"].get<double>(), m2.corrected_porosity);
  const std::string report = MetricsReport(m2);
  EXPECT_NE(report.find("corrected porosity"), std::string::npos);
  EXPECT_NE(report.find("coordination number"), std::string::npos);

  Packing<3> space(Domain<3>::Box(Vector<3>::Zero(), Vector<3>::Constant(3)));
  space.centres = {Vector<3>(1, 1, 1), Vector<3>(2.9, 1, 1)};
  space.radii = {1.0, 1.0};
  space.contacts = {{0, 1}};
  const auto m3 = ComputePackingMetrics(space);
  EXPECT_EQ(MetricsToJson(m3)["fabric"].size(), 3u);
  EXPECT_DOUBLE_EQ(MetricsToJson(m3)["domain_volume_m3"].get<double>(), 27.0);
  EXPECT_DOUBLE_EQ(MetricsToJson(m3)["particle_volume_m3"].get<double>(), m3.particle_volume);
  EXPECT_FALSE(MetricsToJson(m3).contains("domain_area_m2"));
  EXPECT_EQ(MetricsToJson(m3)["orientation_histograms"]["weights"].size(), 3u);
  EXPECT_FALSE(MetricsReport(m3).empty());
}

TEST(PackingMetrics, RejectsInvalidInput) {
  Packing<2> packing(Domain<2>::Rectangle(0, 0, 1, 1));
  packing.centres = {Vector<2>(0.5, 0.5)};
  packing.radii = {0.1};
  MetricsOptions options;
  options.orientation_bins = 0;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("orientation_bins"), std::string::npos);
  EXPECT_THROW(ComputePackingMetrics(packing, options), InputError);
  packing.contacts = {{0, 3}};
  EXPECT_THROW(ComputePackingMetrics(packing), InputError);
  const Packing<2> empty(Domain<2>::Rectangle(0, 0, 1, 1));
  EXPECT_DOUBLE_EQ(ComputePackingMetrics(empty).corrected_porosity, 1.0);
}

}  // namespace
}  // namespace specimen
