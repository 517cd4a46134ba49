// The virtual laboratory (lab/lab_test.h) against its oracles: the closed forms of a regular
// hexagonal packing (O7 of docs/sources.md), the Voigt estimate of an irregular dense packing
// (Madan section 4.3, (4.15)-(4.18)), the consistency of K and G from the isotropic and pure
// shear tests with the UCS E and nu (Madan section 4.5; A14 of docs/sources.md), and the
// Brazilian formula. Expected values come from the sources' formulas, never from earlier
// output of this code.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "generator/generate.h"
#include "lab/lab_envelope.h"
#include "lab/lab_measurement.h"
#include "lab/lab_test.h"
#include "solver/regular_lattice.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;

MaterialParameters Unbreakable(double kn, double kt) {
  MaterialParameters m;
  m.normal_stiffness_n_per_m = kn;
  m.tangential_stiffness_n_per_m = kt;
  m.density_kg_per_m3 = 2000.0;
  return m;
}

// In-plane (2D) closed forms of a bonded disc assembly under uniform strain (Voigt), with
// C = N_c <R^2> / V (Madan (4.15)-(4.18); on the hexagonal lattice, O7 of docs/sources.md,
// C = 3 R^2 / (2 sqrt(3) R^2) = sqrt(3)/2):
//   E' = 4 C kn (kn + kt) / (3 kn + kt),  nu' = (kn - kt) / (3 kn + kt),
//   K' = C kn,  G = C (kn + kt) / 2.
struct Voigt {
  double youngs = 0.0, poisson = 0.0, bulk = 0.0, shear = 0.0;
};
Voigt VoigtInPlane(double c, double kn, double kt) {
  Voigt v;
  v.youngs = 4.0 * c * kn * (kn + kt) / (3.0 * kn + kt);
  v.poisson = (kn - kt) / (3.0 * kn + kt);
  v.bulk = c * kn;
  v.shear = 0.5 * c * (kn + kt);
  return v;
}

// ---------------------------------------------------------------------------------------
// O7: a regular hexagonal packing of equal discs, no breakage. UCS between frictionless
// platens; E' and nu' (the in-plane constants, plane stress reading of O7) within 0.5 %.
//
// The lattice's rows run along the loading axis (y), so its free lateral sides are straight
// rows: in the affine state of uniaxial stress every disc of such a side is in equilibrium,
// forces and moments (the missing 150/210 degree bonds carry no x force and their y forces
// and moments cancel pairwise), so the sides are exactly traction free. The platens touch
// every other row (the ends are zigzag): an end zone whose influence the strain avoids by
// measuring in the interior (strain_boundary_margin = 8 radii) of a tall specimen (H = 3.4 W).
// The stress is F / W with W the domain width; the exact force-carrying width of the
// finite lattice (the affine bond forces across a horizontal cut: m vertical bonds and
// m - 1 diagonal pairs) is sqrt(3) R (m - 2 a / (3 (1 + a))), a = kt / kn, so the domain is
// m sqrt(3) R wide (the rows' Voronoi strips) and the expected E' carries that factor
// (0.6 % at a = 0.25, 1.6 % at a = 1 for m = 21). Measured: E' +0.34, +0.25, +0.12 % and
// nu' 0.33395, 0.23043, -0.0013 for kt/kn = 0, 0.25, 1. (Rows across the loading axis
// instead - flat ends, zigzag sides - leave an O(R/W) ambiguity in the force-carrying width
// and a zigzag edge layer out of equilibrium under affine strain: 0.5-3 % off at 20-60
// discs a row.)
TEST(LabHexagonalLattice, O7ElasticConstantsFromUniaxialCompression) {
  constexpr int kRows = 21, kDiscs = 61;  // rows along y, alternately 61 and 60 discs
  const double radius = 1e-3, kn = 1e10, pitch = std::sqrt(3.0) * radius;
  Packing<2> packing = HexagonalLatticePacking(kRows, kDiscs, kDiscs - 1, radius);
  for (auto& x : packing.centres) x = Vector<2>(x.y(), x.x());  // rows along y
  packing.domain = Domain<2>::Rectangle(-0.5 * pitch, -radius, (kRows - 0.5) * pitch,
                                        2.0 * radius * (kDiscs - 1) + radius);
  for (const double ratio : {0.0, 0.25, 1.0}) {
    SCOPED_TRACE("kt/kn = " + std::to_string(ratio));
    LabTestOptions options;
    options.strain_limit = 1e-3;
    options.loading_rate_group = 1e-5;
    options.strain_boundary_margin = 8.0;
    const LabTestResult r = RunLabTest<2>(packing, Unbreakable(kn, ratio * kn), options);
    ASSERT_TRUE(r.elastic.measured);
    EXPECT_EQ(r.broken_in_tension + r.broken_in_shear, 0);
    const Voigt o7 = VoigtInPlane(std::sqrt(3.0) / 2.0, kn, ratio * kn);
    const double width = 1.0 - 2.0 * ratio / (3.0 * (1.0 + ratio) * kRows);
    const double e = r.elastic.youngs_modulus_in_plane_pa, nu = r.elastic.poisson_ratio_in_plane;
    EXPECT_NEAR(e, o7.youngs * width, 0.005 * o7.youngs);
    EXPECT_NEAR(nu, o7.poisson, 0.005 * std::max(o7.poisson, 1.0 / 3.0));
    // Plane strain reading (docs/lab.md, "Measurement"): nu = nu'/(1 + nu'), E = E'(1 - nu^2).
    EXPECT_NEAR(r.elastic.poisson_ratio, nu / (1.0 + nu), 1e-12);
    // The linear portion (the ISRM average modulus, LinearPortionElasticConstants) of this
    // intact, linear specimen is the same closed form.
    ASSERT_TRUE(r.linear_elastic.measured);
    EXPECT_NEAR(r.linear_elastic.youngs_modulus_in_plane_pa, o7.youngs * width, 0.005 * o7.youngs);
    EXPECT_NEAR(r.linear_elastic.poisson_ratio_in_plane, o7.poisson, 0.005 * std::max(o7.poisson, 1.0 / 3.0));
    std::printf("O7 kt/kn %.2f: E' = %.5e Pa (closed form %.5e x %.4f), nu' = %.5f (%.5f), "
                "%ld steps, %.2f s\n",
                ratio, e, o7.youngs, width, nu, o7.poisson, r.steps, r.wall_seconds);
  }
}

