// The map sweep: design grids, the lab tests at each point reduced to groups, the journal
// that lets a killed sweep resume, the stored map file and its packing check.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "calibrate/map_store.h"
#include "calibrate/map_sweep.h"
#include "common/error.h"
#include "generator/generate.h"
#include "generator/metrics.h"
#include "tests/generator/scratch_directory.h"

namespace specimen {
namespace {

namespace fs = std::filesystem;

Packing<2> SmallPacking(const Domain<2>& domain, int count, double mean_radius) {
  GeneratorOptions options = DefaultGeneratorOptions<2>();
  if (count > 0) options.particle_count = count;
  else options.mean_radius = mean_radius;
  options.seed = 3;
  GeneratorSummary summary;
  return GeneratePacking<2>(domain, options, &summary);
}

// One small UCS square and its Brazilian disc, shared by the tests (generated once).
struct Specimens {
  Packing<2> ucs = SmallPacking(Domain<2>::Rectangle(0, 0, 0.01, 0.01), 300, 0.0);
  Packing<2> bts = SmallPacking(Domain<2>::Disc(Vector<2>(0.005, 0.005), 0.005), 0,
                                VolumeMeanRadius<2>(ucs.radii));
};
const Specimens& Shared() {
  static const Specimens specimens;
  return specimens;
}

SweepDesign TwoByTwo() {
  SweepDesign d;
  d.fixed.friction_coefficient = 0.8;
  d.axes = {{MicroRatio::kStiffnessRatio, 0.25, 0.75, 2}, {MicroRatio::kStrengthRatio, 2.0, 6.0, 2}};
  return d;
}

MapSweepOptions SmallOptions() {
  MapSweepOptions o;
  o.normal_stiffness_n_per_m = 1e10;
  o.bond_tensile_strength_n = 2000.0;
  o.density_kg_per_m3 = 2600.0;
  o.workers = 2;
  o.test.scale_density = true;
  // The elastic range: with these strengths no bond breaks below 30 % of the peak, so nu is
  // the elastic one the Voigt estimate describes (lab/lab_test.h, "damage in the window").
  o.test.modulus_window_high = 0.3;
  return o;
}

TEST(SweepDesign, FullFactorialGridFirstAxisSlowest) {
  SweepDesign d = TwoByTwo();
  d.axes[0].levels = 3;
  const std::vector<MicroRatios> points = d.Points();
  ASSERT_EQ(points.size(), 6u);
  EXPECT_DOUBLE_EQ(points[0].tangential_to_normal_stiffness, 0.25);
  EXPECT_DOUBLE_EQ(points[1].shear_to_tensile_strength, 6.0);
  EXPECT_DOUBLE_EQ(points[2].tangential_to_normal_stiffness, 0.5);
  EXPECT_DOUBLE_EQ(points[5].tangential_to_normal_stiffness, 0.75);
  for (const MicroRatios& r : points) EXPECT_DOUBLE_EQ(r.friction_coefficient, 0.8);
  const SweepDesign back = SweepDesign::FromJson(d.ToJson());
  EXPECT_EQ(back.ToJson(), d.ToJson());
}

// The transfer anchors: a two-level design at 1/4 and 3/4 of each axis (of a geometric axis
// in equal ratios), the half fraction in three dimensions (every pair of levels of two axes
// appears once), four points at most.
TEST(SweepDesign, TransferAnchorsSpanTheBoxAtItsQuarters) {
  const std::vector<MicroRatios> two = TransferAnchorPoints(DefaultSweepDesign(false));
  ASSERT_EQ(two.size(), 4u);
  std::set<std::pair<double, double>> corners;
  for (const MicroRatios& r : two) corners.insert({r.tangential_to_normal_stiffness, r.shear_to_tensile_strength});
  EXPECT_EQ(corners.size(), 4u);
  EXPECT_TRUE(corners.count({0.15 + 0.25 * 0.75, std::pow(10.0, 0.25)}));
  EXPECT_TRUE(corners.count({0.15 + 0.75 * 0.75, std::pow(10.0, 0.75)}));
  const std::vector<MicroRatios> three = TransferAnchorPoints(DefaultSweepDesign(true, 0.45, 0.4));
  ASSERT_EQ(three.size(), 4u);
  std::set<std::pair<double, double>> pairs;
  for (const MicroRatios& r : three) {
    EXPECT_DOUBLE_EQ(r.particle_poisson_ratio, 0.45);
    pairs.insert({r.tangential_to_normal_stiffness, r.normal_stiffness_to_particle});
  }
  EXPECT_EQ(pairs.size(), 4u);  // each (kt/kn, kn/(Ep l)) pair of levels once
}

// With three levels, nine anchors more at the edges and the middle of each axis: the full
// 3 x 3 for two axes; for three, a Latin square (every pair of levels of any two axes once).
TEST(SweepDesign, ThreeLevelTransferAnchorsAddTheEdgesAndTheMiddle) {
  const SweepDesign rigid = DefaultSweepDesign(false);
  const std::vector<MicroRatios> two = TransferAnchorPoints(rigid, 2);
  const std::vector<MicroRatios> all = TransferAnchorPoints(rigid, 3);
  ASSERT_EQ(all.size(), 13u);
  for (size_t k = 0; k < two.size(); ++k)
    EXPECT_DOUBLE_EQ(all[k].tangential_to_normal_stiffness, two[k].tangential_to_normal_stiffness);
  std::set<std::pair<double, double>> grid;
  for (size_t k = 4; k < all.size(); ++k)
    grid.insert({all[k].tangential_to_normal_stiffness, all[k].shear_to_tensile_strength});
  EXPECT_EQ(grid.size(), 9u);
  for (double kt : {0.15, 0.525, 0.9})
    for (double rt : {1.0, std::sqrt(10.0), 10.0}) {
      bool found = false;
      for (const auto& [a, b] : grid) found = found || (std::abs(a - kt) < 1e-12 && std::abs(b - rt) < 1e-9);
      EXPECT_TRUE(found) << "kt/kn " << kt << ", Rt/Rn " << rt;
    }
  const SweepDesign deformable = DefaultSweepDesign(true, 0.45, 0.4);
  const std::vector<MicroRatios> three = TransferAnchorPoints(deformable, 3);
  ASSERT_EQ(three.size(), 13u);
  auto level = [&](const MicroRatios& r, int axis) {
    const SweepAxis& a = deformable.axes[axis];
    const double v = RatioValue(r, a.ratio);
    for (int l = 0; l < 3; ++l)
      if (std::abs(v - a.At(0.5 * l)) <= 1e-9 * (1.0 + std::abs(v))) return l;
    return -1;
  };
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b) {
      std::set<std::pair<int, int>> pairs;
      for (size_t k = 4; k < three.size(); ++k) {
        ASSERT_GE(level(three[k], a), 0);
        pairs.insert({level(three[k], a), level(three[k], b)});
      }
      EXPECT_EQ(pairs.size(), 9u) << "axes " << a << ", " << b;
    }
}

// A geometric axis: levels in equal ratios, and its JSON keeps the spacing.
TEST(SweepDesign, GeometricAxisLevelsInEqualRatios) {
  const SweepDesign d = DefaultSweepDesign(false);
  ASSERT_TRUE(d.axes[1].geometric);
  const std::vector<MicroRatios> points = d.Points();
  EXPECT_DOUBLE_EQ(points[0].shear_to_tensile_strength, 1.0);
  EXPECT_NEAR(points[1].shear_to_tensile_strength, std::sqrt(10.0), 1e-12);
  EXPECT_DOUBLE_EQ(points[2].shear_to_tensile_strength, 10.0);
  EXPECT_TRUE(SweepDesign::FromJson(d.ToJson()).axes[1].geometric);
  SweepDesign bad = d;
  bad.axes[0].geometric = true;
  bad.axes[0].lower = 0.0;
  std::string error;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_NE(error.find("geometric"), std::string::npos) << error;
}

TEST(SweepDesign, InvalidDesignsNameTheAxisAndRange) {
  std::string error;
  SweepDesign d = TwoByTwo();
  d.axes[0].levels = 1;
  EXPECT_FALSE(d.IsValid(&error));
  EXPECT_NE(error.find("levels of kt/kn"), std::string::npos) << error;
  d = TwoByTwo();
  d.axes[1].lower = 7.0;
  EXPECT_FALSE(d.IsValid(&error));
  EXPECT_NE(error.find("Rt/Rn"), std::string::npos) << error;
  d = TwoByTwo();
  d.axes.push_back(d.axes[0]);
  EXPECT_FALSE(d.IsValid(&error));
  EXPECT_NE(error.find("twice"), std::string::npos) << error;
  EXPECT_TRUE(DefaultSweepDesign(false).IsValid(&error)) << error;
  EXPECT_TRUE(DefaultSweepDesign(true, 0.45, 0.3).IsValid(&error)) << error;
}

// The sweep measures the trends of the Voigt estimate (Madan (4.15)-(4.16)): nu falls and E
// rises with kt/kn; the journal makes a second call run nothing; a torn line is skipped.
TEST(MapSweep, MeasuresTheVoigtTrendsAndResumesFromTheJournal) {
  const Specimens& s = Shared();
  const ScratchDirectory scratch;  // not shared with another test run on this machine
  const fs::path journal = fs::path(scratch.File("sweep_journal.jsonl"));
  MapSweepOptions options = SmallOptions();
  options.journal_path = journal.string();
  const SweepDesign design = TwoByTwo();
  const MapSweep first = RunMapSweep<2>(s.ucs, s.bts, design, options);
  ASSERT_EQ(first.points.size(), 4u);
  EXPECT_EQ(first.resumed_points, 0);
  for (const SweepPoint& p : first.points) {
    ASSERT_TRUE(p.ok) << p.failure;
    EXPECT_GT(p.elastic_group, 0.0);
    EXPECT_GT(p.compressive_group, p.tensile_group);  // sigma_c > sigma_t
    // Plane-strain Voigt nu = (1 - kt/kn) / 4; the interior of a 300-disc specimen matches
    // it to a few hundredths (lab/lab_test.h: 5,000 discs within 0.02).
    EXPECT_NEAR(p.poisson_ratio, (1.0 - p.ratios.tangential_to_normal_stiffness) / 4.0, 0.08);
  }
  // Points 0, 1 at kt/kn 0.25; 2, 3 at 0.75.
  EXPECT_GT(first.points[0].poisson_ratio, first.points[2].poisson_ratio + 0.05);
  EXPECT_LT(first.points[0].elastic_group, first.points[2].elastic_group);

  // A torn last line, as a kill in the middle of a write leaves it.
  {
    std::ofstream out(journal, std::ios::app);
    out << "{\"design\": \"trunc";
  }
  const MapSweep again = RunMapSweep<2>(s.ucs, s.bts, design, options);
  EXPECT_EQ(again.resumed_points, 4);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(again.points[i].ToJson(), first.points[i].ToJson());

  // Another design does not reuse these points.
  SweepDesign other = design;
  other.fixed.friction_coefficient = 0.5;
  other.axes = {{MicroRatio::kStiffnessRatio, 0.25, 0.75, 2}};
  options.workers = 1;
  const MapSweep other_sweep = RunMapSweep<2>(s.ucs, s.bts, other, options);
  EXPECT_EQ(other_sweep.resumed_points, 0);
  fs::remove(journal);
}

// The ratios as the map files store them: a bond range is written only when it is not 1, so
// maps built without it keep their keys (and the shipped maps stay found).
TEST(SweepDesign, RatiosRoundTripAndABondRangeChangesTheKeyOnlyWhenSet) {
  MicroRatios r;
  r.tangential_to_normal_stiffness = 0.3;
  r.shear_to_tensile_strength = 4.0;
  r.friction_coefficient = 0.8;
  EXPECT_FALSE(SweepPointRatiosToJson(r).contains("bond_range"));
  EXPECT_EQ(SweepPointRatiosFromJson(SweepPointRatiosToJson(r)).bond_range, 1.0);
  r.bond_range = 1.25;
  const MicroRatios back = SweepPointRatiosFromJson(SweepPointRatiosToJson(r));
  EXPECT_EQ(back.bond_range, 1.25);
  EXPECT_EQ(back.shear_to_tensile_strength, 4.0);
  EXPECT_EQ(MaterialAt(back, 1e10, 1e4, 2600.0, PlaneModel::kPlaneStrain, 1.0).bond_range, 1.25);
}

TEST(MapSweep, BadOptionsAreRefusedBeforeAnyWork) {
  const Specimens& s = Shared();
  MapSweepOptions options = SmallOptions();
  options.normal_stiffness_n_per_m = -1.0;
  try {
    RunMapSweep<2>(s.ucs, s.bts, TwoByTwo(), options);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("normal_stiffness"), std::string::npos) << e.what();
  }
  options = SmallOptions();
  options.journal_path = "/nonexistent-directory/journal.jsonl";
  EXPECT_THROW(RunMapSweep<2>(s.ucs, s.bts, TwoByTwo(), options), FileError);
}

