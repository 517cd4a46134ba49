#include "solver/stability_lanczos.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>

#include "common/error.h"

namespace specimen {

namespace {

// Vector kernels. Long vectors are cut into a fixed number of chunks whatever the thread
// count, and the chunk sums added in order: the result does not depend on the threads.
constexpr size_t kChunkedLength = 32768;
constexpr int kChunks = 64;

double Dot(const std::vector<double>& a, const std::vector<double>& b, int threads = 1) {
  const size_t n = a.size();
  if (n < kChunkedLength) {
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i) sum += a[i] * b[i];
    return sum;
  }
  double partial[kChunks];
#pragma omp parallel for num_threads(threads) schedule(static) if (threads > 1)
  for (int c = 0; c < kChunks; ++c) {
    const size_t begin = n * c / kChunks, end = n * (c + 1) / kChunks;
    double sum = 0.0;
    for (size_t i = begin; i < end; ++i) sum += a[i] * b[i];
    partial[c] = sum;
  }
  double sum = 0.0;
  for (int c = 0; c < kChunks; ++c) sum += partial[c];
  return sum;
}

// y += s x
void Axpy(double s, const std::vector<double>& x, std::vector<double>& y, int threads = 1) {
  const long n = static_cast<long>(x.size());
#pragma omp parallel for num_threads(threads) schedule(static) if (threads > 1 && n >= 32768)
  for (long i = 0; i < n; ++i) y[i] += s * x[i];
}

// y = x / d
void Divide(const std::vector<double>& x, double d, std::vector<double>& y, int threads) {
  const long n = static_cast<long>(x.size());
#pragma omp parallel for num_threads(threads) schedule(static) if (threads > 1 && n >= 32768)
  for (long i = 0; i < n; ++i) y[i] = x[i] / d;
}

// p = r + ratio p
void Direction(const std::vector<double>& r, double ratio, std::vector<double>& p, int threads) {
  const long n = static_cast<long>(r.size());
#pragma omp parallel for num_threads(threads) schedule(static) if (threads > 1 && n >= 32768)
  for (long i = 0; i < n; ++i) p[i] = r[i] + ratio * p[i];
}

std::vector<double> RandomUnitVector(int n, std::uint64_t seed) {
  std::mt19937_64 engine(seed);
  std::normal_distribution<double> gaussian(0.0, 1.0);
  std::vector<double> v(n);
  for (double& x : v) x = gaussian(engine);
  const double norm = std::sqrt(Dot(v, v));
  for (double& x : v) x /= norm;
  return v;
}

// Relative size of the new Lanczos direction below which the Krylov space counts as invariant.
constexpr double kBreakdown = 1e-8;

// Kuczynski-Wozniakowski constant of Theorem 4.2 (Lanczos, random start).
constexpr double kKwConstant = 1.648;

}  // namespace

bool LanczosOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& field, double value, const std::string& range) {
    if (error) {
      std::ostringstream out;
      out << field << " = " << value << " is not allowed: it must be " << range;
      *error = out.str();
    }
    return false;
  };
  if (!(failure_probability > 0.0 && failure_probability <= 0.1))
    return fail("failure_probability", failure_probability, "in (0, 0.1]");
  if (!(relative_tolerance > 0.0 && relative_tolerance < 0.5))
    return fail("relative_tolerance", relative_tolerance, "in (0, 0.5)");
  if (max_iterations < 2) return fail("max_iterations", max_iterations, ">= 2");
  if (exact_dimension < 0) return fail("exact_dimension", exact_dimension, ">= 0");
  if (reorthogonalisation_budget < 0)
    return fail("reorthogonalisation_budget", static_cast<double>(reorthogonalisation_budget),
                ">= 0");
  return true;
}

int KuczynskiWozniakowskiSteps(long long n, double failure_probability, double relative_tolerance) {
  const double log_term = std::log(kKwConstant * std::sqrt(static_cast<double>(std::max(1LL, n))) /
                                   failure_probability);
  return static_cast<int>(std::ceil((log_term / std::sqrt(relative_tolerance) + 1.0) / 2.0));
}

double KuczynskiWozniakowskiTolerance(long long n, double failure_probability, int steps) {
  const double log_term = std::log(kKwConstant * std::sqrt(static_cast<double>(std::max(1LL, n))) /
                                   failure_probability);
  const double root = log_term / (2.0 * steps - 1.0);
  return root * root;
}