// ---------------------------------------------------------------------------------------
// An irregular dense packing of the generator (generate-packing defaults, ~1,500 discs in a
// 20 x 20 mm square, porosity ~9 %, coordination ~5.8), shared by the suites below.
class LabIrregularPacking : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    GeneratorOptions options = DefaultGeneratorOptions<2>();
    options.particle_count = 1500;
    options.seed = 3;
    packing_ = new Packing<2>(GeneratePacking<2>(Domain<2>::Rectangle(0, 0, 0.02, 0.02), options, nullptr));
  }
  static void TearDownTestSuite() {
    delete packing_;
    packing_ = nullptr;
  }

  // C = N_c <R^2> / V of Madan (4.15)-(4.18) for a polydisperse packing, with R^2 the
  // contact's squared half branch length |l|^2 / 4 (= R^2 for equal discs), over the
  // contacts whose midpoints lie in the rectangle `margin` mean radii inside the domain,
  // and V that rectangle's area (x 1 m): the contact density of the region whose strain
  // is measured. margin = 0: the whole specimen.
  static double ContactDensity(double margin) {
    const Packing<2>& p = *packing_;
    double mean = 0.0;
    for (const double r : p.radii) mean += r * r;
    mean = std::sqrt(mean / p.size());
    const Vector<2> lower = p.domain.Lower() + Vector<2>::Constant(margin * mean);
    const Vector<2> upper = p.domain.Upper() - Vector<2>::Constant(margin * mean);
    double sum = 0.0;
    for (const auto& c : p.contacts) {
      const Vector<2> mid = 0.5 * (p.centres[c[0]] + p.centres[c[1]]);
      if ((mid.array() < lower.array()).any() || (mid.array() > upper.array()).any()) continue;
      sum += 0.25 * (p.centres[c[1]] - p.centres[c[0]]).squaredNorm();
    }
    return sum / ((upper - lower).prod());
  }

  // Madan's anchor form: N_c <R^2>_particles / V over the whole domain.
  static double ParticleAveragedDensity() {
    const Packing<2>& p = *packing_;
    double r2 = 0.0;
    for (const double r : p.radii) r2 += r * r / p.size();
    return p.contacts.size() * r2 / p.domain.Volume();
  }

  static Packing<2>* packing_;
};
Packing<2>* LabIrregularPacking::packing_ = nullptr;

constexpr double kMargin = 4.0;  // interior strain region, mean radii (the lab's default)