// Synthetic points on known functions: the stored file round-trips, the elastic surfaces
// ignore Rt/Rn, a map is refused for a packing of another porosity.
TEST(MapStore, RoundTripAndPackingCheck) {
  MapSweep sweep;
  SweepDesign design;
  design.axes = {{MicroRatio::kStiffnessRatio, 0.1, 0.9, 4}, {MicroRatio::kStrengthRatio, 2.0, 10.0, 3}};
  int index = 0;
  for (const MicroRatios& r : design.Points()) {
    SweepPoint p;
    p.index = index++;
    p.ratios = r;
    p.ok = true;
    const double x = r.tangential_to_normal_stiffness, y = r.shear_to_tensile_strength;
    p.poisson_ratio = (1.0 - x) / 4.0;
    p.elastic_group = 0.2 + 0.1 * x;
    p.compressive_group = 0.3 + 0.05 * y;
    p.tensile_group = 0.1 + 0.01 * y - 0.02 * x;
    p.ucs_pa = 1e8;
    p.tensile_strength_pa = 1e7;
    p.youngs_modulus_pa = 1e10;
    sweep.points.push_back(p);
  }
  StoredMaps stored;
  stored.design = design;
  stored.points = sweep.points;
  stored.maps = FitMaps(sweep, design, 2);
  stored.ucs_descriptors.dimension = 2;
  stored.ucs_descriptors.porosity = 0.10;
  stored.ucs_descriptors.coordination = 5.8;
  stored.ucs_descriptors.radius_ratio = 8.0;
  stored.bts_descriptors = stored.ucs_descriptors;
  stored.code_version = "test";
  stored.key = MapKey(2, false, design, {}, {}, 2);
  EXPECT_EQ(stored.maps.poisson_ratio.Gradient(Eigen::Vector2d(0.5, 4.0))[1], 0.0);
  EXPECT_NEAR(stored.maps.poisson_ratio.Evaluate(Eigen::Vector2d(0.5, 7.0)), 0.125, 1e-9);

  const ScratchDirectory scratch;
  const fs::path path = fs::path(scratch.File("maps_test.json"));
  SaveStoredMaps(stored, path.string());
  const StoredMaps back = LoadStoredMaps(path.string());
  EXPECT_EQ(back.key, stored.key);
  EXPECT_EQ(back.points.size(), stored.points.size());
  const Eigen::Vector2d x(0.37, 5.5);
  EXPECT_DOUBLE_EQ(back.maps.compressive_group.Evaluate(x), stored.maps.compressive_group.Evaluate(x));
  EXPECT_DOUBLE_EQ(back.maps.elastic_group.Evaluate(x), stored.maps.elastic_group.Evaluate(x));
  EXPECT_EQ(back.maps.Lower(), stored.maps.Lower());

  // A box bound that differs in its last digits (an eigenvalue bound from another build) has
  // the same key; a real difference does not.
  SweepDesign noisy = design;
  noisy.axes[0].upper = std::nextafter(noisy.axes[0].upper, 1.0) * (1.0 + 4e-16);
  EXPECT_EQ(MapKey(2, false, noisy, {}, {}, 2), stored.key);
  noisy.axes[0].upper = design.axes[0].upper * (1.0 + 1e-4);
  EXPECT_NE(MapKey(2, false, noisy, {}, {}, 2), stored.key);
  // Found under its own name, and by content under a name an earlier version gave it.
  EXPECT_EQ(FindStoredMapFile(scratch.path(), 2, false, stored.key), "");
  const fs::path named = fs::path(scratch.File(MapFileName(2, false, stored.key)));
  SaveStoredMaps(stored, named.string());
  EXPECT_EQ(FindStoredMapFile(scratch.path(), 2, false, stored.key), named.string());
  const fs::path renamed = fs::path(scratch.File(MapFileName(2, false, "0123456789abcdef")));
  fs::rename(named, renamed);
  EXPECT_EQ(FindStoredMapFile(scratch.path(), 2, false, stored.key), renamed.string());
  EXPECT_EQ(FindStoredMapFile(scratch.path(), 2, true, stored.key), "");  // another model
  EXPECT_EQ(FindStoredMapFile(scratch.path(), 2, false, MapKey(2, false, noisy, {}, {}, 2)), "");
  fs::remove(renamed);

  std::string why;
  PackingDescriptors other = stored.ucs_descriptors;
  EXPECT_TRUE(MapsMatchPacking(stored.ucs_descriptors, other, &why));
  other.porosity = 0.14;
  EXPECT_FALSE(MapsMatchPacking(stored.ucs_descriptors, other, &why));
  EXPECT_NE(why.find("porosity"), std::string::npos) << why;
  other = stored.ucs_descriptors;
  other.dimension = 3;
  EXPECT_FALSE(MapsMatchPacking(stored.ucs_descriptors, other, &why));

  {
    std::ofstream out(path);
    out << "{\"format\": \"specimen-maps 1\", \"dimension\": 2";  // truncated
  }
  EXPECT_THROW(LoadStoredMaps(path.string()), InputError);
  {
    std::ofstream out(path);
    out << "{\"format\": \"something else\"}";
  }
  EXPECT_THROW(LoadStoredMaps(path.string()), InputError);
  fs::remove(path);
  EXPECT_THROW(LoadStoredMaps(path.string()), FileError);
}

}  // namespace
}  // namespace specimen
