// The six-spring lattice (Kacianauskas & Vadluga 2009) against its oracles: the natural law
// equals the CST to round-off (O1), homogeneous strains are reproduced exactly on the regular
// lattice, uniaxial and biaxial (O2, O3), the eigenvalues and spring constants of the closed
// forms (O4, O5), the paper's example numbers (O9) and the exact stability limit of central
// differences on a periodic block (O6). Expected values are closed forms and the sources'
// tables, never numbers this code produced.

#include "solver/six_spring_lattice.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <random>

#include "common/error.h"
#include "solver/lattice_stability.h"
#include "tests/solver/lattice_dynamics.h"

namespace specimen {
namespace {

const double kSqrt3 = std::sqrt(3.0);

PlaneElasticity RandomAnisotropic(std::mt19937& rng) {
  // A random symmetric positive definite D: M M^T + I.
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Matrix3d m;
  for (int i = 0; i < 9; ++i) m.data()[i] = u(rng);
  const Eigen::Matrix3d d = m * m.transpose() + Eigen::Matrix3d::Identity();
  PlaneElasticity e;
  e.d11 = d(0, 0);
  e.d12 = d(0, 1);
  e.d13 = d(0, 2);
  e.d22 = d(1, 1);
  e.d23 = d(1, 2);
  e.d33 = d(2, 2);
  return e;
}

// CST stiffness A s B^T D B of triangle (a, b, c), Voigt strain, dofs (ax, ay, bx, by, cx, cy).
Eigen::Matrix<double, 6, 6> CstStiffness(const Vector<2>& a, const Vector<2>& b, const Vector<2>& c,
                                          const PlaneElasticity& d, double s) {
  const double area2 = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  const std::array<Vector<2>, 3> p = {a, b, c};
  Eigen::Matrix<double, 3, 6> bm = Eigen::Matrix<double, 3, 6>::Zero();
  for (int i = 0; i < 3; ++i) {
    const Vector<2>& pj = p[(i + 1) % 3];
    const Vector<2>& pk = p[(i + 2) % 3];
    const double dndx = (pj.y() - pk.y()) / area2, dndy = (pk.x() - pj.x()) / area2;
    bm(0, 2 * i) = dndx;
    bm(1, 2 * i + 1) = dndy;
    bm(2, 2 * i) = dndy;
    bm(2, 2 * i + 1) = dndx;
  }
  return 0.5 * std::abs(area2) * s * bm.transpose() * d.Matrix() * bm;
}

TEST(SixSpringLattice, NaturalStiffnessEqualsCstToRoundOff) {  // O1
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const PlaneElasticity d = RandomAnisotropic(rng);
    const std::vector<Vector<2>> x = {Vector<2>(u(rng), u(rng)), Vector<2>(2.0 + u(rng), u(rng)),
                                      Vector<2>(u(rng), 2.0 + u(rng))};
    const TriangleLattice lattice = BuildTriangleLattice(x, {{0, 1, 2}}, d, 0.01);
    const Eigen::Matrix<double, 6, 6> natural = CartesianTriangleStiffness(lattice, 0);
    // BuildTriangleLattice may reorder to counter-clockwise; compare in its node order.
    const auto& v = lattice.nodes[0];
    const Eigen::Matrix<double, 6, 6> cst = CstStiffness(x[v[0]], x[v[1]], x[v[2]], d, 0.01);
    EXPECT_LT((natural - cst).norm(), 1e-12 * cst.norm()) << "trial " << trial;

    // The force pass at a small displacement: -K u, up to the geometric term O(|u| / L).
    std::vector<Vector<2>> disp(3), force(3, Vector<2>::Zero());
    Eigen::Matrix<double, 6, 1> uvec;
    for (int i = 0; i < 3; ++i) {
      disp[i] = 1e-9 * Vector<2>(u(rng), u(rng));
    }
    for (int i = 0; i < 3; ++i) uvec.segment<2>(2 * i) = disp[v[i]];
    AddTriangleForces(lattice, disp, &force);
    const Eigen::Matrix<double, 6, 1> expected = -cst * uvec;
    for (int i = 0; i < 3; ++i) {
      EXPECT_LT((force[v[i]] - expected.segment<2>(2 * i)).norm(), 1e-7 * expected.norm());
    }
  }
}

TEST(SixSpringLattice, ClosedFormA6MatchesA2WithCorrectedK22) {
  std::mt19937 rng(11);
  const double side = 1.7;
  const Vector<2> a(0.0, 0.0), b(side, 0.0), c(0.5 * side, 0.5 * kSqrt3 * side);
  for (int trial = 0; trial < 20; ++trial) {
    const PlaneElasticity d = RandomAnisotropic(rng);
    const Eigen::Matrix3d derived = TriangleNaturalStiffness(a, b, c, d, 0.01);
    const Eigen::Matrix3d closed = EquilateralNaturalStiffness(d, 0.01);
    EXPECT_LT((derived - closed).norm(), 1e-12 * derived.norm());
    // The printed K22, with +2 sqrt(3) d23, is not the 120-degree edge (erratum).
    const double printed = kSqrt3 / 9.0 * (d.d22 + 2.0 * kSqrt3 * d.d23 + 3.0 * d.d33) * 0.01;
    EXPECT_GT(std::abs(printed - derived(1, 1)), 1e-3 * derived.norm());
  }
}

TEST(SixSpringLattice, IsotropicSpringConstantsMatchTheTable) {  // O5, (11) and (12)
  struct Row {
    double nu, k_nn, k_ns;
  };
  const Row table[] = {{0.00, 0.481125, -0.096225}, {0.10, 0.456826, -0.068038}, {0.20, 0.441031, -0.040094},
                       {0.25, 0.436220, -0.025660}, {0.30, 0.433541, -0.010574}, {0.33, 0.433018, -0.001080},
                       {0.40, 0.435304, 0.022911},  {0.45, 0.440403, 0.042230},  {0.49, 0.446999, 0.059515}};
  for (const Row& row : table) {
    const SixSpringConstants k = IsotropicSixSpringConstants(row.nu, PlaneModel::kPlaneStress);
    EXPECT_NEAR(k.k_nn, row.k_nn, 1e-6) << row.nu;
    EXPECT_NEAR(k.k_ns, row.k_ns, 1e-6) << row.nu;
    // The same constants from (A2) on an equilateral triangle with the isotropic D.
    const Eigen::Matrix3d kn =
        EquilateralNaturalStiffness(IsotropicPlaneElasticity(1.0, row.nu, PlaneModel::kPlaneStress), 1.0);
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) EXPECT_NEAR(kn(i, j), i == j ? k.k_nn : k.k_ns, 1e-12);
    }
  }
  const SixSpringConstants third = IsotropicSixSpringConstants(1.0 / 3.0, PlaneModel::kPlaneStress);
  EXPECT_NEAR(third.k_ns, 0.0, 1e-15);
  EXPECT_NEAR(third.k_nn, kSqrt3 / 4.0, 1e-15);
  // Plane strain: E s (5 - 8 nu) / (6 sqrt(3) (1 + nu)(1 - 2 nu)), (4 nu - 1) / (...); zero shear at 1/4.
  EXPECT_NEAR(IsotropicSixSpringConstants(0.25, PlaneModel::kPlaneStrain).k_ns, 0.0, 1e-15);
  for (double nu : {0.0, 0.2, 0.3, 0.45}) {
    const SixSpringConstants k = IsotropicSixSpringConstants(nu, PlaneModel::kPlaneStrain);
    const double den = 6.0 * kSqrt3 * (1.0 + nu) * (1.0 - 2.0 * nu);
    EXPECT_NEAR(k.k_nn, (5.0 - 8.0 * nu) / den, 1e-14);
    EXPECT_NEAR(k.k_ns, (4.0 * nu - 1.0) / den, 1e-14);
  }
  EXPECT_THROW(IsotropicSixSpringConstants(0.5, PlaneModel::kPlaneStrain), InputError);
  EXPECT_THROW(IsotropicPlaneElasticity(1e9, -1.0, PlaneModel::kPlaneStress), InputError);
}