// Madan section 4.3, (4.15)-(4.16): E/kn and nu against kt/kn from the UCS, no breakage,
// within a few % of the Voigt estimate with this packing's N_c <R^2> / V. Madan's 4979-disc
// specimen has C = 0.8603 (section 4.5, (4.32): N_c = 14435, <R^2> = 1.49e-7 m^2,
// V = 0.05 x 0.05 x 1 m^3); ours is computed from the packing: 0.912 over the
// interior whose strain is measured with the contact R^2 = |l|^2/4 (0.884 over the whole
// domain; 0.823 with the particles' <R^2>, Madan's form, which under-weights the large,
// well-connected particles). Measured (1,544 discs): E' 0.5-1.3 % below Voigt, as an upper
// bound should be; nu' above it by 0.002 (kt/kn = 1.25) to 0.022 (kt = 0): the relaxation
// of a disordered packing lowers G more than K, most where the tangential springs are weak.
// Tolerances: E' within 3 % and not above Voigt; nu' within 0.025.
TEST_F(LabIrregularPacking, VoigtEstimateMadanTable) {
  const double kn = 1e10;
  const double c = ContactDensity(kMargin);
  std::printf("packing: %d discs, %zu contacts; C = N_c<R^2>/V = %.4f (interior, contact R^2), "
              "%.4f (whole, contact R^2), %.4f (whole, particle <R^2>: Madan's form)\n",
              packing_->size(), packing_->contacts.size(), c, ContactDensity(0.0),
              ParticleAveragedDensity());
  for (const double ratio : {0.0, 0.1, 0.25, 0.5, 1.0, 1.25}) {
    SCOPED_TRACE("kt/kn = " + std::to_string(ratio));
    LabTestOptions options;
    options.strain_limit = 1e-3;
    options.strain_boundary_margin = kMargin;
    const LabTestResult r = RunLabTest<2>(*packing_, Unbreakable(kn, ratio * kn), options);
    ASSERT_TRUE(r.elastic.measured);
    const Voigt v = VoigtInPlane(c, kn, ratio * kn);
    const double e = r.elastic.youngs_modulus_in_plane_pa, nu = r.elastic.poisson_ratio_in_plane;
    std::printf("  kt/kn %.2f: E'/kn = %.4f (Voigt %.4f, %+.2f %%), nu' = %.4f (Voigt %.4f, "
                "%+.4f), %.2f s\n",
                ratio, e / kn, v.youngs / kn, 100 * (e / v.youngs - 1), nu, v.poisson,
                nu - v.poisson, r.wall_seconds);
    EXPECT_NEAR(e, v.youngs, 0.03 * v.youngs);
    EXPECT_LT(e, 1.005 * v.youngs);
    EXPECT_NEAR(nu, v.poisson, 0.025);
  }
}

// Inertia scaling (LabTestOptions::mass_scaling_budget): raising the inertia of the few
// light particles that limit the time step changes the dynamics of those particles only; the
// quasi-static elastic response stays, and the step grows (the limit is the certified
// analysis of the scaled masses, so the run is as stable). Measured: rigid E' -0.06 %, DDEM
// E' -0.03 %; taking the DDEM volume from the scaled mass would give +0.23 %, so E' is held
// to 0.12 %.
TEST_F(LabIrregularPacking, InertiaScalingKeepsTheElasticResponse) {
  const double kn = 1e10;
  auto compare = [&](const char* label, const MaterialParameters& material) {
    SCOPED_TRACE(label);
    LabTestOptions options;
    options.strain_limit = 1e-3;
    options.strain_boundary_margin = kMargin;
    options.mass_scaling_budget = 0.0;
    const LabTestResult plain = RunLabTest<2>(*packing_, material, options);
    options.mass_scaling_budget = 0.02;
    const LabTestResult scaled = RunLabTest<2>(*packing_, material, options);
    const double e0 = plain.elastic.youngs_modulus_in_plane_pa;
    std::printf("  %s: E' %.5g -> %.5g Pa, nu' %.4f -> %.4f, steps %ld -> %ld, %s\n", label, e0,
                scaled.elastic.youngs_modulus_in_plane_pa, plain.elastic.poisson_ratio_in_plane,
                scaled.elastic.poisson_ratio_in_plane, plain.steps, scaled.steps,
                MassScalingLine(scaled.mass_scaling).c_str());
    EXPECT_EQ(plain.mass_scaling.scaled_particles, 0);
    EXPECT_GT(scaled.mass_scaling.scaled_particles, 0);
    EXPECT_NEAR(scaled.mass_scaling.added_mass_share, 0.02, 1e-12);
    EXPECT_NEAR(scaled.elastic.youngs_modulus_in_plane_pa, e0, 0.0012 * e0);
    EXPECT_NEAR(scaled.elastic.poisson_ratio_in_plane, plain.elastic.poisson_ratio_in_plane, 0.002);
    EXPECT_GT(scaled.critical_time_step_s, 1.1 * plain.critical_time_step_s);
    EXPECT_LT(scaled.steps, plain.steps);
  };
  compare("rigid, kt/kn 0.25", Unbreakable(kn, 0.25 * kn));
  // DDEM (kt = 0, kn/(Ep l) = 0.2, nu_p = 0.35): the particle stresses use the true volumes.
  MaterialParameters deformable = Unbreakable(kn, 0.0);
  deformable.particle_youngs_modulus_pa = kn / 0.2;
  deformable.particle_poisson_ratio = 0.35;
  compare("DDEM", deformable);
}

