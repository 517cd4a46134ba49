#include "solver/stability_limits.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <sstream>

#include "common/error.h"
#include "solver/particles.h"
#include "solver/stability_network.h"
#include "solver/time_step.h"
#include "common/format.h"

namespace specimen {

namespace {

// 2 / sqrt(lambda) x damping; infinity for lambda = 0.
double TimeStepOf(double lambda, double damping) {
  if (!(lambda > 0.0)) return std::numeric_limits<double>::infinity();
  return 2.0 / std::sqrt(lambda) * damping;
}

EigenvalueReport Report(const LanczosResult& r) {
  EigenvalueReport e;
  e.ritz_value = r.ritz_value;
  e.certified_upper_bound = r.certified_upper_bound;
  e.relative_tolerance = r.relative_tolerance;
  e.residual_norm = r.residual_norm;
  e.iterations = r.iterations;
  e.dimension = r.dimension;
  e.reorthogonalised = r.reorthogonalised;
  e.exact = r.exact;
  e.seconds = r.seconds;
  return e;
}

// The Lanczos options of one stage, with its progress label.
LanczosOptions StageOptions(const StabilityLimitOptions& options, const std::string& label) {
  LanczosOptions lanczos = options.lanczos;
  lanczos.progress = options.progress;
  lanczos.progress_label = label;
  return lanczos;
}

// The operator of the step's stability boundary z = -1 (stability_limits.h, items 1 and 3):
// H = sym(M^-1/2 C^T (I - L)^-1 K* C M^-1/2), where at z = -1 a link's force is
//  - normal: (kn + 2 cn / dt) g plus kn times the strain correction of the total forces (the
//    lagged dashpot force c v_(n-1/2) = c (u_n - u_(n-1)) / dt = 2 c u_n / dt acts as a
//    stiffness 2c/dt; it has no strain correction but enters the particle stress);
//  - tangential: (kt + 2 ct / dt) d_t, not corrected (Madan assumption 5).
// Rigid particles: L = 0 and H = M^-1/2 C^T K* C M^-1/2. Counts the inner CG iterations.
template <int Dim>
class BoundaryOperator {
 public:
  // compliance: nullptr for rigid particles; dashpot_time_step_s: the dt of 2c/dt (0: no
  // dashpots).
  BoundaryOperator(const LinearisedNetwork<Dim>& network, const ParticleCompliance<Dim>* compliance,
                   double dashpot_time_step_s, const StabilityLimitOptions& options)
      : network_(network), compliance_(compliance), options_(options) {
    const int links = network.link_count();
    normal_.resize(links);
    tangential_.resize(links);
    root_kn_.resize(links);
    const bool dashpots = network.has_dashpots() && dashpot_time_step_s > 0.0;
    for (int c = 0; c < links; ++c) {
      normal_[c] = network.normal_stiffness(c);
      tangential_[c] = network.tangential_stiffness(c);
      if (dashpots) {
        normal_[c] += 2.0 * network.normal_dashpot(c) / dashpot_time_step_s;
        tangential_[c] += 2.0 * network.tangential_dashpot(c) / dashpot_time_step_s;
      }
      root_kn_[c] = std::sqrt(network.normal_stiffness(c));
    }
    symmetric_ = compliance == nullptr || (!network.has_tangential() && !dashpots);
  }

  void Apply(const std::vector<double>& x, std::vector<double>& y) {
    if (symmetric_) {
      Forward(x, y);
      return;
    }
    // (H x + H^T x) / 2, the two inner solves side by side (one pass over the network for
    // both right-hand sides).
    const int links = network_.link_count();
    const bool tangential = network_.has_tangential();
    network_.LinkKinematics(x, &raw_normal_, tangential ? &raw_tangential_ : nullptr);
    if (!tangential) raw_tangential_.clear();
    // Forward: f_t = K*_t d_t; (I - B) f_n = K*_n g + kn N^T eps(f_t); solved for
    // w = K^-1/2 f_n from K^-1/2 times the right-hand side.
    std::vector<double>& g = g_;
    std::vector<Vector<Dim>>& t = t_;
    g.resize(links);
    t.resize(raw_tangential_.size());
    for (int c = 0; c < links; ++c) g[c] = raw_normal_[c] * normal_[c];
    for (size_t c = 0; c < t.size(); ++c) t[c] = raw_tangential_[c] * tangential_[c];
    if (tangential) {
      zeros_.assign(links, 0.0);
      network_.StrainOfLinkForces(*compliance_, zeros_, t, &strain_);
      network_.NormalDisplacementOfStrain(strain_, &correction_);
      for (int c = 0; c < links; ++c) g[c] += network_.normal_stiffness(c) * correction_[c];
    }
    for (int c = 0; c < links; ++c) g[c] /= root_kn_[c];
    // Transposed: (I - S) w' = K^1/2 g_raw.
    rhs_transposed_.resize(links);
    for (int c = 0; c < links; ++c) rhs_transposed_[c] = raw_normal_[c] * root_kn_[c];
    SolvePair(g, rhs_transposed_, &w_, &w_transposed_);
    // Forward: y = M^-1/2 C^T f.
    for (int c = 0; c < links; ++c) g[c] = w_[c] * root_kn_[c];
    network_.GatherLinkForces(g, t, y);
    // Transposed: f_n = K*_n z, f_t = K*_t (d_t + S_t^T eps(kn z)), z = K^-1/2 w'.
    std::vector<double>& normal = correction_;
    normal.resize(links);
    for (int c = 0; c < links; ++c) {
      normal[c] = normal_[c] * w_transposed_[c] / root_kn_[c];
      w_transposed_[c] *= root_kn_[c];
    }
    if (tangential) {
      network_.StrainOfLinkForces(*compliance_, w_transposed_, {}, &strain_);
      network_.TangentialDisplacementOfStrain(strain_, &tangential_correction_);
      for (int c = 0; c < links; ++c)
        t[c] = tangential_[c] * (raw_tangential_[c] + tangential_correction_[c]);
    }
    network_.GatherLinkForces(normal, t, transposed_);
    for (size_t k = 0; k < y.size(); ++k) y[k] = 0.5 * (y[k] + transposed_[k]);
    // The bonds' rotational springs are symmetric and strain no particle: both halves add them.
    network_.AddBendingStiffness(x, y);
  }
  long inner_iterations() const { return inner_iterations_; }