LanczosResult LargestEigenvalue(int n, const SymmetricOperator& apply,
                                const LanczosOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("Lanczos: " + error);
  if (n < 1) throw InputError("Lanczos: the operator has no degrees of freedom");
  const auto start_time = std::chrono::steady_clock::now();
  const int threads = std::max(1, options.num_threads);
  LanczosResult result;
  result.dimension = n;
  result.failure_probability = options.failure_probability;

  // 1. How many steps: the KW count for the requested eps, at most n (then exact).
  int planned =
      KuczynskiWozniakowskiSteps(n, options.failure_probability, options.relative_tolerance);
  const bool reorthogonalise =
      static_cast<long long>(n) * (std::min(planned, n) + 1) <= options.reorthogonalisation_budget;
  if (!reorthogonalise) {
    // Finite precision without reorthogonalisation: allow for a 4 n dimension (header).
    planned = KuczynskiWozniakowskiSteps(4LL * n, options.failure_probability,
                                         options.relative_tolerance);
  }
  planned = std::min(planned, options.max_iterations);
  // Small systems: n steps cost little and make the Ritz value exact.
  if (reorthogonalise && n <= options.exact_dimension) planned = n;
  const int steps_cap = reorthogonalise ? std::min(planned, n) : planned;
  result.reorthogonalised = reorthogonalise;

  // 2. The recurrence.
  std::vector<std::vector<double>> basis;
  const bool store_single = options.compute_ritz_vector && !reorthogonalise &&
                            static_cast<long long>(n) * steps_cap <= options.ritz_storage_budget;
  std::vector<std::vector<float>> single_basis;
  std::vector<double> v = RandomUnitVector(n, options.seed), v_previous(n, 0.0), w(n);
  const std::vector<double> start = v;
  std::vector<double> alpha, beta;  // beta[j] couples v_j and v_{j+1}
  double scale = 0.0;               // running estimate of |T|
  bool invariant = false;
  for (int j = 0; j < steps_cap; ++j) {
    if (reorthogonalise) basis.push_back(v);
    if (store_single) single_basis.emplace_back(v.begin(), v.end());
    apply(v, w);
    const double applied_norm = std::sqrt(Dot(w, w, threads));
    const double a = Dot(v, w, threads);
    alpha.push_back(a);
    Axpy(-a, v, w, threads);
    if (j > 0) Axpy(-beta[j - 1], v_previous, w, threads);
    if (reorthogonalise) {
      for (int pass = 0; pass < 2; ++pass)
        for (const std::vector<double>& q : basis) Axpy(-Dot(q, w), q, w);
    }
    const double b = std::sqrt(Dot(w, w, threads));
    scale = std::max({scale, std::abs(a), b});
    if (options.progress)
      options.progress(static_cast<double>(j + 1) / steps_cap, options.progress_label);
    if (j + 1 == steps_cap) {
      beta.push_back(b);
      break;
    }
    if (b <= kBreakdown * applied_norm) {
      // The Krylov space is invariant (to round-off: what is left of A v after removing its
      // components in the space is cancellation noise; continuing would build vectors the
      // three-term recurrence does not describe). Its Ritz values are eigenvalues, and the
      // random start has a component along every eigenvector, so the largest is lambda_max.
      beta.push_back(0.0);
      invariant = true;
      break;
    }
    beta.push_back(b);
    v_previous.swap(v);
    Divide(w, b, v, threads);
  }
  const int k = static_cast<int>(alpha.size());
  result.iterations = k;

  // 3. The tridiagonal eigenproblem.
  // (Dense: the tridiagonal QL path of Eigen can stop short of convergence when the
  // off-diagonal spans many decades, as it does after a near-invariant subspace.)
  Eigen::MatrixXd t = Eigen::MatrixXd::Zero(k, k);
  for (int j = 0; j < k; ++j) t(j, j) = alpha[j];
  for (int j = 0; j + 1 < k; ++j) t(j, j + 1) = t(j + 1, j) = beta[j];
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> tridiagonal(t);
  if (tridiagonal.info() != Eigen::Success)
    throw ComputationError("Lanczos: the eigenvalues of the " + std::to_string(k) + " x " +
                           std::to_string(k) + " tridiagonal matrix did not converge");
  const Eigen::VectorXd s = tridiagonal.eigenvectors().col(k - 1);
  result.ritz_value = std::max(0.0, tridiagonal.eigenvalues()[k - 1]);
  result.residual_norm = std::abs(beta[k - 1] * s[k - 1]);

  // 4. The certificate.
  result.exact = invariant || (reorthogonalise && k == n);
  if (result.exact) {
    result.relative_tolerance = 0.0;
    // Round-off of the recurrence (the breakdown threshold), relative to |A|.
    result.certified_upper_bound = result.ritz_value + 10.0 * kBreakdown * scale;
  } else {
    result.relative_tolerance = KuczynskiWozniakowskiTolerance(reorthogonalise ? n : 4LL * n,
                                                               options.failure_probability, k);
    if (result.relative_tolerance >= 1.0) {
      result.certified_upper_bound = std::numeric_limits<double>::infinity();
    } else {
      result.certified_upper_bound = result.ritz_value / (1.0 - result.relative_tolerance);
    }
  }

  // 5. The Ritz vector y = sum_j s_j v_j.
  if (options.compute_ritz_vector) {
    std::vector<double> y(n, 0.0);
    if (reorthogonalise) {
      for (int j = 0; j < k; ++j) Axpy(s[j], basis[j], y);
    } else if (store_single) {
      for (int j = 0; j < k; ++j) {
        const float* q = single_basis[j].data();
        const double c = s[j];
        for (int i = 0; i < n; ++i) y[i] += c * q[i];
      }
    } else {
      // Second pass: the same recurrence with the stored coefficients.
      std::vector<double> q = start, q_previous(n, 0.0), z(n);
      for (int j = 0; j < k; ++j) {
        Axpy(s[j], q, y);
        if (j + 1 == k) break;
        apply(q, z);
        Axpy(-alpha[j], q, z);
        if (j > 0) Axpy(-beta[j - 1], q_previous, z);
        q_previous.swap(q);
        for (int i = 0; i < n; ++i) q[i] = z[i] / beta[j];
      }
    }
    const double norm = std::sqrt(Dot(y, y));
    if (norm > 0.0)
      for (double& x : y) x /= norm;
    result.ritz_vector = std::move(y);
  }
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return result;
}

