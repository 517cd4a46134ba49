#include "calibrate/response_surface.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <random>

#include "common/error.h"

namespace specimen {
namespace {

// A quadratic in two inputs is reproduced exactly by a degree-2 surface.
TEST(ResponseSurface, ReproducesAPolynomialExactly) {
  auto f = [](double a, double b) { return 1.0 + 2.0 * a - 0.5 * b + 0.3 * a * b + 0.7 * a * a; };
  Eigen::MatrixXd points(25, 2);
  Eigen::VectorXd values(25);
  int k = 0;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j, ++k) {
      points(k, 0) = 0.25 * i;        // kt/kn in [0, 1]
      points(k, 1) = 1.0 + 2.25 * j;  // Rt/Rn in [1, 10]
      values[k] = f(points(k, 0), points(k, 1));
    }
  ResponseSurfaceOptions options;
  options.max_total_degree = 2;
  options.ridge = 0.0;
  const auto s = ResponseSurface::Fit(points, values, options);
  EXPECT_LT(s.max_residual(), 1e-10);
  EXPECT_LT(s.leave_one_out_rms(), 1e-9);
  Eigen::VectorXd x(2);
  x << 0.37, 6.1;
  EXPECT_NEAR(s.Evaluate(x), f(0.37, 6.1), 1e-10);
  // Gradient against the analytic one.
  EXPECT_NEAR(s.Gradient(x)[0], 2.0 + 0.3 * 6.1 + 1.4 * 0.37, 1e-9);
  EXPECT_NEAR(s.Gradient(x)[1], -0.5 + 0.3 * 0.37, 1e-9);
  EXPECT_TRUE(s.InDomain(x));
  x << 1.2, 6.1;
  EXPECT_FALSE(s.InDomain(x));
}

// A logarithmic fit (ResponseSurfaceOptions::log_values) reproduces exp of a quadratic
// exactly, with its gradient, survives JSON, and refuses non-positive values.
TEST(ResponseSurface, LogarithmicFitReproducesAnExponentialOfAPolynomial) {
  auto g = [](double a, double b) { return 0.2 + 1.5 * a + 0.1 * b - 0.4 * a * a + 0.05 * a * b; };
  Eigen::MatrixXd points(16, 2);
  Eigen::VectorXd values(16);
  int k = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j, ++k) {
      points(k, 0) = 0.15 + 0.25 * i;
      points(k, 1) = 2.0 + 8.0 * j / 3.0;
      values[k] = std::exp(g(points(k, 0), points(k, 1)));
    }
  ResponseSurfaceOptions options;
  options.max_total_degree = 2;
  options.ridge = 0.0;
  options.log_values = true;
  const auto s = ResponseSurface::Fit(points, values, options);
  EXPECT_TRUE(s.log_values());
  EXPECT_LT(s.max_residual(), 1e-9);
  Eigen::VectorXd x(2);
  x << 0.5, 7.3;
  const double v = std::exp(g(0.5, 7.3));
  EXPECT_NEAR(s.Evaluate(x), v, 1e-9 * v);
  EXPECT_NEAR(s.Gradient(x)[0], v * (1.5 - 0.8 * 0.5 + 0.05 * 7.3), 1e-8 * v);
  EXPECT_NEAR(s.Gradient(x)[1], v * (0.1 + 0.05 * 0.5), 1e-8 * v);
  const auto back = ResponseSurface::FromJson(s.ToJson());
  EXPECT_TRUE(back.log_values());
  EXPECT_DOUBLE_EQ(back.Evaluate(x), s.Evaluate(x));
  values[3] = 0.0;
  EXPECT_THROW(ResponseSurface::Fit(points, values, options), InputError);
}

// With noise, the leave-one-out error estimates the true prediction error, and round trip
// through JSON preserves every prediction.
TEST(ResponseSurface, NoisyDataAndJsonRoundTrip) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::MatrixXd points(60, 3);
  Eigen::VectorXd values(60);
  auto f = [](const Eigen::VectorXd& p) { return std::exp(-p[0]) + 0.5 * p[1] * p[2]; };
  for (int i = 0; i < 60; ++i) {
    points.row(i) << u(rng), u(rng), u(rng);
    values[i] = f(points.row(i).transpose()) + noise(rng);
  }
  const auto s = ResponseSurface::Fit(points, values);
  EXPECT_GT(s.leave_one_out_rms(), s.rms_residual());
  EXPECT_LT(s.leave_one_out_rms(), 0.03);
  const auto back = ResponseSurface::FromJson(nlohmann::json::parse(s.ToJson().dump()));
  Eigen::VectorXd x(3);
  x << 0.4, 0.2, 0.9;
  EXPECT_DOUBLE_EQ(back.Evaluate(x), s.Evaluate(x));
  EXPECT_NEAR(s.Evaluate(x), f(x), 0.03);
}

TEST(ResponseSurface, TooFewPointsAreRefused) {
  Eigen::MatrixXd points(4, 2);
  points << 0, 0, 1, 0, 0, 1, 1, 1;
  Eigen::VectorXd values(4);
  values << 1, 2, 3, 4;
  try {
    ResponseSurface::Fit(points, values);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("4 sweep points"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ResponseSurface::FromJson(nlohmann::json::parse("{\"exponents\": []}")), std::exception);
}

}  // namespace
}  // namespace specimen