 private:
  // (I - S) w = r, S = K_n^1/2 M K_n^1/2 with the scene's compliance.
  void Solve(const std::vector<double>& r, std::vector<double>* w) {
    const SymmetricOperator i_minus_s = [&](const std::vector<double>& v,
                                            std::vector<double>& out) {
      network_.ApplyDdemOperator(*compliance_, v, out);
      for (size_t k = 0; k < v.size(); ++k) out[k] = v[k] - out[k];
    };
    const ConjugateGradientResult result = ConjugateGradient(
        i_minus_s, r, options_.inner_tolerance, options_.inner_max_iterations, w, &workspace_,
        options_.lanczos.num_threads);
    inner_iterations_ += result.iterations;
    if (!result.converged)
      throw ComputationError(
          "DDEM time step: the inner solve (I - S) w = r did not reach the relative residual " +
          Number(options_.inner_tolerance) + " in " + std::to_string(result.iterations) +
          " iterations (residual " + Number(result.relative_residual) +
          "); rho(B) is too close to 1");
  }

  // Both systems (I - S) w1 = r1, (I - S) w2 = r2 at once.
  void SolvePair(const std::vector<double>& r1, const std::vector<double>& r2,
                 std::vector<double>* w1, std::vector<double>* w2) {
    const SymmetricOperatorPair i_minus_s = [&](const std::vector<double>& v1,
                                                const std::vector<double>& v2,
                                                std::vector<double>& out1,
                                                std::vector<double>& out2) {
      network_.ApplyDdemOperatorPair(*compliance_, v1, v2, out1, out2);
      for (size_t k = 0; k < v1.size(); ++k) {
        out1[k] = v1[k] - out1[k];
        out2[k] = v2[k] - out2[k];
      }
    };
    const std::array<ConjugateGradientResult, 2> results =
        ConjugateGradientPair(i_minus_s, r1, r2, options_.inner_tolerance,
                              options_.inner_max_iterations, w1, w2, &pair_workspace_,
                              options_.lanczos.num_threads);
    for (const ConjugateGradientResult& result : results) {
      inner_iterations_ += result.iterations;
      if (!result.converged)
        throw ComputationError(
            "DDEM time step: the inner solve (I - S) w = r did not reach the relative residual " +
            Number(options_.inner_tolerance) + " in " + std::to_string(result.iterations) +
            " iterations (residual " + Number(result.relative_residual) +
            "); rho(B) is too close to 1");
    }
  }

  // f_t = K*_t d_t; (I - B) f_n = K*_n g + kn N^T eps(f_t); y = M^-1/2 C^T f.
  void Forward(const std::vector<double>& x, std::vector<double>& y) {
    const int links = network_.link_count();
    const bool tangential = network_.has_tangential();
    std::vector<double>& g = g_;
    std::vector<Vector<Dim>>& t = t_;
    network_.LinkKinematics(x, &g, tangential ? &t : nullptr);
    if (!tangential) t.clear();
    for (int c = 0; c < links; ++c) g[c] *= normal_[c];
    if (tangential)
      for (int c = 0; c < links; ++c) t[c] *= tangential_[c];
    if (compliance_ != nullptr) {
      if (tangential) {
        zeros_.assign(links, 0.0);
        network_.StrainOfLinkForces(*compliance_, zeros_, t, &strain_);
        network_.NormalDisplacementOfStrain(strain_, &correction_);
        for (int c = 0; c < links; ++c) g[c] += network_.normal_stiffness(c) * correction_[c];
      }
      // f_n = K^1/2 w with (I - S) w = K^-1/2 rhs.
      for (int c = 0; c < links; ++c) g[c] /= root_kn_[c];
      Solve(g, &w_);
      for (int c = 0; c < links; ++c) g[c] = w_[c] * root_kn_[c];
    }
    network_.GatherLinkForces(g, t, y);
    network_.AddBendingStiffness(x, y);
  }

