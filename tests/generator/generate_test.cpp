// End-to-end tests of the generator on small specimens (the large cases are benchmarks).
#include "generator/generate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "common/error.h"
#include "generator/metrics.h"

namespace specimen {
namespace {

template <int Dim>
Packing<Dim> Generate(const Domain<Dim>& domain, int count, std::uint64_t seed,
                      GeneratorSummary* summary = nullptr) {
  GeneratorOptions options = DefaultGeneratorOptions<Dim>();
  options.particle_count = count;
  options.seed = seed;
  return GeneratePacking<Dim>(domain, options, summary);
}

// The end-to-end case of docs/generator.md, "Validation": ~2,000 discs, porosity <= 12 %,
// nc >= 5.5, nothing outside the domain, fabric 0.5 +- 0.03.
TEST(GeneratePacking, TwoThousandDiscsInASquare) {
  GeneratorSummary summary;
  const auto packing = Generate<2>(Domain<2>::Rectangle(0, 0, 20, 20), 2000, 1, &summary);
  const auto m = ComputePackingMetrics<2>(packing);
  EXPECT_NEAR(m.particle_count, 2000, 200) << summary.FullReport();
  EXPECT_LE(m.nominal_porosity, 0.12);
  EXPECT_GE(m.coordination_number, 5.5);
  EXPECT_EQ(m.protruding_particles, 0);
  EXPECT_EQ(m.max_protrusion, 0.0);
  EXPECT_EQ(m.overlapping_pairs, 0);
  EXPECT_NEAR(m.fabric_eigenvalues[0], 0.5, 0.03);
  EXPECT_NEAR(m.fabric_eigenvalues[1], 0.5, 0.03);
  EXPECT_LE(m.radius_ratio, 10.0 + 1e-9);
  // Contacts honour the tolerance.
  for (const auto& c : packing.contacts)
    EXPECT_LE(std::abs(packing.Gap(c[0], c[1])), 0.02 * m.mean_radius * (1 + 1e-12));
}

// keep_small_overlaps: the final projection leaves overlaps up to overlap_tolerance x the
// mean radius (and no protrusion), so the packing is at least as dense as the exact one of
// the same seed, and every overlapping pair is a contact of the output.
TEST(GeneratePacking, KeepSmallOverlapsIsDenserAndWithinTheTolerance) {
  const auto domain = Domain<2>::Rectangle(0, 0, 20, 20);
  GeneratorOptions options = DefaultGeneratorOptions<2>();
  options.particle_count = 2000;
  GeneratorSummary summary;
  const auto exact = GeneratePacking<2>(domain, options, &summary);
  options.keep_small_overlaps = true;
  const auto kept = GeneratePacking<2>(domain, options, &summary);
  const auto m_exact = ComputePackingMetrics<2>(exact);
  const auto m_kept = ComputePackingMetrics<2>(kept);
  EXPECT_EQ(m_exact.overlapping_pairs, 0);
  EXPECT_GT(m_kept.overlapping_pairs, 0);
  // Within the tolerance against the final mean radius, with no round-off slack.
  EXPECT_LE(m_kept.max_overlap, options.overlap_tolerance);
  EXPECT_EQ(m_kept.max_protrusion, 0.0);
  EXPECT_LT(m_kept.nominal_porosity, m_exact.nominal_porosity);
  // A looser bound, 2 % of the mean radius: denser still, and within it.
  options.overlap_tolerance = 0.02;
  const auto loose = ComputePackingMetrics<2>(GeneratePacking<2>(domain, options, &summary));
  EXPECT_LE(loose.max_overlap, 0.02);
  EXPECT_GT(loose.max_overlap, 0.01);
  EXPECT_LT(loose.nominal_porosity, m_kept.nominal_porosity);
  for (int i = 0; i < kept.size(); ++i)
    for (int j = i + 1; j < kept.size(); ++j)
      if (kept.Gap(i, j) < 0.0) {
        EXPECT_TRUE(std::binary_search(kept.contacts.begin(), kept.contacts.end(),
                                       std::array<int, 2>{i, j}))
            << i << " " << j;
      }
}

TEST(GeneratePacking, SameSeedSameOutputDifferentSeedDifferentOutput) {
  const auto domain = Domain<2>::Rectangle(0, 0, 10, 10);
  const auto a = Generate<2>(domain, 500, 42);
  const auto b = Generate<2>(domain, 500, 42);
  const auto c = Generate<2>(domain, 500, 43);
  ASSERT_EQ(a.size(), b.size());
  for (int i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.radii[i], b.radii[i]);
    EXPECT_EQ(a.centres[i], b.centres[i]);
  }
  EXPECT_EQ(a.contacts, b.contacts);
  EXPECT_TRUE(a.size() != c.size() || a.radii != c.radii);
}

TEST(GeneratePacking, DiscAndNonConvexPolygonDomains) {
  for (const auto& domain :
       {Domain<2>::Disc(Vector<2>(0, 0), 5.0),
        Domain<2>::Polygon({{0, 0}, {10, 0}, {10, 4}, {4, 4}, {4, 10}, {0, 10}})}) {
    const auto packing = Generate<2>(domain, 800, 3);
    const auto m = ComputePackingMetrics<2>(packing);
    EXPECT_EQ(m.protruding_particles, 0) << domain.ToText();
    EXPECT_EQ(m.overlapping_pairs, 0) << domain.ToText();
    EXPECT_LE(m.nominal_porosity, 0.15) << domain.ToText();
    EXPECT_GE(m.coordination_number, 5.0) << domain.ToText();
  }
}

TEST(GeneratePacking, SmallCylinderIn3D) {
  GeneratorSummary summary;
  const auto packing = Generate<3>(Domain<3>::Cylinder(0, 0, 0.5, 0, 1), 1500, 1, &summary);
  const auto m = ComputePackingMetrics<3>(packing);
  EXPECT_GT(m.particle_count, 1200) << summary.FullReport();
  EXPECT_EQ(m.protruding_particles, 0);
  EXPECT_EQ(m.overlapping_pairs, 0);
  EXPECT_LE(m.nominal_porosity, 0.45);
  EXPECT_GE(m.coordination_number, 5.0);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(m.fabric_eigenvalues[k], 1.0 / 3.0, 0.03);
}

// A 3D packing with exact contacts: no overlap or protrusion, r_max / r_min <= 10, fabric
// 1/3 +- 0.03, every contact within the default 2 % tolerance.
void ExpectCleanAndIsotropic(const Packing<3>& packing, const PackingMetrics<3>& m) {
  EXPECT_EQ(m.overlapping_pairs, 0);
  EXPECT_EQ(m.max_overlap, 0.0);
  EXPECT_EQ(m.protruding_particles, 0);
  EXPECT_EQ(m.max_protrusion, 0.0);
  EXPECT_LE(m.radius_ratio, 10.0 + 1e-9);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(m.fabric_eigenvalues[k], 1.0 / 3.0, 0.03);
  for (const auto& c : packing.contacts)
    EXPECT_LE(std::abs(packing.Gap(c[0], c[1])), 0.02 * m.mean_radius * (1 + 1e-12));
}

// The 3D default compacts after the rounds (generator/compaction.h): on the same seed it is
// denser than without, still without overlap or protrusion, and still isotropic.
TEST(GeneratePacking, CompactionInASmallCylinderIsDenserAndClean) {
  const auto cylinder = Domain<3>::Cylinder(0, 0, 0.5, 0, 1);
  GeneratorOptions options = DefaultGeneratorOptions<3>();
  ASSERT_TRUE(options.compaction);
  options.particle_count = 1500;
  options.seed = 2;
  GeneratorSummary with_summary;
  const auto with = GeneratePacking<3>(cylinder, options, &with_summary);
  options.compaction = false;
  const auto without = GeneratePacking<3>(cylinder, options, nullptr);
  const auto m = ComputePackingMetrics<3>(with);
  const auto m0 = ComputePackingMetrics<3>(without);
  EXPECT_FALSE(with_summary.compactions.empty());
  EXPECT_LT(m.nominal_porosity, m0.nominal_porosity - 0.005) << with_summary.FullReport();
  ExpectCleanAndIsotropic(with, m);
}

// The power-law preset (PowerLawGeneratorOptions): on the same count and seed it is denser
// than the default, with a broader radius distribution, and as clean and isotropic.
TEST(GeneratePacking, PowerLawPresetInASmallCylinderIsDenserAndClean) {
  const auto cylinder = Domain<3>::Cylinder(0, 0, 0.5, 0, 1);
  GeneratorOptions options = PowerLawGeneratorOptions<3>();
  options.particle_count = 1500;
  options.seed = 2;
  GeneratorSummary summary;
  const auto dense = GeneratePacking<3>(cylinder, options, &summary);
  GeneratorOptions stienen = DefaultGeneratorOptions<3>();
  stienen.particle_count = 1500;
  stienen.seed = 2;
  const auto narrow = GeneratePacking<3>(cylinder, stienen, nullptr);
  const auto m = ComputePackingMetrics<3>(dense);
  const auto m0 = ComputePackingMetrics<3>(narrow);
  ASSERT_FALSE(summary.compactions.empty());
  EXPECT_EQ(summary.compactions.front().round, 0);
  EXPECT_NE(summary.radius_distribution.find("power law"), std::string::npos);
  EXPECT_NE(summary.FullReport().find("s^-3.5 over a spread of 8"), std::string::npos) << summary.FullReport();
  EXPECT_NEAR(m.particle_count, 1500, 150) << summary.FullReport();
  EXPECT_LT(m.nominal_porosity, m0.nominal_porosity - 0.03) << summary.FullReport();
  EXPECT_LE(m.nominal_porosity, 0.33) << summary.FullReport();
  EXPECT_GE(m.coordination_number, 5.5);
  ExpectCleanAndIsotropic(dense, m);
  // Broader: the relative spread of the radii (polydispersity).
  auto polydispersity = [](const std::vector<double>& r) {
    double mean = 0.0, square = 0.0;
    for (double v : r) mean += v / r.size();
    for (double v : r) square += (v - mean) * (v - mean) / r.size();
    return std::sqrt(square) / mean;
  };
  EXPECT_GT(polydispersity(dense.radii), polydispersity(narrow.radii) + 0.1);
}

TEST(GeneratePacking, BadOptionsNameTheField) {
  const auto domain = Domain<2>::Rectangle(0, 0, 10, 10);
  auto expect_message = [&](GeneratorOptions options, const std::string& field) {
    try {
      GeneratePacking<2>(domain, options, nullptr);
      FAIL() << "accepted bad " << field;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  GeneratorOptions none;
  expect_message(none, "mean_radius");
  GeneratorOptions both;
  both.mean_radius = 0.1;
  both.particle_count = 100;
  expect_message(both, "exactly one");
  GeneratorOptions ratio;
  ratio.particle_count = 100;
  ratio.radius_ratio = 0.5;
  expect_message(ratio, "radius_ratio");
  GeneratorOptions negative;
  negative.mean_radius = -1.0;
  expect_message(negative, "mean_radius");
  GeneratorOptions tolerance;
  tolerance.particle_count = 100;
  tolerance.contact_tolerance = 0.5;
  expect_message(tolerance, "contact_tolerance");
  // The compaction options, each just outside its range.
  using Setter = void (*)(GeneratorOptions&);
  const std::pair<Setter, std::string> compaction_cases[] = {
      {[](GeneratorOptions& o) { o.compaction_exponent = 0.1; }, "compaction_exponent"},
      {[](GeneratorOptions& o) { o.node_size_exponent = 6.5; }, "node_size_exponent"},
      {[](GeneratorOptions& o) { o.round_close_gap = -0.1; }, "round_close_gap"},
      {[](GeneratorOptions& o) { o.compaction_round = -1; }, "compaction_round"},
      {[](GeneratorOptions& o) { o.compaction_close_gap = -0.01; }, "compaction_close_gap"},
      {[](GeneratorOptions& o) { o.compaction_round = 101; }, "compaction_round"},
      {[](GeneratorOptions& o) { o.compaction_rounds = 101; }, "compaction_rounds"}};
  for (const auto& [set, field] : compaction_cases) {
    GeneratorOptions bad;
    bad.particle_count = 100;
    set(bad);
    expect_message(bad, field);
  }
  GeneratorOptions too_big;
  too_big.mean_radius = 3.0;  // a 10 x 10 square holds about three such discs
  expect_message(too_big, "too small");
}

}  // namespace
}  // namespace specimen
