// The six-spring lattice on a generated packing: every triangle of the Delaunay triangulation
// carries the natural stiffness of its own geometry, so a homogeneous strain gives the exact
// stress to round-off (the patch test), and a uniaxial test by central differences with
// lumped masses returns the input E and nu (isotropic, plane strain and plane stress) and the
// input moduli of an orthotropic material along both axes and at 45 degrees. Expected values
// are the input constants and closed forms, never numbers this code produced.

#include "solver/lattice_packing.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include "common/error.h"
#include "generator/generate.h"
#include "solver/lattice_stability.h"
#include "tests/solver/lattice_dynamics.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kSide = 0.03;  // 30 mm square

const Packing<2>& SquarePacking() {
  static const Packing<2> packing = [] {
    GeneratorOptions options = DefaultGeneratorOptions<2>();
    options.particle_count = 800;
    options.seed = 3;
    return GeneratePacking<2>(Domain<2>::Rectangle(0.0, 0.0, kSide, kSide), options, nullptr);
  }();
  return packing;
}

double MeanRadius() { return VolumeMeanRadius<2>(SquarePacking().radii); }

std::vector<Vector<2>> Homogeneous(const std::vector<Vector<2>>& nodes, const Eigen::Vector3d& strain) {
  std::vector<Vector<2>> u;  // u = eps x, Voigt strain
  for (const Vector<2>& x : nodes)
    u.push_back({strain[0] * x.x() + 0.5 * strain[2] * x.y(), 0.5 * strain[2] * x.x() + strain[1] * x.y()});
  return u;
}

TEST(LatticePacking, SurfaceNodesFillTheSquare) {
  const Packing<2>& packing = SquarePacking();
  PackingLatticeSummary summary;
  const PackingLattice lattice = BuildPackingLattice(
      packing, IsotropicPlaneElasticity(30e9, 0.2, PlaneModel::kPlaneStrain), 1.0, {}, &summary);
  EXPECT_EQ(summary.triangles, lattice.triangles.size());
  EXPECT_EQ(lattice.particle_nodes, packing.size());
  EXPECT_EQ(summary.surface_nodes, lattice.node_count() - packing.size());
  EXPECT_EQ(summary.free_nodes, 0) << summary.Describe();
  // Every surface node on a side; the four corners among them; the area is the square's.
  int corners = 0;
  for (int k = lattice.particle_nodes; k < lattice.node_count(); ++k) {
    const Vector<2>& x = lattice.nodes[k];
    const double to_side = std::min({x.x(), x.y(), kSide - x.x(), kSide - x.y()});
    EXPECT_LT(std::abs(to_side), 1e-12 * kSide) << "surface node " << k;
    corners += std::min(x.x(), kSide - x.x()) < 0.25 * MeanRadius() && std::min(x.y(), kSide - x.y()) < 0.25 * MeanRadius();
  }
  EXPECT_EQ(corners, 4);
  EXPECT_NEAR(summary.covered_area_m2, kSide * kSide, 1e-12 * kSide * kSide) << summary.Describe();
  EXPECT_GT(summary.smallest_angle_deg, 0.0);
}

TEST(LatticePacking, WithoutSurfaceNodesOnlyHullSliversAreCut) {
  const Packing<2>& packing = SquarePacking();
  PackingLatticeOptions options;
  options.surface_nodes = false;
  PackingLatticeSummary summary;
  const TriangleLattice lattice =
      BuildPackingLattice(packing, IsotropicPlaneElasticity(30e9, 0.2, PlaneModel::kPlaneStrain), 1.0, options, &summary)
          .triangles;
  EXPECT_GT(summary.hull_slivers_removed, 0);
  // A corner particle may lose every triangle it had.
  EXPECT_LE(summary.free_nodes, 4) << summary.Describe();
  // The hull of the centres lies about one radius inside the square.
  const double inner = kSide - 2.0 * MeanRadius();
  EXPECT_GT(summary.covered_area_m2, 0.9 * inner * inner) << summary.Describe();
  EXPECT_LT(summary.covered_area_m2, kSide * kSide);
  // Euler on a triangulated disc: T = 2 N - 2 - B (B hull nodes), so T < 2 N.
  EXPECT_LT(lattice.size(), 2 * packing.size());

  // No hull triangle of the result is a sliver.
  std::map<std::pair<int, int>, int> edge_count;
  for (const auto& v : lattice.nodes)
    for (int k = 0; k < 3; ++k) ++edge_count[std::minmax(v[k], v[(k + 1) % 3])];
  for (int t = 0; t < lattice.size(); ++t) {
    bool hull = false;
    for (int k = 0; k < 3; ++k) hull |= edge_count[std::minmax(lattice.nodes[t][k], lattice.nodes[t][(k + 1) % 3])] == 1;
    if (!hull) continue;
    const auto& v = lattice.nodes[t];
    for (int k = 0; k < 3; ++k) {
      const Vector<2> a = packing.centres[v[(k + 1) % 3]] - packing.centres[v[k]];
      const Vector<2> b = packing.centres[v[(k + 2) % 3]] - packing.centres[v[k]];
      const double angle = std::atan2(std::abs(a.x() * b.y() - a.y() * b.x()), a.dot(b)) * 180.0 / kPi;
      EXPECT_GE(angle, options.min_hull_angle_deg - 1e-9) << "hull triangle " << t;
    }
  }
}