  const LinearisedNetwork<Dim>& network_;
  const ParticleCompliance<Dim>* compliance_;
  const StabilityLimitOptions& options_;
  std::vector<double> normal_, tangential_, root_kn_;
  bool symmetric_ = true;
  long inner_iterations_ = 0;
  // Work vectors kept between products (no allocation in the Lanczos loop).
  std::vector<double> g_, w_, zeros_, correction_, transposed_;
  std::vector<double> raw_normal_, rhs_transposed_, w_transposed_;
  std::vector<Vector<Dim>> t_, tangential_correction_, raw_tangential_;
  std::vector<SymmetricTensor<Dim>> strain_;
  ConjugateGradientWorkspace workspace_;
  ConjugateGradientPairWorkspace pair_workspace_;
};

// The certified critical step of the boundary operator: undamped 2/sqrt(lambda_max(H)) (the
// certified bound capped by `undamped_cap`, another upper bound of lambda_max), or with
// dashpots the root of dt^2 lambda_max(H(dt)) = 4, times the local damping factor
// 1/sqrt(1 + alpha). Fills the report of the last Lanczos solve.
template <int Dim>
struct BoundaryResult {
  double critical_s = 0.0;  // certified, damped
  double ritz_s = 0.0;      // from the Ritz values (unsafe side), damped
  double undamped_s = 0.0;  // certified, without dashpots and local damping
  double undamped_ritz_s = 0.0;
  LanczosResult lanczos;
  std::vector<double> mode;  // Ritz vector of the undamped solve (when asked for)
  long inner_iterations = 0;
  int fixed_point_iterations = 0;
};

template <int Dim>
BoundaryResult<Dim> CriticalStep(const LinearisedNetwork<Dim>& network,
                                 const ParticleCompliance<Dim>* compliance,
                                 const StabilityLimitOptions& options, LanczosOptions lanczos,
                                 double local_damping_factor, double undamped_cap,
                                 double inexact_margin = 0.0) {
  BoundaryResult<Dim> result;
  auto solve = [&](double dashpot_step, LanczosOptions o) {
    BoundaryOperator<Dim> op(network, compliance, dashpot_step, options);
    LanczosResult r = LargestEigenvalue(
        network.dof_count(),
        [&](const std::vector<double>& x, std::vector<double>& y) { op.Apply(x, y); }, o);
    // The inner solves are inexact: the products are those of an operator within a relative
    // `inexact_margin` of H (below), which the certified bound allows for.
    r.certified_upper_bound *= 1.0 + inexact_margin;
    result.inner_iterations += op.inner_iterations();
    return r;
  };
  result.lanczos = solve(0.0, lanczos);
  result.mode = result.lanczos.ritz_vector;
  // Another valid upper bound (Gershgorin for the DEM operator) may be lower.
  result.lanczos.certified_upper_bound = std::max(
      result.lanczos.ritz_value, std::min(result.lanczos.certified_upper_bound, undamped_cap));
  result.undamped_s = TimeStepOf(result.lanczos.certified_upper_bound, 1.0);
  result.undamped_ritz_s = TimeStepOf(std::max(result.lanczos.ritz_value, 0.0), 1.0);
  double step = result.undamped_s, ritz_step = result.undamped_ritz_s;
  if (network.has_dashpots() && std::isfinite(step)) {
    // The boundary dt^2 lambda_max(H(dt)) = 4, i.e. phi(dt) = dt sqrt(lambda(dt)) - 2 = 0;
    // phi increases with dt (dt^2 H(dt) = dt^2 A + 2 dt C). Secant iterations from the
    // undamped step (phi >= 0) and one fixed-point step, on the certified bounds.
    lanczos.compute_ritz_vector = false;
    auto phi = [&](double dt) {
      const LanczosResult r = solve(dt, lanczos);
      ++result.fixed_point_iterations;
      result.lanczos = r;
      ritz_step = TimeStepOf(r.ritz_value, 1.0);
      return dt * std::sqrt(r.certified_upper_bound) - 2.0;
    };
    double previous = step, previous_phi = phi(step);
    double current = TimeStepOf(result.lanczos.certified_upper_bound, 1.0);
    double current_phi = phi(current);
    for (int k = 0;
         k < 30 && std::abs(current - previous) > 1e-9 * current && current_phi != previous_phi;
         ++k) {
      double next = current - current_phi * (current - previous) / (current_phi - previous_phi);
      next = std::clamp(next, 0.5 * current, 2.0 * current);
      previous = current;
      previous_phi = current_phi;
      current = next;
      current_phi = phi(current);
    }
    step = current * (1.0 - 1e-8);
  }
  result.critical_s = step * local_damping_factor;
  result.ritz_s = ritz_step * local_damping_factor;
  return result;
}

// The DDEM step of normal springs without dashpots, without inner solves. With
// A = K_n^1/2 C M^-1/2 (links x degrees of freedom), the boundary operator is
// H = A^T (I - S)^-1 A, and its nonzero eigenvalues are those of the symmetric-definite pencil
// A A^T v = lambda (I - S) v on the links (v = (I - S)^-1 A x). So lambda* = lambda_max(H) is
// the root of phi(lambda) = lambda, phi(lambda) = lambda_max(A A^T + lambda S): above lambda*,
// A A^T - lambda (I - S) is negative definite (phi < lambda), below it is not (phi > lambda).
// phi is convex with slope y^T S y in [0, rho(B)] (y its unit top eigenvector), so Newton
// from a lower bound climbs to lambda*; each phi is a plain Lanczos solve whose product is
// one pass of the network and one of the DDEM operator (H needs a CG solve per product).
// Certificate: a lambda_c whose certified bound of phi(lambda_c) is <= lambda_c is >= lambda*.
// As phi has slope s at the root, that bound needs the relative tolerance (1 - s) x the gap
// lambda_c / lambda* - 1. Returns nothing when no certificate was reached (the caller then
// takes the inner-solve path).
//
// Tangential springs (kt > 0, no dashpots): the boundary operator is not symmetric (the
// tangential forces enter the strain but are not corrected by it, Madan assumption 5), and
// item 3 of the header takes its symmetric part
//   H_s = A_t^T A_t + A_n^T P A_n + (A_n^T P G A_t + A_t^T G^T P A_n) / 2,  P = (I - S)^-1,
// with A_t = K_t^1/2 C_t M^-1/2 and G = K_n^1/2 M_nt K_t^1/2 (the normal gap correction of the
// strain of tangential forces). Completing the square,
//   H_s = A_t^T A_t + (A_n + G A_t / 2)^T P (A_n + G A_t / 2) - A_t^T G^T P G A_t / 4
//      <= A~^T diag(I, P) A~ = H_u,  A~ = [A_t; A_n + G A_t / 2],
// since P is positive definite. H_u bounds H_s from above (the step stays on the safe side),
// and it has the same pencil form with S acting on the normal block only: lambda_max(H_u)
// is the fixed point of lambda_max(A~ A~^T + lambda diag(0, S)) = lambda, found as below
// without inner solves. The dropped term vanishes on pure rotations (their tangential forces
// load a particle with a couple, no strain); the benchmark measures what it costs.
template <int Dim>
std::optional<BoundaryResult<Dim>> PencilCriticalStep(const LinearisedNetwork<Dim>& network,
                                                      const ParticleCompliance<Dim>& compliance,
                                                      const StabilityLimitOptions& options,
                                                      const LanczosOptions& lanczos,
                                                      double local_damping_factor,
                                                      double start, double lower_bound) {
  const auto start_time = std::chrono::steady_clock::now();
  const bool tangential = network.has_tangential();
  const int size = network.link_count() * (tangential ? 1 + Dim : 1);
  std::vector<double> deformation;
  int iterations = 0;
  // phi(shift) by Lanczos on A A^T + shift S.
  auto solve = [&](double shift, LanczosOptions o) {
    const LanczosResult r = LargestEigenvalue(
        size,
        [&](const std::vector<double>& v, std::vector<double>& y) {
          if (tangential)
            network.ApplyTangentialPencilOperator(compliance, shift, v, y);
          else
            network.ApplyPencilOperator(compliance, shift, v, y);
        },
        o);
    iterations += r.iterations;
    return r;
  };
  // d phi / d shift = y^T S y (Hellmann-Feynman).
  auto slope_of = [&](const std::vector<double>& y) {
    if (tangential)
      network.ApplyTangentialPencilShift(compliance, y, deformation);
    else
      network.ApplyDdemOperator(compliance, y, deformation);
    double ysy = 0.0, yy = 0.0;
    for (int c = 0; c < size; ++c) {
      ysy += y[c] * deformation[c];
      yy += y[c] * y[c];
    }
    return std::clamp(ysy / yy, 0.0, 1.0 - 1e-9);
  };
  // Newton on phi(lambda) - lambda, from `start` (the DEM value). phi - lambda is convex and
  // decreasing: from a start above lambda* one step lands below it, and from there Newton
  // climbs; never below `lower_bound`.
  const double tolerance = options.ddem_relative_tolerance;
  LanczosOptions newton = lanczos;
  newton.compute_ritz_vector = true;
  newton.relative_tolerance = tolerance;
  newton.max_iterations = std::min(newton.max_iterations, 20);
  double lambda = std::max(start, lower_bound), slope = 0.0;
  bool exact = false;
  int newton_steps = 0;
  for (; newton_steps < 50; ++newton_steps) {
    const LanczosResult r = solve(lambda, newton);
    exact = r.exact;
    slope = slope_of(r.ritz_vector);
    const double next = lambda + (r.ritz_value - lambda) / (1.0 - slope);
    const double step = next - lambda;
    lambda = std::max(next, lower_bound);
    if (std::abs(step) <= (exact ? 1e-13 : 0.2 * tolerance) * lambda) break;
  }
  // The certificate, with a gap of the tolerance (exact solves: round-off).
  double gap = exact ? 1e-10 : tolerance;
  LanczosOptions check = lanczos;
  check.compute_ritz_vector = false;
  for (int attempt = 0; attempt < 4; ++attempt) {
    const double certified = lambda * (1.0 + gap);
    // phi(certified) is about lambda* (1 + slope gap): its bound needs eps below (1 - slope)
    // gap; 0.7 of it leaves room for Newton's last step (0.2 of the tolerance).
    check.relative_tolerance = std::clamp(0.7 * (1.0 - slope) * gap, 1e-12, 0.4);
    const LanczosResult r = solve(certified, check);
    if (r.certified_upper_bound <= certified) {
      BoundaryResult<Dim> result;
      result.lanczos = r;
      result.lanczos.ritz_value = lambda;
      result.lanczos.certified_upper_bound = certified;
      result.lanczos.relative_tolerance = gap;
      result.lanczos.iterations = iterations;
      result.lanczos.exact = exact;
      result.lanczos.seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
      result.undamped_s = TimeStepOf(certified, 1.0);
      result.undamped_ritz_s = TimeStepOf(lambda, 1.0);
      result.critical_s = result.undamped_s * local_damping_factor;
      result.ritz_s = result.undamped_ritz_s * local_damping_factor;
      result.fixed_point_iterations = newton_steps + attempt + 1;
      return result;
    }
    // Not certified (the tolerance reached, the round-off allowance of an exact solve, or
    // lambda below lambda*): a wider gap, for the bound's excess over the Ritz value.
    const double excess = r.certified_upper_bound / r.ritz_value - 1.0;
    gap = std::max(2.0 * gap, 1.5 * excess / (1.0 - slope));
    if (r.ritz_value > certified) lambda = r.ritz_value;
  }
  return std::nullopt;
}

// Damping (local alpha or dashpot ratio) that held the flutter of DDEM with kt > 0 in the
// benchmark (tools/bench/stability_bench.py): alpha = 0.05 did in 2D, not in 3D; 0.1 did in
// both (kt = kn and 1.25 kn, kn/(Ep l) at half its limit).
constexpr double kFlutterDamping = 0.1;

struct Limit {
  std::string name;
  double margin = 0.0;  // fraction; < 0: beyond the limit
  bool marginal = false;
  std::string detail;
};

}  // namespace

double DampedUnilateralFactor(double damping, int dimension) {
  // The wall scans of tools/bench/stability_bench.md (header): in 2D the first failures were
  // at 0.89 of the linear limit undamped, 0.99 with alpha = 0.05, none with alpha = 0.1; in
  // 3D at 0.94, 0.93 and 0.97 (alpha 0, 0.05, 0.1), so 3D keeps a factor up to alpha 0.3.
  if (damping < 0.05) return 0.85;
  if (dimension == 3) {
    if (damping < 0.1) return 0.92;
    return damping < 0.3 ? 0.96 : 1.0;
  }
  return damping < 0.1 ? 0.94 : 1.0;
}

bool StabilityLimitOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& field, double value, const std::string& range) {
    if (error) *error = field + " = " + Number(value) + " is not allowed: it must be " + range;
    return false;
  };
  if (!(proposed_time_step_s >= 0.0) || !std::isfinite(proposed_time_step_s))
    return fail("proposed_time_step_s", proposed_time_step_s, "finite and >= 0 (0: none)");
  if (!(safety_factor > 0.0 && safety_factor <= 1.0))
    return fail("safety_factor", safety_factor, "in (0, 1]");
  if (!(time_step_margin >= 0.0 && time_step_margin < 0.5))
    return fail("time_step_margin", time_step_margin, "in [0, 0.5)");
  if (!(unilateral_contact_factor >= 0.0 && unilateral_contact_factor <= 1.0))
    return fail("unilateral_contact_factor", unilateral_contact_factor,
                "in [0, 1] (0: graded by the damping)");
  if (!(max_spectral_radius > 0.0 && max_spectral_radius <= 1.0))
    return fail("max_spectral_radius", max_spectral_radius, "in (0, 1]");
  if (!(ddem_relative_tolerance > 0.0 && ddem_relative_tolerance < 0.5))
    return fail("ddem_relative_tolerance", ddem_relative_tolerance, "in (0, 0.5)");
  if (!(inner_tolerance > 0.0 && inner_tolerance < 1e-3))
    return fail("inner_tolerance", inner_tolerance, "in (0, 1e-3)");
  if (inner_max_iterations < 1) return fail("inner_max_iterations", inner_max_iterations, ">= 1");
  std::string inner;
  if (!lanczos.IsValid(&inner)) {
    if (error) *error = "lanczos." + inner;
    return false;
  }
  return true;
}

