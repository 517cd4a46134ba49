// The contact band (generator/contact_band.h): the rattler refill on a generated packing,
// and the whole stage end to end against the same packing without it.
#include "generator/contact_band.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/error.h"
#include "generator/contact_graph.h"
#include "generator/metrics.h"

namespace specimen {
namespace {

// Contacts per particle: pairs of the regular-triangulation graph with |gap| <= limit.
template <int Dim>
std::vector<int> ContactDegrees(const Domain<Dim>& domain, const std::vector<Vector<Dim>>& x,
                                const std::vector<double>& r, double limit) {
  const double r_max = *std::max_element(r.begin(), r.end());
  const ContactGraph<Dim> graph = BuildContactGraph<Dim>(domain, x, r, 2.5 * r_max);
  std::vector<int> degree(x.size(), 0);
  for (const auto& e : graph.edges)
    if (std::abs(PairGap<Dim>(x, r, e[0], e[1])) <= limit) ++degree[e[0]], ++degree[e[1]];
  return degree;
}

// Every rattler (fewer than Dim + 1 contacts) goes, and what the refill puts into the holes
// touches Dim + 1 particles without overlapping any.
TEST(ContactBand, RefillReplacesTheRattlersByTangentParticles) {
  const auto box = Domain<3>::Box(Vector<3>(0, 0, 0), Vector<3>(1, 1, 1));
  GeneratorOptions generator = PowerLawGeneratorOptions<3>();
  generator.particle_count = 1000;
  generator.seed = 3;
  GeneratorSummary summary;
  const Packing<3> packing = GeneratePacking<3>(box, generator, &summary);
  std::vector<Vector<3>> x = packing.centres;
  std::vector<double> r = packing.radii;
  const double mean_radius = VolumeMeanRadius<3>(r);
  const double limit = 0.02 * mean_radius;
  const std::vector<int> before = ContactDegrees<3>(box, x, r, limit);
  const int rattlers = static_cast<int>(
      std::count_if(before.begin(), before.end(), [](int d) { return d < 4; }));
  ASSERT_GT(rattlers, 10) << "the test needs rattlers to replace";

  ContactBandOptions options;
  options.refill_passes = 1;
  options.band_rounds = 0;
  options.hole_filling.min_radius = summary.radius_min_bound;
  options.hole_filling.max_radius = summary.radius_max_bound;
  options.ghost_band = 2.5 * summary.radius_max_bound;
  const std::vector<GeneratorBandStep> steps = RunContactBand<3>(box, options, x, r);
  ASSERT_EQ(steps.size(), 1u);
  const GeneratorBandStep& step = steps[0];
  EXPECT_EQ(step.kind, "refill");
  EXPECT_EQ(step.removed, rattlers);
  EXPECT_GT(step.inserted, 0);
  EXPECT_EQ(step.particles, packing.size() - rattlers + step.inserted);
  ASSERT_EQ(static_cast<int>(x.size()), step.particles);

  // The inserted particles are appended: each is tangent to Dim + 1 particles or walls (the
  // simplex of its hole), or fills a hole larger than r_max at its centre, and overlaps none.
  const double tangent = 1e-9 * mean_radius;
  const std::vector<int> after = ContactDegrees<3>(box, x, r, tangent);
  for (int i = step.particles - step.inserted; i < step.particles; ++i) {
    int touches = after[i];
    for (const auto& facet : box.Facets())
      if (std::abs(box.FacetDistance(facet, x[i]) - r[i]) <= tangent) ++touches;
    const bool at_max = r[i] >= summary.radius_max_bound * (1 - 1e-12);
    EXPECT_TRUE(touches >= 4 || at_max) << "inserted particle " << i << " touches " << touches;
    for (int j = 0; j < step.particles; ++j) {
      if (j == i) continue;
      EXPECT_GE(PairGap<3>(x, r, i, j), -1e-9 * mean_radius) << i << " " << j;
    }
    EXPECT_GE(box.SignedDistance(x[i]) - r[i], -1e-9 * mean_radius);
  }
}

// End to end: the same specimen with and without the band. With it, nc passes the bound of
// exact contacts with free radii, 8 - 2 Nb / N (docs/generator.md, "The rigidity bound"), every
// overlap stays within the tolerance and the packing stays isotropic.
TEST(ContactBand, PassesTheExactContactBoundWithinTheOverlapTolerance) {
  const auto cylinder = Domain<3>::Cylinder(0, 0, 0.5, 0, 1);
  GeneratorOptions options = PowerLawGeneratorOptions<3>();
  options.particle_count = 2000;
  options.seed = 2;
  options.keep_small_overlaps = true;
  options.overlap_tolerance = 0.02;
  options.max_rounds = 3;
  const Packing<3> exact = GeneratePacking<3>(cylinder, options, nullptr);
  options.rattler_refill_passes = 2;
  options.contact_band_rounds = 3;
  GeneratorSummary summary;
  const Packing<3> banded = GeneratePacking<3>(cylinder, options, &summary);
  const auto m0 = ComputePackingMetrics<3>(exact);
  const auto m = ComputePackingMetrics<3>(banded);

  ASSERT_EQ(summary.band_steps.size(), 5u);
  EXPECT_EQ(summary.band_steps[0].kind, "refill");
  EXPECT_EQ(summary.band_steps[4].kind, "band");
  EXPECT_NE(summary.FullReport().find("contact band"), std::string::npos);
  EXPECT_EQ(summary.ToJson()["band_steps"].size(), 5u);

  // Particles touching the wall (within the contact tolerance) tie up constraints.
  int at_wall = 0;
  for (int i = 0; i < banded.size(); ++i)
    if (cylinder.SignedDistance(banded.centres[i]) - banded.radii[i] <= 0.02 * m.mean_radius) ++at_wall;
  const double exact_bound = 8.0 - 2.0 * at_wall / banded.size();
  EXPECT_GT(m.coordination_number, exact_bound) << summary.FullReport();
  EXPECT_GT(m.coordination_number, m0.coordination_number + 0.3) << summary.FullReport();
  EXPECT_LE(m.max_overlap, 0.02 * (1 + 1e-9));
  EXPECT_EQ(m.protruding_particles, 0);
  EXPECT_LE(m.nominal_porosity, 0.31);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(m.fabric_eigenvalues[k], 1.0 / 3.0, 0.03);
  for (const auto& c : banded.contacts)
    EXPECT_LE(std::abs(banded.Gap(c[0], c[1])), 0.02 * m.mean_radius * (1 + 1e-12));
}

TEST(ContactBand, BadOptionsNameTheField) {
  const auto box = Domain<3>::Box(Vector<3>(0, 0, 0), Vector<3>(1, 1, 1));
  auto expect_message = [&](GeneratorOptions options, const std::string& field) {
    options.particle_count = 100;
    try {
      GeneratePacking<3>(box, options, nullptr);
      FAIL() << "accepted bad " << field;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  GeneratorOptions no_overlaps;
  no_overlaps.contact_band_rounds = 2;
  expect_message(no_overlaps, "keep_small_overlaps");
  GeneratorOptions rounds;
  rounds.keep_small_overlaps = true;
  rounds.contact_band_rounds = 21;
  expect_message(rounds, "contact_band_rounds");
  GeneratorOptions passes;
  passes.rattler_refill_passes = -1;
  expect_message(passes, "rattler_refill_passes");
  GeneratorOptions gap;
  gap.contact_band_candidate_gap = 0.0;
  expect_message(gap, "contact_band_candidate_gap");
  GeneratorOptions iterations;
  iterations.contact_band_iterations = 0;
  expect_message(iterations, "contact_band_iterations");
  // The stage on its own checks its tolerances too (a zero band would silently fall back to
  // exact residuals).
  std::vector<Vector<3>> x = {Vector<3>(0.3, 0.5, 0.5), Vector<3>(0.7, 0.5, 0.5)};
  std::vector<double> r = {0.2, 0.2};
  ContactBandOptions zero_band;
  zero_band.contact_tolerance = 0.0;
  EXPECT_THROW(RunContactBand<3>(box, zero_band, x, r), InputError);
}

}  // namespace
}  // namespace specimen
