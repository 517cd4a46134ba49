#include "generator/densify.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace specimen {
namespace {

// Central finite differences of a scalar residual of one (Dim + 1) block.
template <typename F>
void FiniteDifference(F&& residual, double* block, int size, double* gradient) {
  for (int k = 0; k < size; ++k) {
    const double saved = block[k];
    const double h = 1e-6 * std::max(1.0, std::abs(saved));
    block[k] = saved + h;
    const double plus = residual();
    block[k] = saved - h;
    const double minus = residual();
    block[k] = saved;
    gradient[k] = (plus - minus) / (2 * h);
  }
}

template <int Dim>
void CheckEdgeJacobian(double overlap_weight, bool one_sided, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  double a[Dim + 1], b[Dim + 1];
  for (int k = 0; k < Dim; ++k) a[k] = u(rng), b[k] = u(rng);
  a[Dim] = 0.5 + 0.3 * u(rng);
  b[Dim] = 0.5 + 0.3 * u(rng);
  double ja[Dim + 1], jb[Dim + 1], fa[Dim + 1], fb[Dim + 1];
  EdgeResidual<Dim>(a, b, 0.7, overlap_weight, one_sided, ja, jb);
  auto f = [&] { return EdgeResidual<Dim>(a, b, 0.7, overlap_weight, one_sided, nullptr, nullptr); };
  FiniteDifference(f, a, Dim + 1, fa);
  FiniteDifference(f, b, Dim + 1, fb);
  for (int k = 0; k <= Dim; ++k) {
    EXPECT_NEAR(ja[k], fa[k], 1e-6 * (1 + std::abs(fa[k])));
    EXPECT_NEAR(jb[k], fb[k], 1e-6 * (1 + std::abs(fb[k])));
  }
}

TEST(LevenbergMarquardtResiduals, EdgeMatchesLabra31) {
  // Two discs 3 apart with radii 1 and 1.5: d = 3^2 - 2.5^2 = 2.75, scaled by 1/L^2.
  const double a[3] = {0, 0, 1.0}, b[3] = {3, 0, 1.5};
  EXPECT_DOUBLE_EQ(EdgeResidual<2>(a, b, 1.0, 1.0, false, nullptr, nullptr), 2.75);
  EXPECT_DOUBLE_EQ(EdgeResidual<2>(a, b, 2.0, 1.0, false, nullptr, nullptr), 2.75 / 4);
  // One-sided: a gap gives no residual, an overlap does (weighted).
  EXPECT_DOUBLE_EQ(EdgeResidual<2>(a, b, 1.0, 1.0, true, nullptr, nullptr), 0.0);
  const double c[3] = {2, 0, 1.5};
  EXPECT_DOUBLE_EQ(EdgeResidual<2>(a, c, 1.0, 3.0, true, nullptr, nullptr), 3.0 * (4 - 6.25));
}

TEST(LevenbergMarquardtResiduals, EdgeJacobianMatchesFiniteDifferences) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    CheckEdgeJacobian<2>(1.0, false, seed);
    CheckEdgeJacobian<3>(1.0, false, seed);
    CheckEdgeJacobian<2>(10.0, true, seed);
    CheckEdgeJacobian<3>(10.0, true, seed);
  }
}

// The band residual (contact band): zero anywhere in [-band_overlap, band_gap], the excess
// beyond either end otherwise (overlaps weighted), and nothing pulls a one-sided pair.
TEST(LevenbergMarquardtResiduals, BandEdgeIsZeroInsideTheBandAndTheExcessOutside) {
  const double a[3] = {0, 0, 1.0};
  auto at = [&](double gap, double length_scale, double weight, bool one_sided) {
    const double b[3] = {2.5 + gap, 0, 1.5};
    return BandEdgeResidual<2>(a, b, length_scale, 0.02, 0.03, weight, one_sided, nullptr, nullptr);
  };
  for (double gap : {-0.0199, -0.01, 0.0, 0.015, 0.0299}) EXPECT_DOUBLE_EQ(at(gap, 1.0, 4.0, false), 0.0);
  EXPECT_NEAR(at(0.1, 1.0, 4.0, false), 0.07, 1e-12);
  EXPECT_NEAR(at(0.1, 2.0, 4.0, false), 0.035, 1e-12);
  EXPECT_DOUBLE_EQ(at(0.1, 1.0, 4.0, true), 0.0);
  EXPECT_NEAR(at(-0.05, 1.0, 4.0, false), 4.0 * -0.03, 1e-12);
  EXPECT_NEAR(at(-0.05, 1.0, 4.0, true), 4.0 * -0.03, 1e-12);
}

TEST(LevenbergMarquardtResiduals, BandEdgeJacobianMatchesFiniteDifferences) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  int outside = 0;
  for (int trial = 0; trial < 60; ++trial) {
    double a[4], b[4];
    for (int k = 0; k < 3; ++k) a[k] = u(rng), b[k] = u(rng);
    a[3] = 0.5 + 0.3 * u(rng);
    b[3] = 0.5 + 0.3 * u(rng);
    const double gap = std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                                 (a[2] - b[2]) * (a[2] - b[2])) - a[3] - b[3];
    // Away from the kinks at the band ends, where the residual is not differentiable.
    if (std::abs(gap + 0.05) < 1e-3 || std::abs(gap - 0.1) < 1e-3) continue;
    if (gap < -0.05 || gap > 0.1) ++outside;
    const bool one_sided = trial % 3 == 0;
    auto f = [&] { return BandEdgeResidual<3>(a, b, 0.7, 0.05, 0.1, 4.0, one_sided, nullptr, nullptr); };
    double ja[4], jb[4], fa[4], fb[4];
    BandEdgeResidual<3>(a, b, 0.7, 0.05, 0.1, 4.0, one_sided, ja, jb);
    FiniteDifference(f, a, 4, fa);
    FiniteDifference(f, b, 4, fb);
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(ja[k], fa[k], 1e-6 * (1 + std::abs(fa[k])));
      EXPECT_NEAR(jb[k], fb[k], 1e-6 * (1 + std::abs(fb[k])));
    }
  }
  EXPECT_GT(outside, 20);  // the draws exercise the non-zero branches
}

