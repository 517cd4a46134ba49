#pragma once
// The largest eigenvalue of a symmetric positive semi-definite operator, applied matrix-free,
// with a certified upper bound: the numerical core of the stability limits
// (stability_limits.h), used for omega_max^2 of the bonded network, rho(B) of the DDEM force
// iteration and the DDEM-reduced critical time step.
//
// Method: Lanczos from a random start (Gaussian, seeded: reproducible).
//  - Lower bound: the largest Ritz value theta_k is a Rayleigh quotient, theta_k <= lambda_max,
//    always (it is the unsafe side for a time step: 2/sqrt(theta) >= 2/omega_max).
//  - Upper bound: Kuczynski & Wozniakowski (SIAM J. Matrix Anal. Appl. 13(4), 1992, Thm 4.2):
//    for a symmetric positive semi-definite n x n matrix and a start uniformly distributed on
//    the sphere, after k steps
//        P[ theta_k < (1 - eps) lambda_max ] <= 1.648 sqrt(n) exp(-sqrt(eps) (2k - 1)),
//    whatever the spectrum (no gap assumption). The iteration count is chosen so that this
//    failure probability is at most `failure_probability` for eps = `relative_tolerance`, and
//    the certified bound is theta_k / (1 - eps): above lambda_max except with probability
//    <= delta (1e-6 by default). When the Krylov space becomes invariant or k reaches n
//    (small systems) the Ritz value is exact and eps = 0.
//  - Finite precision: with full reorthogonalisation (classical Gram-Schmidt, twice) the
//    computed recurrence is the exact one to round-off. Above `reorthogonalisation_budget`
//    stored numbers the plain three-term recurrence runs instead; finite-precision Lanczos then
//    behaves as exact Lanczos on a matrix whose eigenvalues lie in tiny intervals around those
//    of A (Greenbaum 1989; Druskin & Knizhnerman 1991), so the Chebyshev-type bound above still
//    governs the largest Ritz value, with n replaced by a slightly larger dimension (a factor
//    4 on n is allowed for).
//  - The Ritz residual |A y - theta y| = beta_k |s_k| is reported: an eigenvalue lies within it
//    of theta (it says how converged the top mode is; the certificate does not rely on it).
// Also: conjugate gradients for the symmetric positive definite inner solves.

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "common/progress.h"

namespace specimen {

// y = A x for vectors of length n (x and y never alias).
using SymmetricOperator = std::function<void(const std::vector<double>& x, std::vector<double>& y)>;

struct LanczosOptions {
  // delta: probability that the certified bound is below lambda_max, in (0, 0.1].
  double failure_probability = 1e-6;
  // eps: relative gap between the certified bound and the Ritz value, in (0, 0.5). Sets the
  // iteration count k = ceil((ln(1.648 sqrt(n) / delta) / sqrt(eps) + 1) / 2).
  double relative_tolerance = 0.004;
  // Iteration cap, >= 2; if it binds, eps is recomputed from the iterations done.
  int max_iterations = 600;
  // Seed of the random start.
  std::uint64_t seed = 20190601;
  // Full reorthogonalisation when n x (k + 1) stored numbers do not exceed this.
  long long reorthogonalisation_budget = 2'000'000;
  // Up to this dimension the iteration runs n steps (reorthogonalised): the result is exact.
  int exact_dimension = 600;
  // Return the Ritz vector of the largest Ritz value. Without reorthogonalisation the Lanczos
  // vectors are kept in single precision when n x steps does not exceed
  // `ritz_storage_budget` (the vector only locates the mode), else a second pass forms it.
  bool compute_ritz_vector = false;
  long long ritz_storage_budget = 64'000'000;
  ProgressCallback progress;  // may be empty
  std::string progress_label = "Lanczos";
  // Threads of the vector operations (sums in a fixed order: the result does not depend on
  // them).
  int num_threads = 1;

  bool IsValid(std::string* error) const;
};

struct LanczosResult {
  double ritz_value = 0.0;             // theta_k <= lambda_max
  double certified_upper_bound = 0.0;  // >= lambda_max with probability >= 1 - delta
  double relative_tolerance = 0.0;     // eps achieved (0: exact)
  double failure_probability = 0.0;    // delta
  double residual_norm = 0.0;          // |A y - theta y| for the unit Ritz vector y
  int iterations = 0;
  int dimension = 0;
  bool reorthogonalised = false;
  bool exact = false;  // invariant Krylov space or k = n: theta is lambda_max to round-off
  std::vector<double> ritz_vector;  // unit, when asked for
  double seconds = 0.0;
};

// The largest eigenvalue of the n x n symmetric positive semi-definite operator `apply`.
// Throws InputError for invalid options or n < 1.
LanczosResult LargestEigenvalue(int n, const SymmetricOperator& apply,
                                const LanczosOptions& options);

// The Lanczos step count for n, delta, eps (the formula of LanczosOptions::relative_tolerance).
int KuczynskiWozniakowskiSteps(long long n, double failure_probability, double relative_tolerance);
// The eps certified by k steps: (ln(1.648 sqrt(n) / delta) / (2k - 1))^2.
double KuczynskiWozniakowskiTolerance(long long n, double failure_probability, int steps);

struct ConjugateGradientResult {
  int iterations = 0;
  double relative_residual = 0.0;  // |b - A x| / |b| (recurrence value)
  bool converged = false;
};

// Work vectors of ConjugateGradient, kept between solves of the same size.
struct ConjugateGradientWorkspace {
  std::vector<double> residual, direction, product;
};

// Solves A x = b for a symmetric positive definite A by conjugate gradients from x = 0, until
// |r| <= relative_tolerance |b| or max_iterations. `workspace` may be null.
ConjugateGradientResult ConjugateGradient(const SymmetricOperator& apply,
                                          const std::vector<double>& b, double relative_tolerance,
                                          int max_iterations, std::vector<double>* x,
                                          ConjugateGradientWorkspace* workspace = nullptr,
                                          int threads = 1);

// Two independent systems A x1 = b1, A x2 = b2 solved side by side (the same iterates as two
// ConjugateGradient calls), with `apply_pair` forming both products in one pass. Each stops
// at its own tolerance; the iteration count is the larger one.
using SymmetricOperatorPair =
    std::function<void(const std::vector<double>& x1, const std::vector<double>& x2,
                       std::vector<double>& y1, std::vector<double>& y2)>;
struct ConjugateGradientPairWorkspace {
  ConjugateGradientWorkspace first, second;
};
std::array<ConjugateGradientResult, 2> ConjugateGradientPair(
    const SymmetricOperatorPair& apply_pair, const std::vector<double>& b1,
    const std::vector<double>& b2, double relative_tolerance, int max_iterations,
    std::vector<double>* x1, std::vector<double>* x2, ConjugateGradientPairWorkspace* workspace,
    int threads = 1);

}  // namespace specimen