TEST(SixSpringLattice, EigenvaluesAndTheirInverse) {  // O4
  for (double nu : {-0.5, 0.0, 0.2, 1.0 / 3.0, 0.45, 0.9}) {
    const double es = 3.2e7;
    const Eigen::Matrix3d k =
        EquilateralNaturalStiffness(IsotropicPlaneElasticity(es, nu, PlaneModel::kPlaneStress), 1.0);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(k);
    const double volumetric = es / (2.0 * kSqrt3 * (1.0 - nu)), deviatoric = es / (kSqrt3 * (1.0 + nu));
    std::vector<double> expected = {volumetric, deviatoric, deviatoric};
    std::sort(expected.begin(), expected.end());
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(eig.eigenvalues()[i], expected[i], 1e-9 * es) << nu;
    EXPECT_GT(eig.eigenvalues()[0], 0.0);  // positive definite over the whole range
    double es_back, nu_back;
    IsotropicConstantsFromEigenvalues(volumetric, deviatoric, &es_back, &nu_back);
    EXPECT_NEAR(es_back, es, 1e-9 * es);
    EXPECT_NEAR(nu_back, nu, 1e-12);
  }
}

TEST(SixSpringLattice, PaperExampleNumbers) {  // O9: E 17.1 GPa, rho 2500, s 10 mm, nu 0.2
  const double e = 17.1e9, rho = 2500.0, s = 0.01, nu = 0.2, side = 3.1746e-3;
  const SixSpringConstants k = IsotropicSixSpringConstants(nu, PlaneModel::kPlaneStress);
  EXPECT_NEAR(k.k_nn * e * s, 7.5416e7, 0.0001e7);
  EXPECT_NEAR(k.k_ns * e * s, -6.856e6, 0.001e6);
  EXPECT_NEAR(2.0 * k.k_nn * e * s, 1.5083e8, 0.0001e8);
  const TriangleLattice periodic_cell = BuildTriangleLattice(
      {Vector<2>(0, 0), Vector<2>(side, 0), Vector<2>(0.5 * side, 0.5 * kSqrt3 * side)}, {{0, 1, 2}},
      IsotropicPlaneElasticity(e, nu, PlaneModel::kPlaneStress), s);
  EXPECT_NEAR(6.0 * LumpedMasses(periodic_cell, 3, rho)[0], 2.1820e-4, 0.0001e-4);  // (2): six triangles
  EXPECT_NEAR(PaperTimeStepEstimate(e, nu, PlaneModel::kPlaneStress, rho, side, s), 1202.75e-9, 0.05e-9);
  EXPECT_NEAR(PaperTimeStepEstimate(e, nu, PlaneModel::kPlaneStress, rho, 1.5873e-3, s), 601.38e-9, 0.05e-9);
  EXPECT_NEAR(RegularLatticeStableTimeStep(e, nu, PlaneModel::kPlaneStress, rho, side), 1030.0e-9, 0.1e-9);
  // The estimate (15) overestimates the limit by sqrt(6 / (5 - 3 nu)).
  for (double v : {0.0, 0.2, 1.0 / 3.0, 0.49}) {
    const double ratio = RegularLatticeStableTimeStep(e, v, PlaneModel::kPlaneStress, rho, side) /
                         PaperTimeStepEstimate(e, v, PlaneModel::kPlaneStress, rho, side, s);
    EXPECT_NEAR(ratio, std::sqrt((5.0 - 3.0 * v) / 6.0), 1e-12);
  }
}