TEST(LatticePacking, HomogeneousStrainGivesTheExactStressToRoundOff) {  // patch test
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Packing<2>& packing = SquarePacking();
  for (int trial = 0; trial < 3; ++trial) {
    // Isotropic, then two random positive definite D (anisotropic).
    PlaneElasticity d = IsotropicPlaneElasticity(40e9, 0.3, PlaneModel::kPlaneStrain);
    if (trial > 0) {
      Eigen::Matrix3d m;
      for (int i = 0; i < 9; ++i) m.data()[i] = unit(rng);
      const Eigen::Matrix3d dm = 1e10 * (m * m.transpose() + Eigen::Matrix3d::Identity());
      d = {dm(0, 0), dm(0, 1), dm(0, 2), dm(1, 1), dm(1, 2), dm(2, 2)};
    }
    const PackingLattice packing_lattice = BuildPackingLattice(packing, d, 1.0, {}, nullptr);
    const TriangleLattice& lattice = packing_lattice.triangles;
    const int n = packing_lattice.node_count();
    // Small enough that the stretch is linear in the strain to 1e-10.
    const Eigen::Vector3d strain = 1e-10 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    const Eigen::Vector3d exact = d.Matrix() * strain;
    const std::vector<Vector<2>> u = Homogeneous(packing_lattice.nodes, strain);
    for (int t = 0; t < lattice.size(); ++t) {
      EXPECT_LT((TriangleStrain(lattice, t, u) - strain).norm(), 1e-8 * strain.norm()) << "triangle " << t;
      EXPECT_LT((TriangleStress(lattice, t, u) - exact).norm(), 1e-8 * exact.norm()) << "triangle " << t;
    }
    // Interior nodes are in equilibrium: the triangles around them cancel.
    std::vector<Vector<2>> f(n, Vector<2>::Zero());
    AddTriangleForces(lattice, u, &f);
    std::map<std::pair<int, int>, int> edge_count;
    for (const auto& v : lattice.nodes)
      for (int k = 0; k < 3; ++k) ++edge_count[std::minmax(v[k], v[(k + 1) % 3])];
    std::vector<char> hull(n, 0);
    for (const auto& [edge, n] : edge_count)
      if (n == 1) hull[edge.first] = hull[edge.second] = 1;
    const double force_scale = exact.norm() * MeanRadius();  // stress x edge length x unit thickness
    int interior = 0;
    for (int i = 0; i < n; ++i) {
      if (hull[i]) continue;
      ++interior;
      EXPECT_LT(f[i].norm(), 1e-8 * force_scale) << "node " << i;
    }
    EXPECT_GE(interior, packing.size() / 2);
  }
}

// A uniaxial test on the lattice of the packing, solved by central differences with the
// row-sum lumped masses and viscous damping until static: the nodes on the bottom side of the
// square are held in y, those on the top side move down together by `shortening` (a rigid
// platen; x free, one corner held in x). Strain: the platen travel over the side; stress: the
// platen force over the side; lateral strain: the mean x displacement of the right side
// against the left.
struct UniaxialResult {
  double youngs_modulus = 0.0, poisson_ratio = 0.0;
  int steps = 0;
  bool converged = false;
};

