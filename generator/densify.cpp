#include "generator/densify.h"

#include <ceres/ceres.h>

#include <chrono>
#include <algorithm>
#include <cmath>

namespace specimen {

template <int Dim>
double EdgeResidual(const double* a, const double* b, double length_scale, double overlap_weight,
                    bool one_sided, double* jacobian_a, double* jacobian_b) {
  double distance_squared = 0.0;
  for (int k = 0; k < Dim; ++k) distance_squared += (a[k] - b[k]) * (a[k] - b[k]);
  const double radius_sum = a[Dim] + b[Dim];
  const double raw = distance_squared - radius_sum * radius_sum;  // Labra (3.1)
  const double scale = (raw < 0.0 ? overlap_weight : (one_sided ? 0.0 : 1.0)) /
                       (length_scale * length_scale);
  if (jacobian_a != nullptr || jacobian_b != nullptr) {
    for (int k = 0; k < Dim; ++k) {
      const double g = 2.0 * (a[k] - b[k]) * scale;
      if (jacobian_a) jacobian_a[k] = g;
      if (jacobian_b) jacobian_b[k] = -g;
    }
    const double g_radius = -2.0 * radius_sum * scale;
    if (jacobian_a) jacobian_a[Dim] = g_radius;
    if (jacobian_b) jacobian_b[Dim] = g_radius;
  }
  return raw * scale;
}

template <int Dim>
double BandEdgeResidual(const double* a, const double* b, double length_scale, double band_overlap,
                        double band_gap, double overlap_weight, bool one_sided, double* jacobian_a,
                        double* jacobian_b) {
  double distance_squared = 0.0;
  for (int k = 0; k < Dim; ++k) distance_squared += (a[k] - b[k]) * (a[k] - b[k]);
  const double distance = std::sqrt(distance_squared);
  const double gap = distance - a[Dim] - b[Dim];
  // Excess outside the band, weighted as the squared form weights overlaps.
  double excess = 0.0, weight = 0.0;
  if (gap < -band_overlap) {
    excess = gap + band_overlap;
    weight = overlap_weight;
  } else if (gap > band_gap && !one_sided) {
    excess = gap - band_gap;
    weight = 1.0;
  }
  const double scale = weight / length_scale;
  if (jacobian_a != nullptr || jacobian_b != nullptr) {
    // d gap / d x_a = (x_a - x_b) / |x_a - x_b|, d gap / d r = -1.
    const double inverse = distance > 0.0 ? scale / distance : 0.0;
    for (int k = 0; k < Dim; ++k) {
      const double g = (a[k] - b[k]) * inverse;
      if (jacobian_a) jacobian_a[k] = g;
      if (jacobian_b) jacobian_b[k] = -g;
    }
    if (jacobian_a) jacobian_a[Dim] = -scale;
    if (jacobian_b) jacobian_b[Dim] = -scale;
  }
  return excess * scale;
}

template <int Dim>
double BoundaryResidual(const Domain<Dim>& domain, const BoundaryFacet<Dim>& facet,
                        const double* particle, double length_scale, double protrusion_weight,
                        bool one_sided, double* jacobian) {
  const Eigen::Map<const Vector<Dim>> x(particle);
  const double s = domain.FacetDistance(facet, x);
  const double r = particle[Dim];
  const double raw = s * std::abs(s) - r * r;  // Labra (3.8), signed form
  const double scale = (raw < 0.0 ? protrusion_weight : (one_sided ? 0.0 : 1.0)) /
                       (length_scale * length_scale);
  if (jacobian != nullptr) {
    const Vector<Dim> gradient = domain.FacetDistanceGradient(facet, x);
    for (int k = 0; k < Dim; ++k) jacobian[k] = 2.0 * std::abs(s) * gradient[k] * scale;
    jacobian[Dim] = -2.0 * r * scale;
  }
  return raw * scale;
}

namespace {

template <int Dim>
class EdgeCost final : public ceres::SizedCostFunction<1, Dim + 1, Dim + 1> {
 public:
  EdgeCost(double length_scale, double overlap_weight, bool one_sided)
      : length_scale_(length_scale), overlap_weight_(overlap_weight), one_sided_(one_sided) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    residuals[0] = EdgeResidual<Dim>(parameters[0], parameters[1], length_scale_, overlap_weight_,
                                     one_sided_, jacobians ? jacobians[0] : nullptr,
                                     jacobians ? jacobians[1] : nullptr);
    return true;
  }