ConjugateGradientResult ConjugateGradient(const SymmetricOperator& apply,
                                          const std::vector<double>& b, double relative_tolerance,
                                          int max_iterations, std::vector<double>* x,
                                          ConjugateGradientWorkspace* workspace, int threads) {
  const int n = static_cast<int>(b.size());
  ConjugateGradientResult result;
  x->assign(n, 0.0);
  const double b_norm = std::sqrt(Dot(b, b, threads));
  if (b_norm == 0.0) {
    result.converged = true;
    return result;
  }
  ConjugateGradientWorkspace local;
  ConjugateGradientWorkspace& work = workspace ? *workspace : local;
  std::vector<double>& r = work.residual;
  std::vector<double>& p = work.direction;
  std::vector<double>& q = work.product;
  r = b;
  p = b;
  q.resize(n);
  double rr = b_norm * b_norm;
  const double target = relative_tolerance * relative_tolerance * rr;
  for (int iteration = 1; iteration <= max_iterations; ++iteration) {
    apply(p, q);
    const double pq = Dot(p, q, threads);
    if (!(pq > 0.0)) break;  // not positive definite (or breakdown)
    const double step = rr / pq;
    Axpy(step, p, *x, threads);
    Axpy(-step, q, r, threads);
    const double rr_new = Dot(r, r, threads);
    result.iterations = iteration;
    result.relative_residual = std::sqrt(rr_new) / b_norm;
    if (rr_new <= target) {
      result.converged = true;
      break;
    }
    const double ratio = rr_new / rr;
    Direction(r, ratio, p, threads);
    rr = rr_new;
  }
  return result;
}

std::array<ConjugateGradientResult, 2> ConjugateGradientPair(
    const SymmetricOperatorPair& apply_pair, const std::vector<double>& b1,
    const std::vector<double>& b2, double relative_tolerance, int max_iterations,
    std::vector<double>* x1, std::vector<double>* x2, ConjugateGradientPairWorkspace* workspace,
    int threads) {
  std::array<ConjugateGradientResult, 2> result;
  ConjugateGradientPairWorkspace local;
  ConjugateGradientPairWorkspace& work = workspace ? *workspace : local;
  const std::vector<double>* b[2] = {&b1, &b2};
  std::vector<double>* x[2] = {x1, x2};
  ConjugateGradientWorkspace* w[2] = {&work.first, &work.second};
  double rr[2], target[2], b_norm[2];
  bool active[2];
  for (int k = 0; k < 2; ++k) {
    const int n = static_cast<int>(b[k]->size());
    x[k]->assign(n, 0.0);
    b_norm[k] = std::sqrt(Dot(*b[k], *b[k], threads));
    active[k] = b_norm[k] > 0.0;
    result[k].converged = !active[k];
    w[k]->residual = *b[k];
    w[k]->direction = *b[k];
    w[k]->product.resize(n);
    rr[k] = b_norm[k] * b_norm[k];
    target[k] = relative_tolerance * relative_tolerance * rr[k];
  }
  for (int iteration = 1; iteration <= max_iterations && (active[0] || active[1]); ++iteration) {
    // Converged systems ride along (their products are not used).
    apply_pair(w[0]->direction, w[1]->direction, w[0]->product, w[1]->product);
    for (int k = 0; k < 2; ++k) {
      if (!active[k]) continue;
      std::vector<double>& r = w[k]->residual;
      std::vector<double>& p = w[k]->direction;
      const std::vector<double>& q = w[k]->product;
      const double pq = Dot(p, q, threads);
      if (!(pq > 0.0)) {
        active[k] = false;  // not positive definite (or breakdown): not converged
        continue;
      }
      const double step = rr[k] / pq;
      Axpy(step, p, *x[k], threads);
      Axpy(-step, q, r, threads);
      const double rr_new = Dot(r, r, threads);
      result[k].iterations = iteration;
      result[k].relative_residual = std::sqrt(rr_new) / b_norm[k];
      if (rr_new <= target[k]) {
        result[k].converged = true;
        active[k] = false;
        continue;
      }
      const double ratio = rr_new / rr[k];
      Direction(r, ratio, p, threads);
      rr[k] = rr_new;
    }
  }
  return result;
}

}  // namespace specimen