// The quasi-static check repeats the test at half the rate: an elastic UCS is rate-free, so E
// changes by far less than the tolerance, and the report gives the half rate's group.
TEST_F(LabIrregularPacking, TheQuasiStaticCheckRunsAtHalfTheRate) {
  LabTestOptions options;
  options.strain_limit = 1e-3;
  options.strain_boundary_margin = kMargin;
  options.check_quasi_static = true;
  const LabTestResult r = RunLabTest<2>(*packing_, Unbreakable(1e10, 0.25e10), options);
  ASSERT_TRUE(r.quasi_static.performed);
  EXPECT_DOUBLE_EQ(r.quasi_static.half_rate_group, 0.5 * r.loading_rate_group);
  EXPECT_LT(r.quasi_static.modulus_change, 0.002);
  EXPECT_TRUE(r.quasi_static.passed);
}

// The linear portion of a test to failure (LabTestResult::linear_elastic) ends before the
// first broken bond, and gives what the same specimen gives intact: E and nu depend on the
// stiffnesses only, not on the strengths (what separates a calibration's elastic and
// strength stages). The strengths here put the first broken bond beyond the axial strain of
// an elastic run (1.5e-3); where bonds break earlier, the intact part of a test to failure
// is too short to read (the drive's start-up dominates), which is why the calibration reads
// E and nu from elastic runs instead.
TEST_F(LabIrregularPacking, LinearPortionIsTheIntactSpecimensAndIgnoresTheStrengths) {
  const double kn = 1e10;
  MaterialParameters intact = Unbreakable(kn, 0.2 * kn);
  LabTestOptions options;
  options.strain_boundary_margin = kMargin;
  options.strain_limit = 1.5e-3;
  options.sample_interval_steps = 50;
  const LabTestResult elastic = RunLabTest<2>(*packing_, intact, options);
  ASSERT_TRUE(elastic.linear_elastic.measured);
  {
    const double strength_ratio = 10.0;
    MaterialParameters breaking = intact;
    breaking.bond_tensile_strength_n = 6e3;
    breaking.bond_shear_strength_n = strength_ratio * 6e3;
    breaking.friction_coefficient = 0.8;
    LabTestOptions to_failure = options;
    to_failure.strain_limit = 0.05;
    to_failure.post_peak_stress_fraction = 0.9;  // the peak is all this test needs
    const LabTestResult r = RunLabTest<2>(*packing_, breaking, to_failure);
    ASSERT_TRUE(r.peak_reached);
    ASSERT_TRUE(r.linear_elastic.measured);
    // Its samples end before the first sample with a broken bond: the window's top is the
    // largest control value among the samples before it.
    double first_break_stress = 0.0, last_intact_control = 0.0;
    for (const LabCurvePoint& p : r.curve) {
      if (p.broken_in_tension + p.broken_in_shear > 0) {
        first_break_stress = p.control;
        break;
      }
      last_intact_control = std::max(last_intact_control, p.control);
    }
    EXPECT_GT(first_break_stress, 0.0);
    EXPECT_DOUBLE_EQ(r.linear_elastic.window_high_pa, last_intact_control);
    EXPECT_LT(r.linear_elastic.window_high_pa, first_break_stress);
    EXPECT_NEAR(r.linear_elastic.window_low_pa, 0.2 * last_intact_control, 1e-9 * last_intact_control);
    // Plane strain reading of the in-plane slopes (docs/lab.md, "Measurement").
    const double nu_in_plane = r.linear_elastic.poisson_ratio_in_plane;
    EXPECT_NEAR(r.linear_elastic.poisson_ratio, nu_in_plane / (1.0 + nu_in_plane), 1e-12);
    EXPECT_NEAR(r.linear_elastic.youngs_modulus_pa,
                r.linear_elastic.youngs_modulus_in_plane_pa * (1.0 - std::pow(r.linear_elastic.poisson_ratio, 2)),
                1e-9 * r.linear_elastic.youngs_modulus_pa);
    std::printf("  Rt/Rn %.0f: peak %.4g MPa, first break at %.3g MPa; linear portion %.3g-%.3g MPa (%d samples), "
                "E %.5g GPa, nu %.5f; intact run E %.5g GPa, nu %.5f; secant 1-50 %%: nu %.4f\n",
                strength_ratio, r.peak_stress_pa / 1e6, first_break_stress / 1e6, r.linear_elastic.window_low_pa / 1e6, r.linear_elastic.window_high_pa / 1e6,
                r.linear_elastic.samples_in_window, r.linear_elastic.youngs_modulus_pa / 1e9,
                r.linear_elastic.poisson_ratio, elastic.linear_elastic.youngs_modulus_pa / 1e9,
                elastic.linear_elastic.poisson_ratio, r.elastic.poisson_ratio);
    EXPECT_NEAR(r.linear_elastic.youngs_modulus_pa, elastic.linear_elastic.youngs_modulus_pa,
                0.005 * elastic.linear_elastic.youngs_modulus_pa);
    EXPECT_NEAR(r.linear_elastic.poisson_ratio, elastic.linear_elastic.poisson_ratio, 0.003);
  }
}