// A band solve is an inequality: a pair open by 10 % of a radius is pulled to the band's
// edge, not to exact contact, and a pair already inside is left where it is.
TEST(LevenbergMarquardt, BandPullsAPairToTheBandNotToContact) {
  const auto domain = Domain<2>::Rectangle(0, 0, 20, 20);
  std::vector<Vector<2>> x = {{8.0, 10.0}, {10.1, 10.0}, {10.0, 14.0}, {12.01, 14.0}};
  std::vector<double> r = {1.0, 1.0, 1.0, 1.0};
  ContactGraph<2> graph;
  graph.edges = {{0, 1}, {2, 3}};
  LevenbergMarquardtOptions options;
  options.radius_min = 0.5;
  options.radius_max = 2.0;
  options.length_scale = 1.0;
  options.position_anchor_weight = 1e-4;
  options.max_iterations = 100;
  options.band_overlap = 0.02;
  options.band_gap = 0.03;
  const auto summary = SolveLevenbergMarquardt<2>(domain, graph, options, x, r);
  const double open_gap = (x[1] - x[0]).norm() - r[0] - r[1];
  EXPECT_LE(open_gap, 0.03 + 1e-4) << summary.termination;
  EXPECT_GT(open_gap, 0.02);  // stopped at the band, not pulled on to exact contact
  EXPECT_NEAR((x[3] - x[2]).norm() - r[2] - r[3], 0.01, 1e-9);  // inside: untouched
}

TEST(LevenbergMarquardtResiduals, BoundaryResidualAndJacobian) {
  const auto disc = Domain<2>::Disc(Vector<2>(0, 0), 5.0);
  const auto cylinder = Domain<3>::Cylinder(0, 0, 5.0, 0, 10);
  // Labra (3.8): inside, b = s^2 - r^2.
  double p[3] = {3.0, 0.0, 1.0};
  EXPECT_DOUBLE_EQ(BoundaryResidual<2>(disc, disc.Facets()[0], p, 1.0, 1.0, false, nullptr), 3.0);
  // Outside (s = -1): s|s| - r^2 = -2, still pulling back.
  double q[3] = {6.0, 0.0, 1.0};
  EXPECT_DOUBLE_EQ(BoundaryResidual<2>(disc, disc.Facets()[0], q, 1.0, 1.0, false, nullptr), -2.0);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int trial = 0; trial < 20; ++trial) {
    double x2[3] = {u(rng), u(rng), 0.8};
    double j[3], fd[3];
    BoundaryResidual<2>(disc, disc.Facets()[0], x2, 0.9, 2.0, false, j);
    FiniteDifference(
        [&] { return BoundaryResidual<2>(disc, disc.Facets()[0], x2, 0.9, 2.0, false, nullptr); },
        x2, 3, fd);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(j[k], fd[k], 1e-6 * (1 + std::abs(fd[k])));
    for (const auto& facet : cylinder.Facets()) {
      double x3[4] = {u(rng), u(rng), 5 + u(rng), 0.8};
      double j3[4], fd3[4];
      BoundaryResidual<3>(cylinder, facet, x3, 1.1, 1.0, false, j3);
      FiniteDifference(
          [&] { return BoundaryResidual<3>(cylinder, facet, x3, 1.1, 1.0, false, nullptr); }, x3,
          4, fd3);
      for (int k = 0; k < 4; ++k) EXPECT_NEAR(j3[k], fd3[k], 1e-6 * (1 + std::abs(fd3[k])));
    }
  }
}

TEST(LevenbergMarquardt, ThreeDiscsInACornerBecomeTangent) {
  // Three discs in the corner of a box, tied to each other and to the walls they face:
  // the solver must make every constraint exact.
  const auto domain = Domain<2>::Rectangle(0, 0, 10, 10);
  std::vector<Vector<2>> x = {{1.2, 1.1}, {3.1, 0.9}, {1.0, 3.2}};
  std::vector<double> r = {0.8, 1.1, 0.9};
  ContactGraph<2> graph;
  graph.edges = {{0, 1}, {0, 2}};
  graph.boundary_ties = {{0, 0}, {0, 3}, {1, 0}, {2, 3}};
  LevenbergMarquardtOptions options;
  options.radius_min = 0.5;
  options.radius_max = 2.0;
  options.length_scale = 1.0;
  options.position_anchor_weight = 1e-4;
  options.max_iterations = 200;
  const auto summary = SolveLevenbergMarquardt<2>(domain, graph, options, x, r);
  EXPECT_LT(summary.final_cost, summary.initial_cost * 1e-6) << summary.termination;
  auto gap = [&](int i, int j) { return (x[i] - x[j]).norm() - r[i] - r[j]; };
  EXPECT_NEAR(gap(0, 1), 0.0, 1e-6);
  EXPECT_NEAR(gap(0, 2), 0.0, 1e-6);
  EXPECT_NEAR(x[0].y(), r[0], 1e-6);
  EXPECT_NEAR(x[0].x(), r[0], 1e-6);
  EXPECT_NEAR(x[1].y(), r[1], 1e-6);
  EXPECT_NEAR(x[2].x(), r[2], 1e-6);
}

}  // namespace
}  // namespace specimen
