#pragma once
// A smooth fit of one map output (a dimensionless group) over its inputs (micro ratios):
// a polynomial of bounded total degree in inputs scaled to [-1, 1], fitted by linear
// least squares. The fit error is measured, not assumed: the RMS and largest residual on
// the sweep points and the leave-one-out (PRESS) error from the hat matrix, which is what
// the calibrator reports as the map's fit error.

#include <Eigen/Core>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace specimen {

struct ResponseSurfaceOptions {
  int max_total_degree = 3;  // >= 0
  // Tikhonov term on the coefficients of the scaled basis (per point); 0 = plain
  // least squares. Keeps sparse sweeps from producing wild high-order terms.
  double ridge = 1e-10;
  // Fit ln(value) instead of the value (positive outputs whose inputs act as factors, such as
  // the strength groups: their leave-one-out error on the default rigid sweep halves, 24 % ->
  // 13 % for Psi_c, 30 % -> 17 % for Psi_t). Evaluate returns exp of the polynomial.
  bool log_values = false;
};

class ResponseSurface {
 public:
  ResponseSurface() = default;

  // points: one row per sweep point (inputs); values: the output at each point. Needs more
  // points than terms; throws InputError otherwise, naming the counts.
  static ResponseSurface Fit(const Eigen::MatrixXd& points, const Eigen::VectorXd& values,
                             const ResponseSurfaceOptions& options = ResponseSurfaceOptions());

  double Evaluate(const Eigen::VectorXd& input) const;
  // Gradient with respect to the (unscaled) inputs.
  Eigen::VectorXd Gradient(const Eigen::VectorXd& input) const;
  int inputs() const { return static_cast<int>(lower_.size()); }
  // Whether `input` lies inside the box of the sweep (with a relative tolerance).
  bool InDomain(const Eigen::VectorXd& input, double tolerance = 1e-9) const;
  const Eigen::VectorXd& lower() const { return lower_; }
  const Eigen::VectorXd& upper() const { return upper_; }

  bool log_values() const { return log_values_; }
  // Fit quality on the sweep points, in the units of the values (also for a log fit).
  double rms_residual() const { return rms_residual_; }
  double max_residual() const { return max_residual_; }
  double leave_one_out_rms() const { return leave_one_out_rms_; }

  nlohmann::json ToJson() const;
  static ResponseSurface FromJson(const nlohmann::json& j);

 private:
  Eigen::VectorXd Scale(const Eigen::VectorXd& input) const;
  Eigen::VectorXd Basis(const Eigen::VectorXd& scaled) const;

  std::vector<std::vector<int>> exponents_;  // one multi-index per term
  Eigen::VectorXd coefficients_;
  Eigen::VectorXd lower_, upper_;
  double rms_residual_ = 0.0, max_residual_ = 0.0, leave_one_out_rms_ = 0.0;
  bool log_values_ = false;
};

}  // namespace specimen