// The regular lattice of the paper's examples: rows along x, alternately nx + 1 and nx nodes
// (the short rows offset by L/2), row pitch sqrt(3)/2 L.
struct RegularLattice {
  std::vector<Vector<2>> nodes;
  std::vector<std::array<int, 3>> triangles;
  std::vector<int> row_of;
  int rows = 0;
};

RegularLattice BuildRegular(int nx, int rows, double side) {
  RegularLattice lattice;
  lattice.rows = rows;
  std::vector<int> first(rows + 1, 0);
  for (int r = 0; r < rows; ++r) {
    const int count = r % 2 == 0 ? nx + 1 : nx;
    first[r + 1] = first[r] + count;
    for (int c = 0; c < count; ++c) {
      lattice.nodes.emplace_back((c + (r % 2 == 0 ? 0.0 : 0.5)) * side, r * 0.5 * kSqrt3 * side);
      lattice.row_of.push_back(r);
    }
  }
  for (int r = 0; r + 1 < rows; ++r) {
    const int lo = first[r], hi = first[r + 1];
    if (r % 2 == 0) {  // long row below
      for (int c = 0; c < nx; ++c) lattice.triangles.push_back({lo + c, lo + c + 1, hi + c});
      for (int c = 0; c + 1 < nx; ++c) lattice.triangles.push_back({hi + c, lo + c + 1, hi + c + 1});
    } else {  // short row below
      for (int c = 0; c < nx; ++c) lattice.triangles.push_back({lo + c, hi + c + 1, hi + c});
      for (int c = 0; c + 1 < nx; ++c) lattice.triangles.push_back({lo + c, lo + c + 1, hi + c + 1});
    }
  }
  return lattice;
}