// A14 (docs/sources.md; Madan section 4.5, (4.33)-(4.36)): K from the isotropic test and G
// from the pure shear test agree with those of the UCS E', nu' (2D: K' = E'/(2(1 - nu')),
// G = E'/(2(1 + nu')), the 2D form of Madan's (4.11)-(4.12)) within 3 %.
TEST_F(LabIrregularPacking, A14BulkAndShearModuliMatchUniaxial) {
  const double kn = 1e10;
  for (const double ratio : {0.0, 0.5}) {
    SCOPED_TRACE("kt/kn = " + std::to_string(ratio));
    const MaterialParameters material = Unbreakable(kn, ratio * kn);
    LabTestOptions options;
    options.strain_limit = 1e-3;
    options.strain_boundary_margin = kMargin;
    const LabTestResult ucs = RunLabTest<2>(*packing_, material, options);
    options.kind = LabTestKind::kIsotropicCompression;
    const LabTestResult isotropic = RunLabTest<2>(*packing_, material, options);
    options.kind = LabTestKind::kPureShear;
    const LabTestResult shear = RunLabTest<2>(*packing_, material, options);
    const double e = ucs.elastic.youngs_modulus_in_plane_pa, nu = ucs.elastic.poisson_ratio_in_plane;
    const double k = e / (2.0 * (1.0 - nu)), g = e / (2.0 * (1.0 + nu));
    const Voigt v = VoigtInPlane(ContactDensity(kMargin), kn, ratio * kn);
    std::printf("  kt/kn %.2f: K = %.4e Pa (UCS %.4e, %+.2f %%; Voigt %.4e), G = %.4e Pa (UCS "
                "%.4e, %+.2f %%; Voigt %.4e)\n",
                ratio, isotropic.bulk_modulus_pa, k, 100 * (isotropic.bulk_modulus_pa / k - 1),
                v.bulk, shear.shear_modulus_pa, g, 100 * (shear.shear_modulus_pa / g - 1), v.shear);
    EXPECT_NEAR(isotropic.bulk_modulus_pa, k, 0.03 * k);
    EXPECT_NEAR(shear.shear_modulus_pa, g, 0.03 * g);
  }
}