 private:
  double length_scale_;
  double overlap_weight_;
  bool one_sided_;
};

template <int Dim>
class BandEdgeCost final : public ceres::SizedCostFunction<1, Dim + 1, Dim + 1> {
 public:
  BandEdgeCost(const LevenbergMarquardtOptions& options, bool one_sided)
      : length_scale_(options.length_scale),
        band_overlap_(options.band_overlap),
        band_gap_(options.band_gap),
        overlap_weight_(options.overlap_weight),
        one_sided_(one_sided) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    residuals[0] = BandEdgeResidual<Dim>(parameters[0], parameters[1], length_scale_,
                                         band_overlap_, band_gap_, overlap_weight_, one_sided_,
                                         jacobians ? jacobians[0] : nullptr,
                                         jacobians ? jacobians[1] : nullptr);
    return true;
  }

 private:
  double length_scale_;
  double band_overlap_;
  double band_gap_;
  double overlap_weight_;
  bool one_sided_;
};

template <int Dim>
class BoundaryCost final : public ceres::SizedCostFunction<1, Dim + 1> {
 public:
  BoundaryCost(const Domain<Dim>& domain, const BoundaryFacet<Dim>& facet, double length_scale,
               double protrusion_weight, bool one_sided)
      : domain_(domain),
        facet_(facet),
        length_scale_(length_scale),
        protrusion_weight_(protrusion_weight),
        one_sided_(one_sided) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    residuals[0] = BoundaryResidual<Dim>(domain_, facet_, parameters[0], length_scale_,
                                         protrusion_weight_, one_sided_,
                                         jacobians ? jacobians[0] : nullptr);
    return true;
  }

 private:
  const Domain<Dim>& domain_;
  const BoundaryFacet<Dim>& facet_;
  double length_scale_;
  double protrusion_weight_;
  bool one_sided_;
};

// Proximal term: x_i pulled towards its position at the start of the solve.
template <int Dim>
class PositionAnchorCost final : public ceres::SizedCostFunction<Dim, Dim + 1> {
 public:
  PositionAnchorCost(const double* anchor, double weight) : weight_(weight) {
    for (int k = 0; k < Dim; ++k) anchor_[k] = anchor[k];
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    for (int k = 0; k < Dim; ++k) residuals[k] = weight_ * (parameters[0][k] - anchor_[k]);
    if (jacobians && jacobians[0]) {
      for (int k = 0; k < Dim * (Dim + 1); ++k) jacobians[0][k] = 0.0;
      for (int k = 0; k < Dim; ++k) jacobians[0][k * (Dim + 1) + k] = weight_;
    }
    return true;
  }

 private:
  double anchor_[Dim];
  double weight_;
};

// Ends the solve successfully once the cost is below a threshold.
class StopBelowCost final : public ceres::IterationCallback {
 public:
  explicit StopBelowCost(double threshold) : threshold_(threshold) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    return summary.cost < threshold_ ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
  }

 private:
  double threshold_;
};

// Hands the state to LevenbergMarquardtOptions::on_iteration after each iteration.
class ReportIteration final : public ceres::IterationCallback {
 public:
  ReportIteration(const std::function<void(int, const std::vector<double>&)>& report,
                  const std::vector<double>& blocks)
      : report_(report), blocks_(blocks) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    report_(summary.iteration, blocks_);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  const std::function<void(int, const std::vector<double>&)>& report_;
  const std::vector<double>& blocks_;
};

}  // namespace