// Nodal forces of the affine field u = eps x (Voigt eps, engineering shear split evenly).
std::vector<Vector<2>> AffineForces(const RegularLattice& mesh, const TriangleLattice& lattice,
                                    const Eigen::Vector3d& eps) {
  std::vector<Vector<2>> disp(mesh.nodes.size()), force(mesh.nodes.size(), Vector<2>::Zero());
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    const Vector<2>& x = mesh.nodes[i];
    disp[i] = Vector<2>(eps[0] * x.x() + 0.5 * eps[2] * x.y(), 0.5 * eps[2] * x.x() + eps[1] * x.y());
  }
  AddTriangleForces(lattice, disp, &force);
  return force;
}

// Virial stress of the external forces that hold the field, sigma = (1/V) sum x (x) (-f).
Eigen::Vector3d VirialStress(const RegularLattice& mesh, const TriangleLattice& lattice,
                             const std::vector<Vector<2>>& force) {
  double volume = 0.0;
  for (double a : lattice.areas) volume += a * lattice.thickness_m;
  Eigen::Matrix2d sum = Eigen::Matrix2d::Zero();
  for (std::size_t i = 0; i < force.size(); ++i) sum -= mesh.nodes[i] * force[i].transpose();
  sum /= volume;
  return Eigen::Vector3d(sum(0, 0), sum(1, 1), 0.5 * (sum(0, 1) + sum(1, 0)));
}

TEST(SixSpringLattice, RegularLatticeCounts) {  // O2's block: nx 8, 7 rows
  const RegularLattice mesh = BuildRegular(8, 7, 1.0);
  EXPECT_EQ(mesh.nodes.size(), 60u);
  EXPECT_EQ(mesh.triangles.size(), 90u);
  const TriangleLattice lattice = BuildTriangleLattice(
      mesh.nodes, mesh.triangles, IsotropicPlaneElasticity(1e9, 0.2, PlaneModel::kPlaneStress), 0.1);
  double area = 0.0;
  for (double a : lattice.areas) area += a;
  EXPECT_NEAR(area, 38.971143, 1e-6);
}

// The uniaxial test O2: the affine field of a uniaxial stress along y holds every node other
// than the loaded rows force-free (the zig-zag lateral edges are free), and the reaction of
// the loaded row gives E = R H^2 / (A s delta). Strain 1e-8: the geometric term is 1e-8.
void ExpectExactUniaxial(const PlaneElasticity& d, double expected_e, double expected_nu, double tolerance) {
  const RegularLattice mesh = BuildRegular(8, 7, 1.0);
  const TriangleLattice lattice = BuildTriangleLattice(mesh.nodes, mesh.triangles, d, 0.1);
  const Eigen::Matrix3d compliance = d.Matrix().inverse();
  const double stress = 1e-8 * expected_e;
  const Eigen::Vector3d eps = compliance * Eigen::Vector3d(0.0, stress, 0.0);
  const std::vector<Vector<2>> force = AffineForces(mesh, lattice, eps);
  double reaction = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < force.size(); ++i) scale = std::max(scale, force[i].norm());
  for (std::size_t i = 0; i < force.size(); ++i) {
    if (mesh.row_of[i] == mesh.rows - 1) {
      reaction -= force[i].y();
    } else if (mesh.row_of[i] != 0) {
      EXPECT_LT(force[i].norm(), 1e-6 * scale) << "node " << i;
    }
  }
  const double height = (mesh.rows - 1) * 0.5 * kSqrt3;
  double area = 0.0;
  for (double a : lattice.areas) area += a;
  const double delta = eps[1] * height;
  EXPECT_NEAR(reaction * height * height / (area * 0.1 * delta), expected_e, tolerance * expected_e);
  EXPECT_NEAR(-eps[0] / eps[1], expected_nu, tolerance);
}

