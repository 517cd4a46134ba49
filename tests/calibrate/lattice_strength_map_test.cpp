// The lattice's strength map (calibrate/lattice_strength_map.h) on a closed-form stand-in for
// the two lattice tests, so that the reach, the start and the rounds from a map are checked in
// milliseconds: a target made by the stand-in at hidden triangle strengths is met from the
// map's start; a UCS / sigma_t below the map's floor is declared out of reach before round 1;
// a map biased against the tests (as the map's strain scale is against a target's) is
// corrected by the rounds; the file is found only for equivalent specimens and the same tests.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "calibrate/lattice_calibration.h"
#include "calibrate/lattice_strength_map.h"
#include "common/error.h"

namespace specimen {
namespace {

// The UCS blends the triangles' Mohr-Coulomb UCS (specimen factor 0.9) with a tension cut-off
// at 12 sigma_t, harmonically, and rises with nu; the Brazilian strength blends 0.7 sigma_t
// with a shear cap 0.25 c (1 + sin phi). UCS / sigma_B then falls from about 17 at small
// sigma_t / c to about 8 at large. `ucs_bias` and `bts_bias` scale the results.
struct StandIn {
  double ucs_bias = 1.0, bts_bias = 1.0;
  int calls = 0;

  LatticeRoundMeasurement operator()(const LatticeMaterial& m, int) {
    ++calls;
    const double c = m.strength.cohesion_pa, t = m.strength.tensile_strength_pa;
    const double phi = m.strength.friction_angle_deg * 3.14159265358979323846 / 180.0;
    const PlaneElasticity& d = m.elasticity;  // plane strain: nu = d12 / (d11 + d12)
    const double nu = d.d12 / (d.d11 + d.d12);
    LatticeRoundMeasurement r;
    r.ucs_pa = ucs_bias * (1.0 + 0.2 * nu) / (1.0 / (0.9 * m.strength.TriangleCompressiveStrength()) + 1.0 / (12.0 * t));
    r.bts_pa = bts_bias / (1.0 / (0.7 * t) + 1.0 / (0.25 * c * (1.0 + std::sin(phi))));
    r.youngs_modulus_pa = d.d11 * (1.0 + nu) * (1.0 - 2.0 * nu) / (1.0 - nu);
    r.poisson_ratio = nu;
    r.critical_time_step_s = 1e-8;
    return r;
  }
};

LatticeMaterial Material(double nu, double c, double sigma_t, double phi) {
  LatticeMaterial m;
  m.elasticity = IsotropicPlaneElasticity(30e9, nu, PlaneModel::kPlaneStrain);
  m.density_kg_per_m3 = 2600.0;
  m.strength = {sigma_t, c, phi};
  return m;
}

// The target the stand-in gives at hidden triangle strengths (nu 0.2, between the rows).
TargetMaterial Twin(double c, double sigma_t, double phi) {
  StandIn truth;
  const LatticeRoundMeasurement r = truth(Material(0.2, c, sigma_t, phi), 0);
  TargetMaterial t;
  t.name = "twin";
  t.youngs_modulus_pa = r.youngs_modulus_pa;
  t.poisson_ratio = 0.2;
  t.ucs_pa = r.ucs_pa;
  t.tensile_strength_pa = r.bts_pa;
  t.density_kg_per_m3 = 2600.0;
  return t;
}

LatticeStrengthMap MapOf(StandIn& model) {
  LatticeStrengthMap map;
  MeasureLatticeMapRows({0.15, 0.25}, [&](const LatticeMaterial& m, int r) { return model(m, r); }, nullptr, &map);
  return map;
}

TEST(LatticeStrengthMap, ItsStartMeetsATwinTargetOnTheStandIn) {
  StandIn model;
  const LatticeStrengthMap map = MapOf(model);
  ASSERT_TRUE(map.Covers(0.2));
  const TargetMaterial target = Twin(40e6, 10e6, 30.0);
  const LatticeMapStart start = StartFromMap(map, target);
  SCOPED_TRACE(start.statement);
  EXPECT_TRUE(start.reachable);
  EXPECT_EQ(start.friction_angle_deg, 30.0);  // reachable at the preferred angle
  // The stand-in at the start gives the target within the interpolation's error.
  StandIn check;
  const LatticeRoundMeasurement r =
      check(Material(0.2, start.cohesion_pa, start.tensile_strength_pa, start.friction_angle_deg), 0);
  EXPECT_NEAR(r.ucs_pa / target.ucs_pa, 1.0, 0.02);
  EXPECT_NEAR(r.bts_pa / target.tensile_strength_pa, 1.0, 0.05);
  EXPECT_NEAR(start.cohesion_pa / 40e6, 1.0, 0.05);
  // The rounds from it end in round 1 or 2; from the closed form they take longer.
  LatticeCalibrationOptions options;
  options.map = map;
  StandIn rounds_with_map, rounds_without;
  const LatticeCalibrationSummary with_map =
      CalibrateLattice(target, options, [&](const LatticeMaterial& m, int k) { return rounds_with_map(m, k); });
  options.map.reset();
  const LatticeCalibrationSummary without =
      CalibrateLattice(target, options, [&](const LatticeMaterial& m, int k) { return rounds_without(m, k); });
  EXPECT_TRUE(with_map.converged);
  EXPECT_TRUE(with_map.map_used);
  EXPECT_LE(rounds_with_map.calls, 2);
  EXPECT_LT(rounds_with_map.calls, rounds_without.calls);
}

// Below the floor (about 8 at 50 degrees and the largest sigma_t / c): out of reach before
// round 1, the interval given, sigma_t given up from the start and the UCS met.
TEST(LatticeStrengthMap, ARatioBelowItsFloorIsOutOfReachBeforeRoundOne) {
  StandIn model;
  const LatticeStrengthMap map = MapOf(model);
  TargetMaterial target = Twin(40e6, 10e6, 30.0);
  target.tensile_strength_pa = target.ucs_pa / 5.0;
  const LatticeMapStart start = StartFromMap(map, target);
  SCOPED_TRACE(start.statement);
  EXPECT_FALSE(start.reachable);
  EXPECT_NE(start.statement.find("out of the lattice's reach"), std::string::npos);
  // The floor is the smallest ratio the map gives at nu 0.2 at its grid's (phi, s).
  double floor = 1e9;
  for (double phi : map.design.friction_angles_deg)
    for (double s : map.design.tensile_over_cohesion) floor = std::min(floor, map.At(0.2, phi, s).StrengthRatio());
  EXPECT_NEAR(start.ratio_low / floor, 1.0, 1e-3);
  EXPECT_GT(start.ratio_low, 5.0);
  LatticeCalibrationOptions options;
  options.map = map;
  StandIn rounds;
  const LatticeCalibrationSummary s =
      CalibrateLattice(target, options, [&](const LatticeMaterial& m, int k) { return rounds(m, k); });
  EXPECT_FALSE(s.map_reachable);
  EXPECT_TRUE(s.tensile_capped);
  EXPECT_NE(s.notes.front().find("before round 1"), std::string::npos);
  EXPECT_LE(std::abs(s.rounds[s.best_round - 1].error_ucs), options.tolerance_ucs);
  EXPECT_LE(rounds.calls, 3);
}

// The tests give a UCS 6 % above the map and a Brazilian strength 8 % below (the transfer
// error of the map's strain scale is of that size): the rounds correct it, within 4 rounds.
TEST(LatticeStrengthMap, ABiasedMapIsCorrectedByTheRounds) {
  StandIn model;
  const LatticeStrengthMap map = MapOf(model);
  const TargetMaterial target = Twin(25e6, 12e6, 30.0);
  LatticeCalibrationOptions options;
  options.map = map;
  StandIn biased;
  biased.ucs_bias = 1.06;
  biased.bts_bias = 0.92;
  const LatticeCalibrationSummary s =
      CalibrateLattice(target, options, [&](const LatticeMaterial& m, int k) { return biased(m, k); });
  std::string trace;
  for (const LatticeCalibrationRound& r : s.rounds)
    trace += std::to_string(r.round) + ": UCS " + std::to_string(100 * r.error_ucs) + " %, sigma_t " +
             std::to_string(100 * r.error_tensile) + " %\n";
  SCOPED_TRACE(trace);
  EXPECT_TRUE(s.converged);
  EXPECT_FALSE(s.tensile_capped);
  EXPECT_LE(biased.calls, 4);
}

TEST(LatticeStrengthMap, IsFoundOnlyForEquivalentSpecimensAndTheSameTests) {
  StandIn model;
  LatticeStrengthMap map = MapOf(model);
  map.ucs_descriptors.particles = 5000;
  map.ucs_descriptors.porosity = 0.15;
  map.ucs_descriptors.coordination = 4.0;
  map.ucs_descriptors.radius_ratio = 10.0;
  map.bts_descriptors = map.ucs_descriptors;
  map.bts_descriptors.particles = 3900;
  LabTestOptions test;
  LatticeProtocol protocol;
  map.protocol = LatticeMapProtocol(test, protocol);
  const std::filesystem::path directory = std::filesystem::path(testing::TempDir()) / "lattice_map_find";
  std::filesystem::remove_all(directory);
  std::filesystem::create_directories(directory);
  const std::string path =
      (directory / LatticeMapFileName(map.ucs_descriptors, map.bts_descriptors, map.protocol)).string();
  SaveLatticeStrengthMap(map, path);
  const LatticeStrengthMap loaded = LoadLatticeStrengthMap(path);
  ASSERT_EQ(loaded.points.size(), map.points.size());
  EXPECT_DOUBLE_EQ(loaded.At(0.2, 22.0, 0.3).ucs_over_cohesion, map.At(0.2, 22.0, 0.3).ucs_over_cohesion);
  EXPECT_EQ(FindLatticeStrengthMap(directory.string(), map.ucs_descriptors, map.bts_descriptors, map.protocol), path);
  PackingDescriptors other = map.ucs_descriptors;
  other.porosity = 0.2;
  EXPECT_EQ(FindLatticeStrengthMap(directory.string(), other, map.bts_descriptors, map.protocol), "");
  other = map.ucs_descriptors;
  other.particles = 20000;  // the strengths depend on the specimen's size
  EXPECT_EQ(FindLatticeStrengthMap(directory.string(), other, map.bts_descriptors, map.protocol), "");
  LatticeProtocol point_load = protocol;
  point_load.loading_arc_deg = 0.0;  // the Brazilian strength depends on the jaws
  EXPECT_EQ(FindLatticeStrengthMap(directory.string(), map.ucs_descriptors, map.bts_descriptors,
                                   LatticeMapProtocol(test, point_load)),
            "");
  LabTestOptions faster = test;
  faster.loading_rate_group *= 2.0;
  EXPECT_EQ(FindLatticeStrengthMap(directory.string(), map.ucs_descriptors, map.bts_descriptors,
                                   LatticeMapProtocol(faster, protocol)),
            "");
  // Rows: 0.15 and 0.25 interpolate 0.2; 0.3 lies beyond; a row missing a point is no row,
  // and a point off the grid does not stand in for it.
  EXPECT_TRUE(map.Covers(0.2));
  EXPECT_FALSE(map.Covers(0.3));
  const LatticeMapPoint last = map.points.back();
  map.points.pop_back();
  EXPECT_FALSE(map.Covers(0.2));
  EXPECT_TRUE(map.Covers(0.15));
  LatticeMapPoint off_grid = last;
  off_grid.tensile_over_cohesion *= 1.3;
  map.points.push_back(off_grid);
  EXPECT_FALSE(map.Covers(0.2));
  EXPECT_THROW(map.At(0.25, 30.0, 0.3), InputError);
  // The rows a nu needs: on a row, the two around it, its own beyond the grid.
  const LatticeMapDesign grid;
  EXPECT_EQ(grid.RowsFor(0.252), std::vector<double>({0.25}));
  EXPECT_EQ(grid.RowsFor(0.2), std::vector<double>({0.15, 0.25}));
  EXPECT_EQ(grid.RowsFor(0.02), std::vector<double>({0.02}));
  std::filesystem::remove_all(directory);
}

// Two runs that add rows to one map file: the second, merging what the file holds before it
// writes, keeps the first's rows; an incomplete row of its own is replaced by a complete
// stored one, and a row it has is not duplicated.
TEST(LatticeStrengthMap, RowsStoredByAnotherRunAreMergedNotLost) {
  StandIn model;
  auto measure = [&](const LatticeMaterial& m, int r) { return model(m, r); };
  LatticeStrengthMap first, second;
  MeasureLatticeMapRows({0.15}, measure, nullptr, &first);
  MeasureLatticeMapRows({0.25, 0.35}, measure, nullptr, &second);
  const size_t row = first.points.size();
  second.points.pop_back();  // the 0.35 row incomplete
  EXPECT_EQ(MergeLatticeMapRows(first, &second), 1);
  EXPECT_EQ(second.Rows(), std::vector<double>({0.15, 0.25}));
  EXPECT_EQ(second.points.size(), 3 * row - 1);
  EXPECT_EQ(MergeLatticeMapRows(first, &second), 0);
  LatticeStrengthMap complete;
  MeasureLatticeMapRows({0.35}, measure, nullptr, &complete);
  EXPECT_EQ(MergeLatticeMapRows(complete, &second), 1);
  EXPECT_EQ(second.Rows(), std::vector<double>({0.15, 0.25, 0.35}));
  EXPECT_EQ(second.points.size(), 3 * row);
  EXPECT_TRUE(second.Covers(0.2));
  // Another grid's rows (complete on their own grid) are not merged.
  LatticeStrengthMap other;
  other.design.friction_angles_deg = {10.0, 30.0};
  MeasureLatticeMapRows({0.05}, measure, nullptr, &other);
  ASSERT_EQ(other.Rows(), std::vector<double>({0.05}));
  EXPECT_EQ(MergeLatticeMapRows(other, &second), 0);
  EXPECT_EQ(second.Rows(), std::vector<double>({0.15, 0.25, 0.35}));
}

}  // namespace
}  // namespace specimen