template <int Dim>
LanczosResult LargestDdemEigenvalue(const LinearisedNetwork<Dim>& network,
                                    const ParticleCompliance<Dim>& compliance,
                                    const StabilityLimitOptions& options, const std::string& label) {
  return LargestEigenvalue(
      network.link_count(),
      [&](const std::vector<double>& x, std::vector<double>& y) {
        network.ApplyDdemOperator(compliance, x, y);
      },
      StageOptions(options, label));
}

template <int Dim>
StabilityLimits AnalyseStabilityLimits(
    const Packing<Dim>& packing, const SceneOptions<Dim>& scene,
    const StabilityLimitOptions& given_options,
    const std::function<void(const LinearisedNetwork<Dim>&, const StabilityLimitOptions&)>& more) {
  StabilityLimitOptions options = given_options;
  options.lanczos.num_threads = scene.num_threads;  // the network's products and the vectors'
  std::string error;
  if (!options.IsValid(&error)) throw InputError("stability analysis: " + error);
  if (!scene.material.IsPhysical(Dim == 2 ? 1.0 : VolumeMeanRadius<Dim>(packing.radii), &error))
    throw InputError("material: " + error);
  const auto start = std::chrono::steady_clock::now();
  const LinearisedNetwork<Dim> network(packing, scene, options.wall_reach_m);
  const MaterialParameters& material = scene.material;
  StabilityLimits s;

  // 1. The scene.
  s.dimension = Dim;
  s.particles = network.particle_count();
  s.links = network.link_count();
  s.contact_links = network.contact_links();
  s.wall_links = network.wall_links();
  s.rattler_links = network.rattler_links();
  s.rattlers_without_neighbour = network.rattlers_without_neighbour();
  s.degrees_of_freedom = network.dof_count();
  s.fixed_degrees_of_freedom = network.fixed_dofs();
  s.rotation = network.has_rotation();
  s.normal_stiffness_n_per_m = material.normal_stiffness_n_per_m;
  s.tangential_stiffness_n_per_m = material.tangential_stiffness_n_per_m;
  s.bond_radius_ratio = material.bond_radius_ratio;
  s.bond_range = material.bond_range;
  s.deformable = material.deformable();
  s.particle_poisson_ratio = material.particle_poisson_ratio;
  if (s.deformable) s.particle_youngs_modulus_pa = *material.particle_youngs_modulus_pa;
  s.particle_model = !s.deformable ? "rigid"
                     : Dim == 3    ? "3D isotropic"
                                   : PlaneModelName(material.plane_model);
  s.group_length_m = Dim == 2 ? 1.0 : VolumeMeanRadius<Dim>(packing.radii);

  // 2. The solver's per-particle bound (time_step.h), for comparison; local damping factor.
  const ParticleArrays<Dim> particles = BuildParticles<Dim>(packing, material, false);
  const CriticalTimeStepEstimate per_particle = PerParticleCriticalTimeStep<Dim>(
      particles, network.ContactPairs(), material, network.WallStiffnessPerParticle());
  s.per_particle_bound_s = per_particle.per_particle_bound_s;
  s.mass_scaling = particles.mass_scaling;
  s.guaranteed_bound_s = per_particle.guaranteed_bound_s;
  s.local_damping_factor = per_particle.local_damping_factor;

  // 3. omega_max^2 of M^-1/2 K M^-1/2: Lanczos (certified) and Gershgorin (deterministic);
  //    with dashpots, the damped boundary (fixed point in dt).
  const int dofs = network.dof_count();
  double dem_ritz = 0.0, dem_upper = 0.0;
  if (dofs > 0 && network.link_count() > 0) {
    LanczosOptions lanczos = StageOptions(options, "omega_max (DEM)");
    lanczos.compute_ritz_vector = options.locate_mode;
    const double gershgorin = network.GershgorinBound();
    s.gershgorin_bound_s = TimeStepOf(gershgorin, 1.0);
    const BoundaryResult<Dim> dem =
        CriticalStep<Dim>(network, nullptr, options, lanczos, s.local_damping_factor, gershgorin);
    s.dem_eigenvalue = Report(dem.lanczos);
    dem_ritz = 4.0 / (dem.undamped_ritz_s * dem.undamped_ritz_s);
    dem_upper = 4.0 / (dem.undamped_s * dem.undamped_s);
    s.dem_time_step_ritz_s = dem.ritz_s;
    s.dem_critical_time_step_s = dem.critical_s;
    s.dashpot_factor = dem.critical_s / (dem.undamped_s * s.local_damping_factor);
    s.dashpot_fixed_point_iterations = dem.fixed_point_iterations;
    // Where the mode lives: the particle with the largest share of sum y^2 (mass-scaled
    // coordinates: the mode's kinetic energy).
    const std::vector<double>& mode = dem.mode;
    if (!mode.empty()) {
      std::vector<double> share(s.particles, 0.0);
      double rotational = 0.0;
      for (int d = 0; d < dofs; ++d) {
        const double e = mode[d] * mode[d];
        const int owner = network.DofOwner(d);
        if (owner >= 0) share[owner] += e;
        if (network.DofIsRotation(d)) rotational += e;
      }
      const auto top = std::max_element(share.begin(), share.end());
      s.mode_particle = static_cast<int>(top - share.begin());
      s.mode_particle_share = *top;
      s.mode_particle_radius_m = network.radius(s.mode_particle);
      s.mode_rotational_share = rotational;
    }
  } else {
    s.dem_time_step_ritz_s = s.dem_critical_time_step_s = s.gershgorin_bound_s =
        std::numeric_limits<double>::infinity();
  }
  s.omega_max_ritz_rad_per_s = std::sqrt(dem_ritz);
  s.omega_max_certified_rad_per_s = std::sqrt(dem_upper);
  s.critical_time_step_s = s.dem_critical_time_step_s;
  s.critical_time_step_method =
      "2/omega_max, omega_max^2 certified by Lanczos (Kuczynski-Wozniakowski, failure "
      "probability " +
      Number(options.lanczos.failure_probability, 2) + ") and Gershgorin";
  if (network.has_dashpots())
    s.critical_time_step_method += ", dashpots at the boundary z = -1 (2c/dt)";
  if (!std::isfinite(s.critical_time_step_s)) {
    // Nothing can oscillate (no links, or every axis prescribed): the per-particle bound
    // (which counts one contact per particle) is all there is.
    s.critical_time_step_s = s.per_particle_bound_s;
    s.critical_time_step_method = "per-particle bound (the network has no stiffness)";
  }

  // 4. DDEM convergence: lambda_max(S^) for Ep = 1.
  const ParticleCompliance<Dim> unit_compliance(1.0, material.particle_poisson_ratio,
                                                material.plane_model);
  s.max_spectral_radius = options.max_spectral_radius;
  const double kn = material.normal_stiffness_n_per_m;
  if (network.link_count() > 0) {
    const LanczosResult r = LargestDdemEigenvalue<Dim>(network, unit_compliance, options, "rho(B)");
    s.convergence_eigenvalue = Report(r);
    s.unit_spectral_radius_pa = r.certified_upper_bound;
  }
  if (s.unit_spectral_radius_pa > 0.0) {
    s.admissible_kn_over_ep = kn / (s.group_length_m * s.unit_spectral_radius_pa);
    s.recommended_kn_over_ep = options.max_spectral_radius * s.admissible_kn_over_ep;
    s.smallest_youngs_modulus_pa = s.unit_spectral_radius_pa / options.max_spectral_radius;
  }
  if (s.deformable) {
    const double ep = s.particle_youngs_modulus_pa;
    s.spectral_radius = s.unit_spectral_radius_pa / ep;
    s.spectral_radius_ritz = s.convergence_eigenvalue.ritz_value / ep;
    s.kn_over_ep = kn / (ep * s.group_length_m);
  }

  // 5. The DDEM time step (z = -1 effective stiffness), when the iteration converges.
  if (s.deformable && s.spectral_radius < 1.0 && dofs > 0 && network.link_count() > 0) {
    const ParticleCompliance<Dim> compliance(s.particle_youngs_modulus_pa,
                                             material.particle_poisson_ratio, material.plane_model);
    LanczosOptions lanczos = StageOptions(options, "omega_max (DDEM)");
    lanczos.relative_tolerance = options.ddem_relative_tolerance;
    // Inner solves to the relative residual tau: the error of w = (I - S)^-1 r is at most
    // tau / (1 - rho(B)) of |w|-scale quantities, so each product is within that (times the
    // norms of the outer factors, <= 1 relative to |H| up to a small constant) of the exact
    // one; a tenfold allowance.
    const double inexact_margin =
        10.0 * options.inner_tolerance / std::max(1e-3, 1.0 - s.spectral_radius);
    // No dashpots: the pencil, without inner solves, Newton from the DEM value. Normal
    // springs: DDEM only stiffens, lambda_max(H) >= the DEM value, a lower bound; with
    // tangential springs the coupling G can soften the top mode (benchmark: up to 0.4 %), so
    // Newton may go below it there (lower bound 0).
    std::optional<BoundaryResult<Dim>> pencil;
    // The pencil has no term for the bonds' rotational springs: with them, inner solves.
    if (!network.has_dashpots() && !network.has_bending() && !options.ddem_inner_solves)
      pencil = PencilCriticalStep<Dim>(network, compliance, options, lanczos,
                                       s.local_damping_factor, dem_ritz,
                                       network.has_tangential() ? 0.0 : dem_ritz);
    s.ddem_time_step_inner_solves = !pencil;
    const BoundaryResult<Dim> ddem =
        pencil ? *pencil
               : CriticalStep<Dim>(network, &compliance, options, lanczos, s.local_damping_factor,
                                   std::numeric_limits<double>::infinity(), inexact_margin);
    s.ddem_eigenvalue = Report(ddem.lanczos);
    s.ddem_eigenvalue.inner_iterations = static_cast<int>(ddem.inner_iterations);
    s.ddem_time_step_ritz_s = ddem.ritz_s;
    s.ddem_critical_time_step_s = ddem.critical_s;
    s.ddem_reduction_percent = 100.0 * (1.0 - s.ddem_time_step_ritz_s / s.dem_time_step_ritz_s);
    s.ddem_time_step_available = true;
    s.critical_time_step_s = s.ddem_critical_time_step_s;
    s.critical_time_step_method =
        "2/omega_max of the DDEM scheme (z = -1 effective stiffness C^T (I - L)^-1 K C), "
        "certified by Lanczos (Kuczynski-Wozniakowski, failure probability " +
        Number(options.lanczos.failure_probability, 2) + ")";
    if (network.has_dashpots())
      s.critical_time_step_method += ", dashpots at the boundary z = -1 (2c/dt)";
  } else if (s.deformable && s.spectral_radius >= 1.0) {
    s.critical_time_step_method =
        "none: the DDEM force iteration diverges (rho(B) >= 1) at any time step; the DEM value "
        "is shown";
  }
  // Unilateral wall contacts, weakly damped: contacts that open and close (impacts) make the
  // scheme piecewise linear, and central differences then grow at some steps below the
  // linear limit (header); the scene is held to the damping-graded factor (or the option's)
  // x that limit.
  s.linear_critical_time_step_s = s.critical_time_step_s;
  {
    const double damping =
        std::max({material.translational_damping, material.rotational_damping,
                  material.normal_dashpot_ratio, material.tangential_dashpot_ratio});
    s.unilateral_contacts = s.wall_links > 0;
    const double graded = DampedUnilateralFactor(damping, Dim);
    if (s.unilateral_contacts && graded < 1.0 && std::isfinite(s.critical_time_step_s)) {
      s.unilateral_factor = options.unilateral_contact_factor > 0.0
                                ? options.unilateral_contact_factor
                                : graded;
      s.critical_time_step_s *= s.unilateral_factor;
      s.critical_time_step_method +=
          "; x " + Number(s.unilateral_factor, 3) + " for the unilateral wall contacts of " +
          (damping == 0.0 ? "an undamped" : "a weakly damped") + " scene (impacts)";
    }
  }
  // Madan assumption 5 makes DDEM with tangential springs non-conservative (header).
  s.flutter_possible = s.deformable && network.has_tangential();
  s.safety_factor = options.safety_factor;
  s.recommended_time_step_s = options.safety_factor * s.critical_time_step_s;

  // 6. Verdict for the proposed (or the recommended) step.
  s.judged_time_step_s = options.proposed_time_step_s > 0.0 ? options.proposed_time_step_s
                                                            : scene.time_step.time_step_s;
  s.judged_time_step_proposed = s.judged_time_step_s > 0.0;
  if (!s.judged_time_step_proposed) s.judged_time_step_s = s.recommended_time_step_s;
  std::vector<Limit> limits;
  {
    Limit step;
    step.name = s.ddem_time_step_available ? "critical time step (DDEM)" : "critical time step";
    step.margin = 1.0 - s.judged_time_step_s / s.critical_time_step_s;
    step.marginal = step.margin < options.time_step_margin;
    step.detail = "time step " + Number(s.judged_time_step_s) + " s against the critical " +
                  Number(s.critical_time_step_s) + " s";
    s.time_step_margin_percent = 100.0 * step.margin;
    limits.push_back(step);
  }
  if (s.deformable) {
    Limit convergence;
    convergence.name = "DDEM convergence rho(B) < 1";
    convergence.margin = 1.0 - s.spectral_radius;
    convergence.marginal = s.spectral_radius > options.max_spectral_radius;
    convergence.detail = "rho(B) = " + Number(s.spectral_radius, 5) +
                         " (required <= " + Number(options.max_spectral_radius, 4) +
                         "; kn/(Ep " + (Dim == 2 ? "l" : "R") + ") = " + Number(s.kn_over_ep, 5) +
                         ", admissible " +
                         Number(s.admissible_kn_over_ep, 5) + ")";
    s.spectral_radius_margin_percent = 100.0 * convergence.margin;
    limits.push_back(convergence);
  }
  const Limit* binding = &limits.front();
  for (const Limit& l : limits)
    if (l.margin < binding->margin) binding = &l;
  // A step at the limit itself is still bounded; rho(B) = 1 is not.
  bool unstable = limits.front().margin < 0.0 || (s.deformable && s.spectral_radius >= 1.0);
  bool marginal = false;
  for (const Limit& l : limits) marginal = marginal || l.marginal;
  s.verdict_message.clear();
  if (s.flutter_possible) {
    // Undamped: it grows (benchmark: within about 1e-4 s of simulated time at kn/(Ep l) =
    // 0.35, kt = kn, 2D); local damping alpha = 0.1 held it in 2D and 3D.
    const double alpha = std::max(material.translational_damping, material.rotational_damping);
    const bool damped =
        alpha >= kFlutterDamping || material.normal_dashpot_ratio >= kFlutterDamping;
    if (alpha == 0.0 && !network.has_dashpots()) {
      unstable = true;
    } else if (!damped) {
      marginal = true;
    }
    s.flutter_message =
        std::string(alpha == 0.0 && !network.has_dashpots() ? "undamped"
                    : damped                                ? "damped"
                                                            : "weakly damped") +
        " DDEM with tangential springs: the model is not conservative (Madan assumption 5), "
        "slowly growing modes exist at any time step; local damping alpha >= " +
        Number(kFlutterDamping) + " (or dashpots) held them in the benchmark";
    if (!damped) {
      s.binding_limit = "DDEM with kt > 0 needs damping (flutter)";
      s.margin_percent = 0.0;
    }
  }
  s.verdict = unstable ? "unstable" : marginal ? "marginal" : "stable";
  if (s.binding_limit.empty()) {
    s.binding_limit = binding->name;
    s.margin_percent = 100.0 * binding->margin;
  }
  s.verdict_message = s.verdict + ": binding limit " + s.binding_limit + ", margin " +
                      Number(s.margin_percent, 4) + " % (" + binding->detail + ")";
  if (s.binding_limit.rfind("DDEM with kt > 0", 0) == 0)
    s.verdict_message += "; " + s.flutter_message;

  // Limits of the linear analysis worth a word in this scene.
  if (s.flutter_possible) s.warnings.push_back(s.flutter_message);
  if (s.unilateral_factor != 1.0)
    s.warnings.push_back(
        "walls hold only in compression: a particle meeting or leaving a wall is an impact, "
        "and central differences on contacts that open and close can grow below the linear "
        "limit (the critical step holds a factor " +
        Number(s.unilateral_factor, 3) +
        " for it, from the benchmark, not a proof); local damping alpha >= 0.1 is safer");
  if (s.rattlers_without_neighbour > 0)
    s.warnings.push_back(std::to_string(s.rattlers_without_neighbour) +
                         " particle(s) have no link and no neighbour within the search skin: "
                         "not part of the analysis");
  if (s.deformable && s.spectral_radius >= 1.0)
    s.warnings.push_back("rho(B) >= 1: the DDEM scheme diverges at any time step (Madan (3.13))");

  if (more) more(network, options);
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return s;
}