TEST(SixSpringLattice, UniaxialTestReturnsTheInputConstants) {  // O2
  for (double nu : {-0.5, 0.0, 0.1, 0.2, 1.0 / 3.0, 0.4, 0.49, 0.8}) {
    ExpectExactUniaxial(IsotropicPlaneElasticity(17.1e9, nu, PlaneModel::kPlaneStress), 17.1e9, nu, 1e-6);
  }
  // Plane strain: the in-plane constants are E' = E / (1 - nu^2), nu' = nu / (1 - nu).
  for (double nu : {0.0, 0.1, 0.25, 0.3, 0.45, 0.49}) {
    ExpectExactUniaxial(IsotropicPlaneElasticity(17.1e9, nu, PlaneModel::kPlaneStrain), 17.1e9 / (1 - nu * nu),
                        nu / (1 - nu), 1e-6);
  }
}

TEST(SixSpringLattice, HomogeneousStrainsGiveTheExactStress) {  // O3, anisotropic D too
  std::mt19937 rng(3);
  const RegularLattice mesh = BuildRegular(10, 9, 0.5);
  for (int trial = 0; trial < 5; ++trial) {
    const PlaneElasticity d = RandomAnisotropic(rng);
    const TriangleLattice lattice = BuildTriangleLattice(mesh.nodes, mesh.triangles, d, 0.2);
    const Eigen::Vector3d eps(3e-9, -1e-9, 2e-9);
    const std::vector<Vector<2>> force = AffineForces(mesh, lattice, eps);
    const Eigen::Vector3d expected = d.Matrix() * eps;
    EXPECT_LT((VirialStress(mesh, lattice, force) - expected).norm(), 1e-6 * expected.norm());
    // Interior nodes (six triangles) carry no residual.
    std::vector<int> triangles_at(mesh.nodes.size(), 0);
    for (const auto& t : lattice.nodes) {
      for (int i : t) ++triangles_at[i];
    }
    for (std::size_t i = 0; i < force.size(); ++i) {
      if (triangles_at[i] == 6) {
        EXPECT_LT(force[i].norm(), 1e-6 * expected.norm() * 0.25) << i;
      }
    }
  }
}

// The modulus of an orthotropic plate loaded at angle theta to axis 1 (plane stress):
// 1/E(theta) = c^4/E1 + s^4/E2 + (1/G12 - 2 nu12/E1) c^2 s^2.
double OrthotropicDirectionalModulus(const OrthotropicConstants& k, double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  return 1.0 / (std::pow(c, 4) / k.youngs_modulus_1_pa + std::pow(s, 4) / k.youngs_modulus_2_pa +
                (1.0 / k.shear_modulus_12_pa - 2.0 * k.poisson_ratio_12 / k.youngs_modulus_1_pa) * c * c * s * s);
}

TEST(SixSpringLattice, OrthotropicModuliAlongBothAxesAndAt45Degrees) {
  // The paper's section 5.3 material: E1 17.1 GPa, E2 8.55 GPa, G 7.125 GPa, nu 0.2.
  OrthotropicConstants k;
  k.youngs_modulus_1_pa = 17.1e9;
  k.youngs_modulus_2_pa = 8.55e9;
  k.poisson_ratio_12 = 0.2;
  k.shear_modulus_12_pa = 7.125e9;
  const RegularLattice mesh = BuildRegular(12, 11, 1.0);
  for (double axis : {0.0, 0.3}) {  // material axis along the lattice rows, and rotated
    k.axis_angle_rad = axis;
    const PlaneElasticity d = OrthotropicPlaneElasticity(k, PlaneModel::kPlaneStress);
    const TriangleLattice lattice = BuildTriangleLattice(mesh.nodes, mesh.triangles, d, 0.01);
    // The lattice's effective D from three unit strains, then its compliance.
    Eigen::Matrix3d effective;
    for (int j = 0; j < 3; ++j) {
      Eigen::Vector3d eps = Eigen::Vector3d::Zero();
      eps[j] = 1e-8;
      effective.col(j) = VirialStress(mesh, lattice, AffineForces(mesh, lattice, eps)) / 1e-8;
    }
    const Eigen::Matrix3d compliance = effective.inverse();
    for (double load : {0.0, M_PI / 2.0, M_PI / 4.0}) {  // loading direction from x
      const double direction = axis + load;              // along axis 1, axis 2, at 45 degrees
      const Eigen::Vector3d n(std::cos(direction) * std::cos(direction), std::sin(direction) * std::sin(direction),
                              std::sin(direction) * std::cos(direction));
      // Uniaxial stress sigma n (x) n: axial strain n.eps n = n_voigt . S sigma_voigt.
      // (the Voigt stress of a unit uniaxial stress is n itself; gamma = 2 eps_xy).
      const double axial = n.dot(compliance * n);
      EXPECT_NEAR(1.0 / axial, OrthotropicDirectionalModulus(k, load), 1e-6 * k.youngs_modulus_1_pa)
          << "axis " << axis << " load " << load;
    }
  }
  // Textbook checks of the constants themselves.
  k.axis_angle_rad = 0.0;
  const PlaneElasticity d = OrthotropicPlaneElasticity(k, PlaneModel::kPlaneStress);
  const double nu21 = 0.2 * 8.55 / 17.1;
  EXPECT_NEAR(d.d11, 17.1e9 / (1.0 - 0.2 * nu21), 1.0);
  EXPECT_NEAR(d.d33, 7.125e9, 1e-3);
  OrthotropicConstants bad = k;
  bad.poisson_ratio_12 = 1.5;  // |nu12| >= sqrt(E1 / E2) = 1.41
  EXPECT_THROW(OrthotropicPlaneElasticity(bad, PlaneModel::kPlaneStress), InputError);
  EXPECT_THROW(OrthotropicPlaneElasticity(k, PlaneModel::kPlaneStrain), InputError);  // no E3
}

