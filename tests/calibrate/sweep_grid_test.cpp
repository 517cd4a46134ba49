// The sweep grid interpolant (calibrate/sweep_grid.h) and its use by the surrogate.
#include <cmath>

#include <gtest/gtest.h>

#include "calibrate/map_sweep.h"
#include "calibrate/surrogate.h"
#include "calibrate/sweep_grid.h"

namespace specimen {
namespace {

// The DDEM design: kt/kn, kn/(Ep l) linear, Rt/Rn geometric; 3 levels each.
SweepDesign Design() { return DefaultSweepDesign(/*deformable=*/true, 0.45, 0.5, 0.8); }

// ln(Psi_c / Psi_t) quadratic in each of kt/kn, kn/(Ep l), ln(Rt/Rn) (with a product term and
// a peak inside the kt/kn axis, as the DDEM maps have): the interpolant reproduces it anywhere.
double LogRatio(const MicroRatios& r) {
  const double s = r.tangential_to_normal_stiffness, c = r.normal_stiffness_to_particle,
               u = std::log(r.shear_to_tensile_strength);
  return 2.0 + 0.4 * u - 6.0 * (s - 0.4) * (s - 0.4) * u - 0.5 * c * u + 0.3 * c * c;
}

std::vector<SweepPoint> Points(const SweepDesign& design) {
  std::vector<SweepPoint> points;
  const std::vector<MicroRatios> grid = design.Points();
  for (size_t i = 0; i < grid.size(); ++i) {
    SweepPoint p;
    p.index = static_cast<int>(i);
    p.ratios = grid[i];
    p.ok = true;
    p.elastic_group = 0.25;
    p.poisson_ratio = 0.25 - 0.2 * grid[i].tangential_to_normal_stiffness + 0.1 * grid[i].normal_stiffness_to_particle;
    p.tensile_group = 0.05;
    p.compressive_group = 0.05 * std::exp(LogRatio(grid[i]));
    points.push_back(p);
  }
  return points;
}

MicroRatios At(double s, double c, double x) {
  MicroRatios r = Design().fixed;
  r.tangential_to_normal_stiffness = s, r.normal_stiffness_to_particle = c, r.shear_to_tensile_strength = x;
  return r;
}

TEST(SweepGrid, ReproducesAQuadraticPerAxisAnywhereInTheBox) {
  const SweepGrid grid(Design(), Points(Design()));
  ASSERT_TRUE(grid.valid());
  for (double s : {0.15, 0.22, 0.375, 0.41, 0.6})
    for (double c : {0.0, 0.13, 0.5})
      for (double x : {1.0, 2.2, 3.1622776601683795, 7.9, 10.0})
        EXPECT_NEAR(grid.LogGroupRatio(At(s, c, x)), LogRatio(At(s, c, x)), 1e-10) << s << " " << c << " " << x;
  // Outside the box: the value at the nearest face.
  EXPECT_NEAR(grid.LogGroupRatio(At(0.7, 0.25, 20.0)), LogRatio(At(0.6, 0.25, 10.0)), 1e-10);
}

TEST(SweepGrid, AnUnmeasuredPointLeavesNoGrid) {
  std::vector<SweepPoint> points = Points(Design());
  points[5].ok = false;
  EXPECT_FALSE(SweepGrid(Design(), points).valid());
  points.erase(points.begin() + 5);
  EXPECT_FALSE(SweepGrid(Design(), points).valid());
  EXPECT_FALSE(SweepGrid().valid());
}

// A 5,000-disc specimen's descriptors, the same for both tests, and the sweep of Points on it.
PackingDescriptors Specimen() {
  PackingDescriptors specimen;
  specimen.dimension = 2, specimen.particles = 5000, specimen.porosity = 0.094, specimen.coordination = 5.83;
  specimen.mean_radius = 3.77e-4, specimen.radius_ratio = 9.0, specimen.mean_radius_squared = 1.3e-7;
  specimen.mean_branch_length = 6.6e-4, specimen.mean_branch_length_squared = 4.6e-7;
  return specimen;
}

MapSweep Sweep(const SweepDesign& design) {
  MapSweep sweep;
  sweep.points = Points(design);
  sweep.ucs_descriptors = sweep.bts_descriptors = Specimen();
  return sweep;
}

TEST(SweepGrid, TheSurrogateCorrectsItByTheMeasurements) {
  const SweepDesign design = Design();
  const std::vector<SweepPoint> points = Points(design);
  const PackingDescriptors specimen = Specimen();
  const MapSet maps = FitMaps(Sweep(design), design, /*max_total_degree=*/2);
  CalibrationSurrogate surrogate(maps, specimen, specimen);
  const MicroRatios r = At(0.3, 0.2, 6.0);
  EXPECT_DOUBLE_EQ(surrogate.GridStrengthRatio(r), surrogate.StrengthRatio(r));  // no grid yet
  surrogate.SetSweepGrid(SweepGrid(design, points));
  ASSERT_TRUE(surrogate.HasSweepGrid());
  // Same descriptors for both tests: the ratio of the groups is the specimens' ratio.
  EXPECT_NEAR(std::log(surrogate.GridStrengthRatio(r)), LogRatio(r), 1e-10);
  // A measurement 20 % above the grid shifts it by that factor (the only correction there).
  SurrogateMeasurement m;
  m.ratios = At(0.45, 0.3, 4.0);
  m.tensile_per_strength = 1.0;
  m.ucs_per_strength = 1.2 * std::exp(LogRatio(m.ratios));
  surrogate.AddMeasurement(m, /*stored=*/false);
  EXPECT_NEAR(surrogate.GridStrengthRatio(r) / std::exp(LogRatio(r)), 1.2, 1e-9);
}

// Five rounds at one elastic set (Rt/Rn 3 to 8), 20 % below the grid, and one measurement at
// another kt/kn, 20 % above: halfway between the sets the five share one point's weight (the
// correction leans to the single one, which is nearer in Rt/Rn); at the rounds' set, theirs.
TEST(SweepGrid, RoundsAtOneElasticSetCountAsOnePointAwayFromIt) {
  const SweepDesign design = Design();
  const PackingDescriptors specimen = Specimen();
  CalibrationSurrogate surrogate(FitMaps(Sweep(design), design, 2), specimen, specimen);
  surrogate.SetSweepGrid(SweepGrid(design, Points(design)));
  auto add = [&](const MicroRatios& r, double factor) {
    SurrogateMeasurement m;
    m.ratios = r;
    m.tensile_per_strength = 1.0;
    m.ucs_per_strength = factor * std::exp(LogRatio(r));
    surrogate.AddMeasurement(m, /*stored=*/false);
  };
  for (double x : {3.0, 4.0, 5.0, 6.5, 8.0}) add(At(0.5, 0.2, x), 0.8);
  add(At(0.2, 0.2, 5.0), 1.2);
  auto correction = [&](const MicroRatios& r) { return std::log(surrogate.GridStrengthRatio(r)) - LogRatio(r); };
  const double halfway = correction(At(0.35, 0.2, 5.0));
  EXPECT_GT(halfway, 0.5 * (std::log(1.2) + std::log(0.8)));  // counted one by one: -0.14
  EXPECT_LT(halfway, std::log(1.2));
  EXPECT_NEAR(correction(At(0.5, 0.2, 5.0)), std::log(0.8), 0.01);
}

// The leave-one-out errors of the correction: none where every stored measurement is off the
// grid by the same factor; where one is off by 30 % more than the rest, that one's is about
// ln 1.3 (the others predict it) and the others' small.
TEST(SweepGrid, LeaveOneOutErrorsOfTheCorrectionAtTheStoredMeasurements) {
  const SweepDesign design = Design();
  const PackingDescriptors specimen = Specimen();
  auto surrogate_with = [&](double outlier) {
    CalibrationSurrogate s(FitMaps(Sweep(design), design, 2), specimen, specimen);
    s.SetSweepGrid(SweepGrid(design, Points(design)));
    const std::vector<MicroRatios> anchors = TransferAnchorPoints(design, 3);
    for (size_t k = 0; k < anchors.size(); ++k) {
      SurrogateMeasurement m;
      m.ratios = anchors[k];
      m.tensile_per_strength = 1.0;
      m.ucs_per_strength = 0.8 * (k == 6 ? outlier : 1.0) * std::exp(LogRatio(m.ratios));
      s.AddMeasurement(m, /*stored=*/true);
    }
    // A run of this calibration (not stored) takes no part.
    SurrogateMeasurement run;
    run.ratios = At(0.3, 0.2, 6.0);
    run.tensile_per_strength = 1.0;
    run.ucs_per_strength = 3.0 * std::exp(LogRatio(run.ratios));
    s.AddMeasurement(run, /*stored=*/false);
    return s;
  };
  const std::vector<double> uniform = surrogate_with(1.0).StoredStrengthRatioLeaveOneOut();
  ASSERT_EQ(uniform.size(), 13u);
  for (double e : uniform) EXPECT_NEAR(e, 0.0, 1e-9);
  const std::vector<double> one_off = surrogate_with(1.3).StoredStrengthRatioLeaveOneOut();
  ASSERT_EQ(one_off.size(), 13u);
  EXPECT_NEAR(one_off[6], std::log(1.3), 1e-9);
  for (size_t k = 0; k < one_off.size(); ++k)
    if (k != 6) {
      EXPECT_LT(std::abs(one_off[k]), 0.5 * std::log(1.3)) << k;
    }
}

}  // namespace
}  // namespace specimen
