// The numerical core of the stability analysis: Lanczos with its certificate against dense
// eigenvalues (stability_lanczos.h), conjugate gradients, and the matrix-free network
// operators (stability_network.h) against an independent dense assembly.

#include "solver/stability_lanczos.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>

#include "solver/regular_lattice.h"
#include "solver/stability_network.h"

namespace specimen {
namespace {

SymmetricOperator DenseOperator(const Eigen::MatrixXd& a) {
  return [a](const std::vector<double>& x, std::vector<double>& y) {
    y.resize(x.size());
    Eigen::Map<Eigen::VectorXd>(y.data(), y.size()) =
        a * Eigen::Map<const Eigen::VectorXd>(x.data(), x.size());
  };
}

// A random symmetric positive semi-definite matrix Q diag(lambda) Q^T.
Eigen::MatrixXd RandomMatrix(int n, const Eigen::VectorXd& spectrum, unsigned seed) {
  std::mt19937 engine(seed);
  std::normal_distribution<double> gaussian;
  Eigen::MatrixXd g(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) g(i, j) = gaussian(engine);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(g);
  const Eigen::MatrixXd q = qr.householderQ();
  return q * spectrum.asDiagonal() * q.transpose();
}

TEST(Lanczos, ExactForSmallSystemsAndCertifiedForLargeOnes) {
  // Small: n steps, exact.
  Eigen::VectorXd small(40);
  for (int i = 0; i < 40; ++i) small[i] = 1.0 + i;
  const LanczosResult exact =
      LargestEigenvalue(40, DenseOperator(RandomMatrix(40, small, 1)), LanczosOptions());
  EXPECT_TRUE(exact.exact);
  EXPECT_NEAR(exact.ritz_value, 40.0, 1e-9);
  EXPECT_GE(exact.certified_upper_bound, 40.0);
  // Larger than the exact-mode limit, with a spectrum crowded below the top: the Ritz value
  // is below lambda_max, the certified bound above it, eps apart.
  const int n = 700;
  Eigen::VectorXd spectrum(n);
  for (int i = 0; i < n; ++i) spectrum[i] = 1.0 + 1e-3 * i;  // top 1.699, gaps 1e-3
  LanczosOptions options;
  options.relative_tolerance = 0.01;
  const LanczosResult r =
      LargestEigenvalue(n, DenseOperator(RandomMatrix(n, spectrum, 2)), options);
  const double top = spectrum[n - 1];
  EXPECT_FALSE(r.exact);
  EXPECT_LE(r.ritz_value, top * (1.0 + 1e-12));
  EXPECT_GE(r.certified_upper_bound, top);
  EXPECT_NEAR(r.certified_upper_bound / r.ritz_value, 1.0 / (1.0 - r.relative_tolerance), 1e-12);
  EXPECT_LE(r.relative_tolerance, 0.01);
  EXPECT_EQ(r.iterations, KuczynskiWozniakowskiSteps(n, 1e-6, 0.01));
  // The KW count and tolerance are inverse.
  EXPECT_LE(KuczynskiWozniakowskiTolerance(n, 1e-6, r.iterations), 0.01);
}

TEST(Lanczos, DegenerateSpectrumAndBreakdown) {
  // Eigenvalues 0 (30 times), 1, 2, 3 (10 times each), 100 once: the Krylov space closes
  // after 5 steps; the Ritz value is exact (a regression test: the QL tridiagonal solver
  // stopped short on such a recurrence).
  Eigen::VectorXd spectrum = Eigen::VectorXd::Zero(61);
  for (int i = 30; i < 60; ++i) spectrum[i] = 1.0 + (i - 30) / 10;
  spectrum[60] = 100.0;
  const LanczosResult r =
      LargestEigenvalue(61, DenseOperator(RandomMatrix(61, spectrum, 3)), LanczosOptions());
  EXPECT_TRUE(r.exact);
  EXPECT_NEAR(r.ritz_value, 100.0, 1e-8);
  EXPECT_LE(r.iterations, 6);
}

TEST(Lanczos, RejectsInvalidOptions) {
  LanczosOptions options;
  options.relative_tolerance = 0.7;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("relative_tolerance = 0.7"), std::string::npos) << error;
}

TEST(ConjugateGradient, SolvesASymmetricPositiveDefiniteSystem) {
  Eigen::VectorXd spectrum(50);
  for (int i = 0; i < 50; ++i) spectrum[i] = 1.0 + 0.1 * i;
  const Eigen::MatrixXd a = RandomMatrix(50, spectrum, 4);
  std::vector<double> b(50, 1.0), x;
  const ConjugateGradientResult r = ConjugateGradient(DenseOperator(a), b, 1e-12, 200, &x);
  EXPECT_TRUE(r.converged);
  const Eigen::VectorXd residual =
      a * Eigen::Map<Eigen::VectorXd>(x.data(), 50) - Eigen::VectorXd::Ones(50);
  EXPECT_LT(residual.norm(), 1e-10);
}

// An independent dense assembly of M^-1/2 K M^-1/2 for 2D discs with rotations: per link the
// relative contact-point displacement d = (u_j + theta_j x s_j) - (u_i + theta_i x s_i),
// s_i = R_i n, s_j = -R_j n; K = sum kn (n.d)^2 + kt |d_t|^2 (as quadratic forms).
// Particle dofs (x, y, theta) in packing order; walls: springs to ground on their particles.
Eigen::MatrixXd DenseScaledStiffness(const Packing<2>& packing, double kn, double kt,
                                     double density, const std::vector<int>& wall_particles,
                                     const Vector<2>& wall_normal, double k_wall,
                                     const std::vector<int>& fixed_x) {
  const int n = packing.size();
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  auto add = [&](int i, int j, const Vector<2>& normal, double k_normal, double k_tangent) {
    // d = L q over the dofs of i (and j).
    Eigen::MatrixXd l = Eigen::MatrixXd::Zero(2, 3 * n);
    const Vector<2> t(-normal.y(), normal.x());
    const double ri = packing.radii[i];
    l(0, 3 * i) = -1;
    l(1, 3 * i + 1) = -1;
    // -theta_i x (R_i n) = -R_i theta_i t
    l.col(3 * i + 2) = -ri * t;
    if (j >= 0) {
      const double rj = packing.radii[j];
      l(0, 3 * j) = 1;
      l(1, 3 * j + 1) = 1;
      l.col(3 * j + 2) = -rj * t;  // theta_j x (-R_j n) = -R_j theta_j t
    }
    const Eigen::Matrix2d spring =
        k_normal * normal * normal.transpose() + k_tangent * t * t.transpose();
    k += l.transpose() * spring * l;
  };
  for (const auto& [i, j] : packing.contacts) {
    const Vector<2> branch = packing.centres[j] - packing.centres[i];
    add(i, j, branch.normalized(), kn, kt);
  }
  for (const int p : wall_particles) add(p, -1, -wall_normal, k_wall, 0.0);
  std::vector<int> keep;
  std::vector<double> mass;
  for (int p = 0; p < n; ++p) {
    const double r = packing.radii[p];
    const double m = density * M_PI * r * r;
    for (int a = 0; a < 3; ++a) {
      if (a == 0 && std::count(fixed_x.begin(), fixed_x.end(), p)) continue;
      keep.push_back(3 * p + a);
      mass.push_back(a < 2 ? m : 0.5 * m * r * r);
    }
  }
  Eigen::MatrixXd a(keep.size(), keep.size());
  for (size_t r = 0; r < keep.size(); ++r)
    for (size_t c = 0; c < keep.size(); ++c)
      a(r, c) = k(keep[r], keep[c]) / std::sqrt(mass[r] * mass[c]);
  return a;
}

TEST(LinearisedNetwork, StiffnessMatchesAnIndependentAssembly) {
  // Madan's HCP specimen, kt = kn/2, a wall under the bottom row 10 times stiffer, the middle
  // discs held in x.
  const double kn = 7e10, kt = 3.5e10, density = 2000;
  const Packing<2> packing = HexagonalLatticePacking(7, 4, 5, 1e-3);
  SceneOptions<2> scene;
  scene.material.normal_stiffness_n_per_m = kn;
  scene.material.tangential_stiffness_n_per_m = kt;
  scene.material.density_kg_per_m3 = density;
  WallOptions<2> wall;
  wall.name = "bottom";
  wall.normal = Vector<2>(0, 1);
  wall.point = Vector<2>(0, -1e-3);
  wall.normal_stiffness_n_per_m = 10 * kn;
  scene.walls = {wall};
  FixedDofs<2> held;
  held.name = "middle";
  held.particles = {6, 15};
  held.fix_translation = {true, false};
  scene.fixed_dofs = {held};
  const LinearisedNetwork<2> network(packing, scene);
  std::vector<int> bottom;
  for (int p = 0; p < packing.size(); ++p)
    if (packing.centres[p].y() < 1e-9) bottom.push_back(p);
  ASSERT_EQ(network.wall_links(), static_cast<int>(bottom.size()));
  const Eigen::MatrixXd expected =
      DenseScaledStiffness(packing, kn, kt, density, bottom, Vector<2>(0, 1), 10 * kn, {6, 15});
  const int n = network.dof_count();
  ASSERT_EQ(n, expected.rows());
  // The network numbers its dofs along a space-filling curve: compare invariants (the
  // spectrum) and the Lanczos result.
  Eigen::MatrixXd a(n, n);
  std::vector<double> e(n, 0.0), y;
  for (int c = 0; c < n; ++c) {
    e[c] = 1.0;
    network.ApplyScaledStiffness(e, y);
    e[c] = 0.0;
    for (int r = 0; r < n; ++r) a(r, c) = y[r];
  }
  EXPECT_LT((a - a.transpose()).norm(), 1e-12 * a.norm());
  const Eigen::VectorXd lambda = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(a).eigenvalues();
  const Eigen::VectorXd reference =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(expected).eigenvalues();
  EXPECT_LT((lambda - reference).cwiseAbs().maxCoeff(), 1e-9 * reference.maxCoeff());
  const LanczosResult r = LargestEigenvalue(
      n,
      [&](const std::vector<double>& x, std::vector<double>& out) {
        network.ApplyScaledStiffness(x, out);
      },
      LanczosOptions());
  EXPECT_NEAR(r.ritz_value, reference.maxCoeff(), 1e-9 * reference.maxCoeff());
  EXPECT_GE(network.GershgorinBound(), reference.maxCoeff());
}

TEST(LinearisedNetwork, DdemOperatorIsSymmetricAndMatchesTheRowFormula) {
  // A row of 40 discs (plane strain): M = (R^2/V) (n n):D:(n n) at both ends, B = kn M;
  // the infinite row has rho(B) = 4 kn (1 - nu^2) / (pi Ep) (Madan (3.27)); a finite row
  // comes close from below.
  Packing<2> row = SquareLatticePacking(40, 1, 1e-3);
  SceneOptions<2> scene;
  scene.material.normal_stiffness_n_per_m = 7e10;
  scene.material.density_kg_per_m3 = 2000;
  const LinearisedNetwork<2> network(row, scene);
  const double nu = 0.35;
  const ParticleCompliance<2> unit(1.0, nu, PlaneModel::kPlaneStrain);
  const int links = network.link_count();
  Eigen::MatrixXd s(links, links);
  std::vector<double> e(links, 0.0), y;
  for (int c = 0; c < links; ++c) {
    e[c] = 1.0;
    network.ApplyDdemOperator(unit, e, y);
    e[c] = 0.0;
    for (int r = 0; r < links; ++r) s(r, c) = y[r];
  }
  EXPECT_LT((s - s.transpose()).norm(), 1e-12 * s.norm());
  const double lambda = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(s).eigenvalues().maxCoeff();
  const double infinite = 4 * 7e10 * (1 - nu * nu) / M_PI;  // rho(B) x Ep
  EXPECT_LT(lambda, infinite);
  EXPECT_GT(lambda, 0.99 * infinite);
}

}  // namespace
}  // namespace specimen