TEST(SixSpringLattice, ExactStabilityLimitOfCentralDifferences) {  // O6, full six-spring law
  const double e = 17.1e9, rho = 2500.0, s = 0.01, side = 3.1746e-3;
  for (double nu : {0.0, 0.2, 0.4}) {
    const PlaneElasticity d = IsotropicPlaneElasticity(e, nu, PlaneModel::kPlaneStress);
    const TriangleLattice block = PeriodicBlock(6, 6, side, d, s);
    // omega_max^2 m / (E s) = 8 / (sqrt(3) (1 - nu^2)), m = rho s sqrt(3)/2 L^2.
    const double limit = RegularLatticeStableTimeStep(e, nu, PlaneModel::kPlaneStress, rho, side);
    const double mass = 0.5 * kSqrt3 * rho * side * side * s;
    EXPECT_NEAR(2.0 / limit, std::sqrt(8.0 / (kSqrt3 * (1 - nu * nu)) * e * s / mass), 1e-9 / limit);
    EXPECT_LT(CentralDifferenceGrowth(block, 36, rho, 0.99 * limit, 3000), 1e-8) << "nu " << nu;
    EXPECT_GT(CentralDifferenceGrowth(block, 36, rho, 1.01 * limit, 3000), 1e-3) << "nu " << nu;
    // The Lanczos analysis of the assembled lattice finds the same limit (72 unknowns: exact).
    const LatticeStability analysis = AnalyseLatticeStability(block, LumpedMasses(block, 36, rho), {});
    EXPECT_TRUE(analysis.lanczos.exact);
    EXPECT_NEAR(2.0 / std::sqrt(analysis.lanczos.ritz_value) / limit, 1.0, 1e-9) << "nu " << nu;
    // The certified step keeps a round-off margin below it.
    EXPECT_LE(analysis.critical_time_step_s, limit);
    EXPECT_NEAR(analysis.critical_time_step_s / limit, 1.0, 1e-7) << "nu " << nu;
    EXPECT_LE(analysis.gershgorin_time_step_s, analysis.critical_time_step_s * (1.0 + 1e-12));
  }
}

TEST(SixSpringLattice, BadInputIsRefused) {
  const std::vector<Vector<2>> collinear = {Vector<2>(0, 0), Vector<2>(1, 0), Vector<2>(2, 0)};
  const PlaneElasticity d = IsotropicPlaneElasticity(1e9, 0.2, PlaneModel::kPlaneStrain);
  EXPECT_THROW(BuildTriangleLattice(collinear, {{0, 1, 2}}, d, 1.0), InputError);
  EXPECT_THROW(BuildTriangleLattice(collinear, {{0, 1, 3}}, d, 1.0), InputError);
  EXPECT_THROW(BuildTriangleLattice(collinear, {{0, 1, 2}}, d, 0.0), InputError);
  PlaneElasticity negative = d;
  negative.d33 = -1.0;
  EXPECT_THROW(BuildTriangleLattice({Vector<2>(0, 0), Vector<2>(1, 0), Vector<2>(0, 1)}, {{0, 1, 2}}, negative, 1.0),
               InputError);
}

}  // namespace
}  // namespace specimen
