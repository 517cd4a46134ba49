#include "calibrate/response_surface.h"

#include <Eigen/Dense>
#include <cmath>
#include <functional>

#include <nlohmann/json.hpp>

#include "common/error.h"
#include "common/format.h"

namespace specimen {
namespace {

// All multi-indices of `inputs` variables with total degree <= degree, graded order.
std::vector<std::vector<int>> MultiIndices(int inputs, int degree) {
  std::vector<std::vector<int>> result;
  std::vector<int> current(inputs, 0);
  std::function<void(int, int)> recurse = [&](int variable, int remaining) {
    if (variable == inputs) {
      result.push_back(current);
      return;
    }
    for (int power = 0; power <= remaining; ++power) {
      current[variable] = power;
      recurse(variable + 1, remaining - power);
    }
    current[variable] = 0;
  };
  recurse(0, degree);
  return result;
}

}  // namespace

Eigen::VectorXd ResponseSurface::Scale(const Eigen::VectorXd& input) const {
  Eigen::VectorXd scaled(input.size());
  for (int k = 0; k < input.size(); ++k) {
    const double span = upper_[k] - lower_[k];
    scaled[k] = span > 0.0 ? 2.0 * (input[k] - lower_[k]) / span - 1.0 : 0.0;
  }
  return scaled;
}

Eigen::VectorXd ResponseSurface::Basis(const Eigen::VectorXd& s) const {
  Eigen::VectorXd basis(exponents_.size());
  for (size_t t = 0; t < exponents_.size(); ++t) {
    double value = 1.0;
    for (int k = 0; k < s.size(); ++k) value *= std::pow(s[k], exponents_[t][k]);
    basis[t] = value;
  }
  return basis;
}

ResponseSurface ResponseSurface::Fit(const Eigen::MatrixXd& points, const Eigen::VectorXd& values,
                                     const ResponseSurfaceOptions& options) {
  if (options.max_total_degree < 0) throw InputError("max_total_degree must be >= 0");
  if (points.rows() != values.size())
    throw InputError("response surface: " + std::to_string(points.rows()) + " points but " +
                     std::to_string(values.size()) + " values");
  if (points.rows() == 0 || points.cols() == 0)
    throw InputError("response surface: no points to fit (" + std::to_string(points.rows()) + " points, " +
                     std::to_string(points.cols()) + " inputs)");
  ResponseSurface s;
  s.log_values_ = options.log_values;
  if (options.log_values && !(values.minCoeff() > 0.0))
    throw InputError("response surface: a logarithmic fit needs positive values (smallest " +
                     Number(values.minCoeff()) + ")");
  const Eigen::VectorXd fitted_values = options.log_values ? Eigen::VectorXd(values.array().log()) : values;
  const int inputs = static_cast<int>(points.cols());
  s.lower_ = points.colwise().minCoeff().transpose();
  s.upper_ = points.colwise().maxCoeff().transpose();
  // Inputs that do not vary carry no information: no powers of them.
  std::vector<std::vector<int>> all = MultiIndices(inputs, options.max_total_degree);
  for (const auto& e : all) {
    bool usable = true;
    for (int k = 0; k < inputs; ++k)
      if (e[k] > 0 && !(s.upper_[k] > s.lower_[k])) usable = false;
    if (usable) s.exponents_.push_back(e);
  }
  const int terms = static_cast<int>(s.exponents_.size());
  if (points.rows() <= terms)
    throw InputError("response surface: " + std::to_string(points.rows()) +
                     " sweep points for " + std::to_string(terms) +
                     " polynomial terms; more points or a lower degree are needed");
  Eigen::MatrixXd a(points.rows(), terms);
  for (int i = 0; i < points.rows(); ++i) a.row(i) = s.Basis(s.Scale(points.row(i).transpose())).transpose();
  Eigen::MatrixXd normal = a.transpose() * a;
  normal.diagonal().array() += options.ridge * points.rows();
  const Eigen::LDLT<Eigen::MatrixXd> solver(normal);
  s.coefficients_ = solver.solve(a.transpose() * fitted_values);
  const Eigen::VectorXd residual = a * s.coefficients_ - fitted_values;
  // In the units of the values: a log fit's prediction is exp of the polynomial.
  auto value_of = [&](int i, double fitted_residual) {
    const double predicted = fitted_values[i] + fitted_residual;
    return (options.log_values ? std::exp(predicted) : predicted) - values[i];
  };
  double sum = 0.0, press = 0.0;
  for (int i = 0; i < a.rows(); ++i) {
    const double r = value_of(i, residual[i]);
    sum += r * r;
    s.max_residual_ = std::max(s.max_residual_, std::abs(r));
    // PRESS: the leave-one-out residual of point i is r_i / (1 - h_ii), h = A (A^T A)^-1 A^T.
    const double leverage = a.row(i).dot(solver.solve(a.row(i).transpose()));
    const double denominator = std::max(1.0 - leverage, 1e-12);
    press += std::pow(value_of(i, residual[i] / denominator), 2);
  }
  s.rms_residual_ = std::sqrt(sum / values.size());
  s.leave_one_out_rms_ = std::sqrt(press / values.size());
  return s;
}

double ResponseSurface::Evaluate(const Eigen::VectorXd& input) const {
  const double polynomial = Basis(Scale(input)).dot(coefficients_);
  return log_values_ ? std::exp(polynomial) : polynomial;
}

Eigen::VectorXd ResponseSurface::Gradient(const Eigen::VectorXd& input) const {
  const Eigen::VectorXd s = Scale(input);
  Eigen::VectorXd gradient = Eigen::VectorXd::Zero(input.size());
  for (size_t t = 0; t < exponents_.size(); ++t) {
    for (int k = 0; k < s.size(); ++k) {
      if (exponents_[t][k] == 0) continue;
      double term = coefficients_[t] * exponents_[t][k] * std::pow(s[k], exponents_[t][k] - 1);
      for (int m = 0; m < s.size(); ++m)
        if (m != k) term *= std::pow(s[m], exponents_[t][m]);
      gradient[k] += term * 2.0 / (upper_[k] - lower_[k]);
    }
  }
  return log_values_ ? Eigen::VectorXd(gradient * Evaluate(input)) : gradient;
}

bool ResponseSurface::InDomain(const Eigen::VectorXd& input, double tolerance) const {
  for (int k = 0; k < input.size(); ++k) {
    const double slack = tolerance * std::max(1.0, upper_[k] - lower_[k]);
    if (input[k] < lower_[k] - slack || input[k] > upper_[k] + slack) return false;
  }
  return true;
}

nlohmann::json ResponseSurface::ToJson() const {
  nlohmann::json j;
  j["exponents"] = exponents_;
  j["coefficients"] = std::vector<double>(coefficients_.data(), coefficients_.data() + coefficients_.size());
  j["lower"] = std::vector<double>(lower_.data(), lower_.data() + lower_.size());
  j["upper"] = std::vector<double>(upper_.data(), upper_.data() + upper_.size());
  j["rms_residual"] = rms_residual_;
  j["max_residual"] = max_residual_;
  j["leave_one_out_rms"] = leave_one_out_rms_;
  j["log_values"] = log_values_;
  return j;
}

ResponseSurface ResponseSurface::FromJson(const nlohmann::json& j) {
  ResponseSurface s;
  try {
    s.exponents_ = j.at("exponents").get<std::vector<std::vector<int>>>();
    const auto c = j.at("coefficients").get<std::vector<double>>();
    const auto lo = j.at("lower").get<std::vector<double>>();
    const auto hi = j.at("upper").get<std::vector<double>>();
    s.coefficients_ = Eigen::Map<const Eigen::VectorXd>(c.data(), c.size());
    s.lower_ = Eigen::Map<const Eigen::VectorXd>(lo.data(), lo.size());
    s.upper_ = Eigen::Map<const Eigen::VectorXd>(hi.data(), hi.size());
    s.rms_residual_ = j.at("rms_residual").get<double>();
    s.max_residual_ = j.at("max_residual").get<double>();
    s.leave_one_out_rms_ = j.at("leave_one_out_rms").get<double>();
    s.log_values_ = j.value("log_values", false);
  } catch (const nlohmann::json::exception& e) {
    throw FileError(std::string("response surface: ") + e.what());
  }
  if (s.coefficients_.size() != static_cast<Eigen::Index>(s.exponents_.size()) ||
      s.lower_.size() != s.upper_.size())
    throw FileError("response surface: inconsistent sizes");
  for (const auto& e : s.exponents_)
    if (static_cast<Eigen::Index>(e.size()) != s.lower_.size())
      throw FileError("response surface: an exponent list does not match the number of inputs");
  return s;
}

}  // namespace specimen