template <int Dim>
LevenbergMarquardtSummary SolveLevenbergMarquardt(const Domain<Dim>& domain,
                                                  const ContactGraph<Dim>& graph,
                                                  const LevenbergMarquardtOptions& options,
                                                  std::vector<Vector<Dim>>& centres,
                                                  std::vector<double>& radii) {
  const auto start = std::chrono::steady_clock::now();
  const int n = static_cast<int>(radii.size());
  // Parameter blocks [x, (y, z,) r] per particle, contiguous.
  std::vector<double> parameters(static_cast<size_t>(n) * (Dim + 1));
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < Dim; ++k) parameters[i * (Dim + 1) + k] = centres[i][k];
    parameters[i * (Dim + 1) + Dim] = radii[i];
  }

  ceres::Problem::Options problem_options;
  problem_options.enable_fast_removal = false;
  ceres::Problem problem(problem_options);
  const bool local = !options.free_particles.empty();
  auto is_free = [&](int i) { return !local || options.free_particles[i] != 0; };
  std::vector<char> in_problem(n, 0);
  for (int i = 0; i < n; ++i) {
    if (!is_free(i)) continue;
    problem.AddParameterBlock(&parameters[i * (Dim + 1)], Dim + 1);
    in_problem[i] = 1;
  }
  auto hold = [&](int i) {
    if (in_problem[i]) return;
    problem.AddParameterBlock(&parameters[i * (Dim + 1)], Dim + 1);
    problem.SetParameterBlockConstant(&parameters[i * (Dim + 1)]);
    in_problem[i] = 2;
  };
  const bool banded = options.band_gap > 0.0;  // the residual form, chosen once per solve
  for (size_t k = 0; k < graph.edges.size(); ++k) {
    const auto& e = graph.edges[k];
    if (!is_free(e[0]) && !is_free(e[1])) continue;
    hold(e[0]);
    hold(e[1]);
    const bool one_sided = !options.edge_one_sided.empty() && options.edge_one_sided[k];
    ceres::CostFunction* cost =
        banded ? static_cast<ceres::CostFunction*>(new BandEdgeCost<Dim>(options, one_sided))
               : new EdgeCost<Dim>(options.length_scale, options.overlap_weight, one_sided);
    problem.AddResidualBlock(cost, nullptr, &parameters[e[0] * (Dim + 1)],
                             &parameters[e[1] * (Dim + 1)]);
  }
  for (size_t k = 0; k < graph.boundary_ties.size(); ++k) {
    const auto& tie = graph.boundary_ties[k];
    if (!is_free(tie.first)) continue;
    const bool one_sided = !options.tie_one_sided.empty() && options.tie_one_sided[k];
    problem.AddResidualBlock(
        new BoundaryCost<Dim>(domain, domain.Facets()[tie.second], options.length_scale,
                              options.protrusion_weight, one_sided),
        nullptr, &parameters[tie.first * (Dim + 1)]);
  }
  if (options.position_anchor_weight > 0.0) {
    const double weight = options.position_anchor_weight / options.length_scale;
    for (int i = 0; i < n; ++i)
      if (is_free(i))
        problem.AddResidualBlock(new PositionAnchorCost<Dim>(&parameters[i * (Dim + 1)], weight),
                                 nullptr, &parameters[i * (Dim + 1)]);
  }
  for (int i = 0; i < n; ++i) {
    if (in_problem[i] != 1) continue;
    double* block = &parameters[i * (Dim + 1)];
    problem.SetParameterLowerBound(block, Dim, options.radius_min);
    problem.SetParameterUpperBound(block, Dim, options.radius_max);
  }

  ceres::Solver::Options solver_options;
  solver_options.minimizer_type = ceres::TRUST_REGION;
  solver_options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  if (options.iterative_linear_solver) {
    solver_options.linear_solver_type = ceres::CGNR;
    solver_options.preconditioner_type = ceres::JACOBI;
  } else {
    solver_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    solver_options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;

  }
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.gradient_tolerance = options.gradient_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  solver_options.num_threads = options.num_threads;
  solver_options.logging_type = ceres::SILENT;
  StopBelowCost stop(options.stop_cost);
  if (options.stop_cost > 0.0) solver_options.callbacks.push_back(&stop);
  ReportIteration report(options.on_iteration, parameters);
  if (options.on_iteration) {
    solver_options.update_state_every_iteration = true;
    solver_options.callbacks.push_back(&report);
  }
  solver_options.minimizer_progress_to_stdout = false;

  ceres::Solver::Summary ceres_summary;
  ceres::Solve(solver_options, &problem, &ceres_summary);

  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < Dim; ++k) centres[i][k] = parameters[i * (Dim + 1) + k];
    radii[i] = parameters[i * (Dim + 1) + Dim];
  }
  LevenbergMarquardtSummary summary;
  summary.iterations = static_cast<int>(ceres_summary.iterations.size()) - 1;
  summary.initial_cost = ceres_summary.initial_cost;
  summary.final_cost = ceres_summary.final_cost;
  summary.termination = ceres_summary.message;
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

template double EdgeResidual<2>(const double*, const double*, double, double, bool, double*,
                                double*);
template double EdgeResidual<3>(const double*, const double*, double, double, bool, double*,
                                double*);
template double BandEdgeResidual<2>(const double*, const double*, double, double, double, double,
                                    bool, double*, double*);
template double BandEdgeResidual<3>(const double*, const double*, double, double, double, double,
                                    bool, double*, double*);
template double BoundaryResidual<2>(const Domain<2>&, const BoundaryFacet<2>&, const double*,
                                    double, double, bool, double*);
template double BoundaryResidual<3>(const Domain<3>&, const BoundaryFacet<3>&, const double*,
                                    double, double, bool, double*);
template LevenbergMarquardtSummary SolveLevenbergMarquardt<2>(const Domain<2>&,
                                                              const ContactGraph<2>&,
                                                              const LevenbergMarquardtOptions&,
                                                              std::vector<Vector<2>>&,
                                                              std::vector<double>&);
template LevenbergMarquardtSummary SolveLevenbergMarquardt<3>(const Domain<3>&,
                                                              const ContactGraph<3>&,
                                                              const LevenbergMarquardtOptions&,
                                                              std::vector<Vector<3>>&,
                                                              std::vector<double>&);

}  // namespace specimen