UniaxialResult LatticeUniaxial(const PlaneElasticity& d, double density, double shortening) {
  const PackingLattice packing_lattice = BuildPackingLattice(SquarePacking(), d, 1.0, {}, nullptr);
  const TriangleLattice& lattice = packing_lattice.triangles;
  const std::vector<Vector<2>>& x = packing_lattice.nodes;
  const int n = packing_lattice.node_count();
  const std::vector<double> mass = LumpedMasses(lattice, n, density);
  const double on = 1e-12 * kSide;
  std::vector<char> bottom(n, 0), top(n, 0), left(n, 0), right(n, 0);
  int held_x = -1;
  for (int i = packing_lattice.particle_nodes; i < n; ++i) {
    bottom[i] = x[i].y() < on;
    top[i] = x[i].y() > kSide - on;
    left[i] = x[i].x() < on;
    right[i] = x[i].x() > kSide - on;
    if (bottom[i] && left[i]) held_x = i;
  }
  EXPECT_GE(held_x, 0);
  auto mean_over = [&](const std::vector<char>& set, auto value) {
    double sum = 0.0;
    int count = 0;
    for (int i = 0; i < n; ++i)
      if (set[i]) sum += value(i), ++count;
    return sum / count;
  };
  const double top_count = static_cast<double>(std::count(top.begin(), top.end(), 1));

  // Critical step from the Gershgorin bound of M^-1 K (each row's absolute sum over its mass).
  std::vector<double> row_sum(2 * n, 0.0);
  double stiffest = 0.0;
  for (int t = 0; t < lattice.size(); ++t) {
    const Eigen::Matrix<double, 6, 6> k = CartesianTriangleStiffness(lattice, t);
    for (int a = 0; a < 6; ++a) row_sum[2 * lattice.nodes[t][a / 2] + a % 2] += k.row(a).cwiseAbs().sum();
  }
  for (int i = 0; i < 2 * n; ++i)
    if (mass[i / 2] > 0.0) stiffest = std::max(stiffest, row_sum[i] / mass[i / 2]);
  const double dt = 0.9 * 2.0 / std::sqrt(stiffest);
  // Viscous damping pi c / (4 H), well below the first axial mode's pi c / H: the slowest mode,
  // the flexure of the free sides, lies far lower and would creep under critical damping of
  // the axial one (twice as many steps at twice this damping).
  const double wave_speed = std::sqrt(std::max(d.d11, d.d22) / density);
  const double damping = 0.25 * kPi * wave_speed / kSide;

  std::vector<Vector<2>> u(n, Vector<2>::Zero()), v(n, Vector<2>::Zero()), f(n);
  for (int i = 0; i < n; ++i)
    if (top[i]) u[i].y() = -shortening;
  UniaxialResult result;
  double platen_force = 0.0;
  for (result.steps = 1; result.steps <= 200000; ++result.steps) {
    std::fill(f.begin(), f.end(), Vector<2>::Zero());
    AddTriangleForces(lattice, u, &f);
    double residual = 0.0;
    platen_force = 0.0;
    for (int i = 0; i < n; ++i) {
      Vector<2> force = f[i];
      if (top[i]) platen_force += f[i].y();  // the compressed triangles push the platen up
      if (bottom[i] || top[i]) force.y() = 0.0;
      if (i == held_x) force.x() = 0.0;
      residual = std::max(residual, force.norm());
      v[i] = ((1.0 - 0.5 * damping * dt) * v[i] + dt * force / mass[i]) / (1.0 + 0.5 * damping * dt);
      u[i] += dt * v[i];
    }
    // Static: no free degree of freedom carries more than 1e-10 of a platen node's mean force.
    if (result.steps > 100 && residual < 1e-10 * std::abs(platen_force) / top_count) {
      result.converged = true;
      break;
    }
  }
  const double axial_strain = shortening / kSide;
  const double lateral_strain =
      (mean_over(right, [&](int i) { return u[i].x(); }) - mean_over(left, [&](int i) { return u[i].x(); })) / kSide;
  result.youngs_modulus = platen_force / kSide / axial_strain;
  result.poisson_ratio = lateral_strain / axial_strain;
  return result;
}

TEST(LatticePacking, UniaxialTestReturnsTheInputConstants) {
  struct Case {
    double nu;
    PlaneModel model;
  };
  for (const Case c : {Case{0.0, PlaneModel::kPlaneStrain}, Case{0.2, PlaneModel::kPlaneStrain},
                       Case{0.45, PlaneModel::kPlaneStrain}, Case{0.3, PlaneModel::kPlaneStress}}) {
    const double e = 30e9;
    const UniaxialResult r = LatticeUniaxial(IsotropicPlaneElasticity(e, c.nu, c.model), 2500.0, 1e-6 * kSide);
    ASSERT_TRUE(r.converged) << "nu " << c.nu << " after " << r.steps << " steps";
    // The plane strain uniaxial response: E' = E / (1 - nu^2), nu' = nu / (1 - nu).
    const double e2d = c.model == PlaneModel::kPlaneStrain ? e / (1.0 - c.nu * c.nu) : e;
    const double nu2d = c.model == PlaneModel::kPlaneStrain ? c.nu / (1.0 - c.nu) : c.nu;
    // The specimen is the square itself, so the homogeneous state is the exact solution: the
    // measured constants are the input ones to the relaxation's residual.
    EXPECT_NEAR(r.youngs_modulus / e2d, 1.0, 1e-6) << "nu " << c.nu;
    EXPECT_NEAR(r.poisson_ratio, nu2d, 1e-6) << "nu " << c.nu;
  }
}