// Brazilian test (Labra (4.38)): sigma_t = 2 F / (pi D t) with F the peak platen force, D the
// disc's diameter and t = 1 m in 2D; the test runs through the peak to 50 % of it.
TEST(LabBrazilian, TensileStrengthFormula) {
  GeneratorOptions generator = DefaultGeneratorOptions<2>();
  generator.particle_count = 600;
  generator.seed = 5;
  const double radius = 0.01;
  const Packing<2> packing =
      GeneratePacking<2>(Domain<2>::Disc(Vector<2>::Zero(), radius), generator, nullptr);
  MaterialParameters material = Unbreakable(1e10, 2.5e9);
  material.bond_tensile_strength_n = 2e3;
  material.bond_shear_strength_n = 2e4;
  material.friction_coefficient = 0.5;
  LabTestOptions options;
  options.kind = LabTestKind::kBrazilian;
  const LabTestResult r = RunLabTest<2>(packing, material, options);
  ASSERT_TRUE(r.peak_reached) << r.termination_message;
  EXPECT_EQ(r.termination, LabTermination::kPostPeak);
  double force = 0.0;
  for (const LabCurvePoint& p : r.curve) force = std::max(force, p.platen_force_n);
  const double expected = 2.0 * force / (kPi * 2.0 * radius * 1.0);
  EXPECT_NEAR(r.tensile_strength_pa, expected, 1e-12 * expected);
  EXPECT_DOUBLE_EQ(r.peak_force_n, force);
  EXPECT_DOUBLE_EQ(r.width_m, 2.0 * radius);
  EXPECT_LE(r.curve.back().control, options.post_peak_stress_fraction * force * (1 + 1e-12));
  EXPECT_GT(r.broken_in_tension, 0);
  std::printf("BTS: F = %.4e N/m, sigma_t = %.4e Pa, %ld bonds broken, %ld steps, %.2f s\n",
              force, r.tensile_strength_pa, r.broken_in_tension + r.broken_in_shear, r.steps,
              r.wall_seconds);
}

// Confined biaxial compression (biaxial (a)): the lateral walls hold sigma_3 while
// the platens load; the peak axial stress rises with sigma_3 and the Mohr-Coulomb fit of the
// envelope has a positive cohesion and friction angle. No closed form: a sanity check of the
// servo, the envelope and the fit on a small specimen (500 discs: 34.7, 116, 131 MPa at 0, 5,
// 10 MPa; c = 7.4 MPa, phi = 54 deg - a steep envelope; not compared with rock).
TEST(LabConfined, EnvelopeRisesWithConfinement) {
  GeneratorOptions generator = DefaultGeneratorOptions<2>();
  generator.particle_count = 500;
  generator.seed = 7;
  const Packing<2> packing =
      GeneratePacking<2>(Domain<2>::Rectangle(0, 0, 0.01, 0.01), generator, nullptr);
  MaterialParameters material = Unbreakable(1e10, 2.5e9);
  material.bond_tensile_strength_n = 2e3;
  material.bond_shear_strength_n = 2e4;
  material.friction_coefficient = 0.5;
  LabTestOptions options;
  options.kind = LabTestKind::kConfinedCompression;
  const ConfinedEnvelope envelope =
      RunConfinedEnvelope<2>(packing, material, options, {0.0, 5e6, 1e7});
  ASSERT_EQ(envelope.tests.size(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    const LabTestResult& t = envelope.tests[k];
    EXPECT_TRUE(t.peak_reached) << t.termination_message;
    // The servo holds sigma_3 within 10 % up to the peak (after it, the failing specimen's
    // dilation outruns the servo: up to 37 % here, reported as confinement_max_error).
    const double s3 = envelope.confining_stress_pa[k];
    const CurvePeak peak = FindPeak(t.curve, options.post_peak_stress_fraction);
    for (int i = 0; s3 > 0.0 && i <= peak.index; ++i)
      ASSERT_NEAR(t.curve[i].lateral_stress_pa, s3, 0.1 * s3) << "sample " << i;
    EXPECT_GE(t.confinement_max_error, 0.0);
    if (k > 0) {
      EXPECT_GT(t.peak_stress_pa, envelope.tests[k - 1].peak_stress_pa);
    }
  }
  ASSERT_TRUE(envelope.fit.valid) << envelope.fit_message;
  EXPECT_GT(envelope.fit.cohesion_pa, 0.0);
  EXPECT_GT(envelope.fit.friction_angle_deg, 0.0);
  EXPECT_LT(envelope.fit.friction_angle_deg, 70.0);
  std::printf("biaxial: peaks %.4g %.4g %.4g MPa, c = %.4g MPa, phi = %.3g deg\n",
              envelope.tests[0].peak_stress_pa * 1e-6, envelope.tests[1].peak_stress_pa * 1e-6,
              envelope.tests[2].peak_stress_pa * 1e-6, envelope.fit.cohesion_pa * 1e-6,
              envelope.fit.friction_angle_deg);
}

}  // namespace
}  // namespace specimen
