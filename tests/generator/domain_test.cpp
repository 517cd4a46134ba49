#include "generator/domain.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(Domain, RectangleGeometry) {
  const auto d = Domain<2>::Rectangle(0, 0, 4, 2);
  EXPECT_DOUBLE_EQ(d.Volume(), 8.0);
  EXPECT_DOUBLE_EQ(d.SignedDistance(Vector<2>(1, 1)), 1.0);
  EXPECT_DOUBLE_EQ(d.SignedDistance(Vector<2>(3.5, 0.5)), 0.5);
  EXPECT_DOUBLE_EQ(d.SignedDistance(Vector<2>(5, 1)), -1.0);
  ASSERT_EQ(d.Facets().size(), 4u);
  for (const auto& f : d.Facets()) {
    // Facet distance positive inside, mirror lands outside at the same distance.
    const Vector<2> x(1.0, 0.5);
    const double s = d.FacetDistance(f, x);
    EXPECT_GT(s, 0.0);
    EXPECT_NEAR(d.FacetDistance(f, d.Mirror(f, x)), -s, 1e-12);
  }
}

TEST(Domain, DiscAndCylinder) {
  const auto disc = Domain<2>::Disc(Vector<2>(1, 1), 2.0);
  EXPECT_NEAR(disc.Volume(), 4 * kPi, 1e-12);
  EXPECT_NEAR(disc.SignedDistance(Vector<2>(1, 2)), 1.0, 1e-12);
  const auto& f = disc.Facets()[0];
  const Vector<2> x(1.5, 1.0);
  EXPECT_NEAR(disc.FacetDistance(f, disc.Mirror(f, x)), -1.5, 1e-12);

  const auto cyl = Domain<3>::Cylinder(0, 0, 0.5, 0, 1);
  EXPECT_NEAR(cyl.Volume(), kPi * 0.25, 1e-12);
  EXPECT_NEAR(cyl.SignedDistance(Vector<3>(0, 0, 0.5)), 0.5, 1e-12);
  EXPECT_NEAR(cyl.SignedDistance(Vector<3>(0.4, 0, 0.5)), 0.1, 1e-12);
  EXPECT_NEAR(cyl.SignedDistance(Vector<3>(0, 0, 0.05)), 0.05, 1e-12);
  EXPECT_LT(cyl.SignedDistance(Vector<3>(0.6, 0, 0.5)), 0.0);
  EXPECT_EQ(cyl.Facets().size(), 3u);
}

TEST(Domain, PolygonOrientationAndReflexCorner) {
  // L-shaped polygon given clockwise: stored counter-clockwise, area positive.
  const std::vector<Vector<2>> l_shape = {{0, 0}, {0, 2}, {1, 2}, {1, 1}, {2, 1}, {2, 0}};
  const auto d = Domain<2>::Polygon(l_shape);
  EXPECT_NEAR(d.Volume(), 3.0, 1e-12);
  EXPECT_GT(d.SignedDistance(Vector<2>(0.5, 1.5)), 0.0);
  EXPECT_LT(d.SignedDistance(Vector<2>(1.5, 1.5)), 0.0);  // in the notch
  // The edge from (1,1) to (1,2) does not apply to a point below y = 1.
  for (const auto& f : d.Facets()) {
    if (f.point.x() == 1.0 && f.end.x() == 1.0) {
      EXPECT_FALSE(d.FacetApplies(f, Vector<2>(0.5, 0.5)));
      EXPECT_TRUE(d.FacetApplies(f, Vector<2>(0.5, 1.5)));
    }
  }
}