std::string StabilityLimits::BriefReport() const {
  char head[256], convergence[256] = "", margin[64];
  std::snprintf(head, sizeof(head), "%dD stability: dt_cr %.6g s (recommended %.6g s)", dimension,
                critical_time_step_s, recommended_time_step_s);
  if (deformable)
    std::snprintf(convergence, sizeof(convergence), ", rho(B) %.5f, admissible kn/(Ep %s) %.5g",
                  spectral_radius, dimension == 2 ? "l" : "R", admissible_kn_over_ep);
  std::snprintf(margin, sizeof(margin), "%.3g", margin_percent);
  return std::string(head) + convergence + ", " + verdict + " (" + binding_limit + ", margin " +
         margin + " %)";
}

template StabilityLimits AnalyseStabilityLimits<2>(
    const Packing<2>&, const SceneOptions<2>&, const StabilityLimitOptions&,
    const std::function<void(const LinearisedNetwork<2>&, const StabilityLimitOptions&)>&);
template StabilityLimits AnalyseStabilityLimits<3>(
    const Packing<3>&, const SceneOptions<3>&, const StabilityLimitOptions&,
    const std::function<void(const LinearisedNetwork<3>&, const StabilityLimitOptions&)>&);
template LanczosResult LargestDdemEigenvalue<2>(const LinearisedNetwork<2>&,
                                                const ParticleCompliance<2>&,
                                                const StabilityLimitOptions&, const std::string&);
template LanczosResult LargestDdemEigenvalue<3>(const LinearisedNetwork<3>&,
                                                const ParticleCompliance<3>&,
                                                const StabilityLimitOptions&, const std::string&);

}  // namespace specimen