TEST(LatticePacking, OrthotropicModuliAlongBothAxesAndAt45Degrees) {
  OrthotropicConstants o;
  o.youngs_modulus_1_pa = 60e9;
  o.youngs_modulus_2_pa = 20e9;
  o.poisson_ratio_12 = 0.25;
  o.shear_modulus_12_pa = 12e9;
  // The test loads along y: material axis 1 at 90 degrees puts E1 along the load.
  struct Case {
    double angle_deg, expected_modulus;
  };
  const double s11 = 1.0 / o.youngs_modulus_1_pa, s22 = 1.0 / o.youngs_modulus_2_pa;
  const double s12 = -o.poisson_ratio_12 / o.youngs_modulus_1_pa, s66 = 1.0 / o.shear_modulus_12_pa;
  // Off-axis modulus at 45 degrees: 1/E = (s11 + s22 + 2 s12 + s66) / 4.
  const double e45 = 4.0 / (s11 + s22 + 2.0 * s12 + s66);
  for (const Case c : {Case{90.0, o.youngs_modulus_1_pa}, Case{0.0, o.youngs_modulus_2_pa}, Case{45.0, e45}}) {
    o.axis_angle_rad = c.angle_deg * kPi / 180.0;
    const UniaxialResult r =
        LatticeUniaxial(OrthotropicPlaneElasticity(o, PlaneModel::kPlaneStress), 2500.0, 1e-6 * kSide);
    ASSERT_TRUE(r.converged) << c.angle_deg << " deg";
    EXPECT_NEAR(r.youngs_modulus / c.expected_modulus, 1.0, 1e-6) << c.angle_deg << " deg";
  }
}

// The critical step of the Lanczos analysis against bisection by real runs: central
// differences from a random field stay bounded at 0.99 of it and diverge at 1.01.
TEST(LatticePacking, CriticalTimeStepMatchesBisection) {
  const double density = 2500.0;
  for (double nu : {0.0, 0.3, 0.45}) {
    const PackingLattice lattice = BuildPackingLattice(
        SquarePacking(), IsotropicPlaneElasticity(30e9, nu, PlaneModel::kPlaneStrain), 1.0, {}, nullptr);
    const int n = lattice.node_count();
    const LatticeStability s = AnalyseLatticeStability(lattice.triangles, LumpedMasses(lattice.triangles, n, density), {});
    EXPECT_GT(s.critical_time_step_s, 0.0);
    EXPECT_LE(s.gershgorin_time_step_s, s.critical_time_step_s * (1.0 + 1e-12));
    // The certified bound lies within its tolerance of the Ritz value.
    EXPECT_NEAR(s.omega_max_squared / s.lanczos.ritz_value, 1.0, 0.005);
    EXPECT_LT(CentralDifferenceGrowth(lattice.triangles, n, density, 0.99 * s.critical_time_step_s, 4000), 1e-7)
        << "nu " << nu;
    EXPECT_GT(CentralDifferenceGrowth(lattice.triangles, n, density, 1.01 * s.critical_time_step_s, 4000), 1e-3)
        << "nu " << nu;
  }
}

TEST(LatticePacking, BadInputIsRefused) {
  const PlaneElasticity d = IsotropicPlaneElasticity(30e9, 0.2, PlaneModel::kPlaneStress);
  PackingLatticeOptions options;
  options.min_hull_angle_deg = 50.0;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("min_hull_angle_deg"), std::string::npos);
  EXPECT_THROW(BuildPackingLattice(SquarePacking(), d, 1.0, options, nullptr), InputError);
  options = PackingLatticeOptions{};
  options.surface_gap = -0.1;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("surface_gap"), std::string::npos);
  EXPECT_THROW(BuildPointLattice({{0.0, 0.0}, {1.0, 0.0}}, d, 1.0, {}, nullptr), InputError);
  EXPECT_THROW(BuildPointLattice({{0.0, 0.0}, {1.0, 0.0}, {2.0, 0.0}}, d, 1.0, {}, nullptr), InputError);
}

}  // namespace
}  // namespace specimen