TEST(Domain, TextRoundTripIsBitExact) {
  const auto rect = Domain<2>::Rectangle(0.1, -0.3, 100.0 / 3.0, 2.0 / 7.0);
  EXPECT_EQ(Domain<2>::Parse(rect.ToText()).ToText(), rect.ToText());
  // The short form is for reading: 0.05 stays 0.05 (the exact form has 17 digits).
  EXPECT_EQ(Domain<2>::Rectangle(0, 0, 0.05, 0.05).ToShortText(), "rectangle 0 0 0.05 0.05");
  EXPECT_EQ(Domain<3>::Cylinder(0, 0, 0.025, 0, 0.1).ToShortText(),
            "cylinder 0 0 0.025 0 0.1");
  const auto poly = Domain<2>::Polygon({{0, 0}, {1.0 / 3.0, 0}, {0.5, 0.7}, {0, 1}});
  const auto poly2 = Domain<2>::Parse(poly.ToText());
  EXPECT_EQ(poly2.ToText(), poly.ToText());
  EXPECT_EQ(poly2.PolygonVertices()[1].x(), 1.0 / 3.0);
  const auto cyl = Domain<3>::Cylinder(0.1, 0.2, 0.5, 0, 1.0 / 3.0);
  EXPECT_EQ(Domain<3>::Parse(cyl.ToText()).ToText(), cyl.ToText());
  const auto box = Domain<3>::Box(Vector<3>(0, 0, 0), Vector<3>(1, 2, 3));
  EXPECT_EQ(Domain<3>::Parse(box.ToText()).ToText(), box.ToText());
}

TEST(Domain, BadInputNamesTheField) {
  try {
    Domain<2>::Rectangle(0, 0, -1, 1);
    FAIL() << "negative width accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("width"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Domain<2>::Disc(Vector<2>(0, 0), 0.0), InputError);
  EXPECT_THROW(Domain<3>::Cylinder(0, 0, 1, 1, 1), InputError);
  EXPECT_THROW(Domain<3>::Box(Vector<3>(0, 0, 0), Vector<3>(1, 0, 1)), InputError);
  // Bow-tie: self-intersecting.
  try {
    Domain<2>::Polygon({{0, 0}, {1, 1}, {1, 0}, {0, 1}});
    FAIL() << "self-intersecting polygon accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("self-intersecting"), std::string::npos);
  }
  EXPECT_THROW(Domain<2>::Polygon({{0, 0}, {1, 1}}), InputError);
  EXPECT_THROW(Domain<2>::Parse("hexagon 1 2 3"), InputError);
  EXPECT_THROW(Domain<3>::Parse("rectangle 0 0 1 1"), InputError);
  EXPECT_THROW(Domain<2>::Parse("rectangle 0 0 1"), InputError);
  EXPECT_THROW(Domain<2>::Parse("rectangle 0 0 1 x"), InputError);
  // Decimal numbers only: no hexadecimal, no infinity, no NaN.
  EXPECT_THROW(Domain<2>::Parse("rectangle 0 0 0x10 1"), InputError);
  EXPECT_THROW(Domain<2>::Parse("rectangle 0 0 0x1p3 1"), InputError);
  EXPECT_THROW(Domain<3>::Parse("cylinder 0 0 inf 0 1"), InputError);
  EXPECT_THROW(Domain<3>::Parse("box 0 0 0 1 nan 1"), InputError);
  EXPECT_NO_THROW(Domain<2>::Parse("rectangle -1.5e-3 0 +2E-3 1."));
  EXPECT_THROW(Domain<2>::Parse("polygon -1 0 0"), InputError);
  EXPECT_THROW(Domain<2>::Parse("polygon 2.5 0 0 1 0 1 1"), InputError);
}

TEST(Domain, SimplePolygonCheck) {
  EXPECT_TRUE(IsSimplePolygon({{0, 0}, {1, 0}, {1, 1}, {0, 1}}));
  EXPECT_FALSE(IsSimplePolygon({{0, 0}, {1, 1}, {1, 0}, {0, 1}}));
  EXPECT_FALSE(IsSimplePolygon({{0, 0}, {2, 0}, {1, 0}, {1, 1}}));  // folds back on itself
  EXPECT_FALSE(IsSimplePolygon({{0, 0}, {1, 0}, {2, 0}}));          // zero area
}

}  // namespace
}  // namespace specimen
