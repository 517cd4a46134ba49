#include "generator/generate.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <sstream>

#include <nlohmann/json.hpp>

#include "common/error.h"
#include "common/format.h"
#include "generator/compaction.h"
#include "generator/contact_band.h"
#include "generator/contact_graph.h"
#include "generator/densify.h"
#include "generator/hole_filling.h"
#include "generator/initial_placement.h"
#include "specimen_version.h"

namespace specimen {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Porosity the method typically reaches: used only to turn a requested mean radius into
// a particle count (and back). 2D triangulated packings ~9 %, 3D ~30 %.
template <int Dim>
constexpr double kExpectedPorosity = Dim == 2 ? 0.09 : 0.30;

// Fill fraction of the random sequential addition of step 1: well below RSA saturation
// (~0.55 in 2D, ~0.38 in 3D for equal spheres) so that almost every node finds a place.
template <int Dim>
constexpr double kNodeFillFraction = Dim == 2 ? 0.45 : 0.30;
constexpr int kNodeAttempts = 200;
// Share of the final particles that hole filling typically inserts (measured with the
// default options), and how far above the requested count filling may go.
template <int Dim>
constexpr double kExpectedInsertionShare = Dim == 2 ? 0.015 : 0.12;
// The same with node spheres as initial radii (the power-law preset): the net change, as
// hole filling inserts and the repair rounds and the projection remove (measured: 3D
// +4.3 %, 2D -3.7 %).
template <int Dim>
constexpr double kExpectedInsertionShareNodeSpheres = Dim == 2 ? -0.037 : 0.043;
constexpr double kCountSlack = 1.03;
// Rings of neighbours around a defect that a repair round lets move.
constexpr int kRepairRings = 2;

// Log-centre of the final radii relative to that of the node sizes (see the bounds below).
template <int Dim>
constexpr double kRadiusCentre = Dim == 2 ? 0.8 : 0.85;

// Ratio of the largest node size to the volume-based mean size for sizes with number
// density ~ s^-exponent over [1, spread]: spread / (E[s^D])^(1/D) (log-uniform, exponent 1:
// E[s^D] = (spread^D - 1) / (D ln spread)).
template <int Dim>
double LargestToMeanSize(double spread, double exponent) {
  if (spread <= 1.0 + 1e-12) return 1.0;
  // Log-uniform in closed form (bit for bit what earlier versions computed).
  const double moment = exponent == 1.0 ? (std::pow(spread, Dim) - 1.0) / (Dim * std::log(spread))
                                        : PowerLawMoment(spread, exponent, Dim);
  return spread / std::pow(moment, 1.0 / Dim);
}

// State of the packing measured on a contact graph (used after every round).
template <int Dim>
struct RoundState {
  double max_overlap = 0.0;     // absolute
  double max_protrusion = 0.0;  // absolute
  int contacts = 0;             // edges with |gap| <= contact limit
};

template <int Dim>
RoundState<Dim> Measure(const Domain<Dim>& domain, const ContactGraph<Dim>& graph,
                        const std::vector<Vector<Dim>>& x, const std::vector<double>& r,
                        double contact_limit) {
  RoundState<Dim> state;
  for (const auto& e : graph.edges) {
    const double gap = PairGap<Dim>(x, r, e[0], e[1]);
    state.max_overlap = std::max(state.max_overlap, -gap);
    if (std::abs(gap) <= contact_limit) ++state.contacts;
  }
  for (size_t i = 0; i < x.size(); ++i)
    state.max_protrusion = std::max(state.max_protrusion, r[i] - domain.SignedDistance(x[i]));
  return state;
}

// Chooses which residuals are exact (two-sided) this round: the candidates with the
// smallest gap relative to their size, up to `count`. All others stay one-sided: they may
// not overlap, but nothing pulls them together (this is what keeps a large gap on one pair
// from being paid for by overlaps on its neighbours, Labra's defect (a)).
template <int Dim>
void SelectExactConstraints(const Domain<Dim>& domain, const ContactGraph<Dim>& graph,
                            const std::vector<Vector<Dim>>& x, const std::vector<double>& r,
                            size_t count, double gap_limit, LevenbergMarquardtOptions* lm) {
  struct Candidate {
    double relative_gap;
    bool is_edge;
    int index;
  };
  std::vector<Candidate> candidates;
  candidates.reserve(graph.edges.size() + graph.boundary_ties.size());
  for (size_t k = 0; k < graph.edges.size(); ++k) {
    const auto& e = graph.edges[k];
    const double gap = PairGap<Dim>(x, r, e[0], e[1]);
    if (gap > gap_limit) continue;
    candidates.push_back({gap / (r[e[0]] + r[e[1]]), true, static_cast<int>(k)});
  }
  const auto& facets = domain.Facets();
  for (size_t k = 0; k < graph.boundary_ties.size(); ++k) {
    const auto& tie = graph.boundary_ties[k];
    const double gap = domain.FacetDistance(facets[tie.second], x[tie.first]) - r[tie.first];
    if (gap > gap_limit) continue;
    candidates.push_back({gap / (2.0 * r[tie.first]), false, static_cast<int>(k)});
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.relative_gap < b.relative_gap ||
           (a.relative_gap == b.relative_gap &&
            (a.is_edge < b.is_edge || (a.is_edge == b.is_edge && a.index < b.index)));
  });
  lm->edge_one_sided.assign(graph.edges.size(), 1);
  lm->tie_one_sided.assign(graph.boundary_ties.size(), 1);
  const size_t take = std::min(count, candidates.size());
  for (size_t k = 0; k < take; ++k) {
    if (candidates[k].is_edge) lm->edge_one_sided[candidates[k].index] = 0;
    else lm->tie_one_sided[candidates[k].index] = 0;
  }
}

// After a round: a pair still overlapping by more than `conflict_limit` is folded over
// itself; a particle held at r_min that still overlaps by more than `fit_limit` sits in a
// hole smaller than r_min. Neither can be mended by another least-squares round: the
// smaller particle of the pair (or the one that does not fit) is flagged for removal.
template <int Dim>
std::vector<char> FindConflicts(const ContactGraph<Dim>& graph, double radius_min,
                                double fit_limit, double conflict_limit,
                                const std::vector<Vector<Dim>>& x, const std::vector<double>& r) {
  std::vector<char> remove(x.size(), 0);
  for (const auto& e : graph.edges) {
    const double gap = PairGap<Dim>(x, r, e[0], e[1]);
    if (gap >= -fit_limit) continue;
    const int smaller = r[e[0]] < r[e[1]] || (r[e[0]] == r[e[1]] && e[0] > e[1]) ? e[0] : e[1];
    if (gap < -conflict_limit || r[smaller] <= radius_min * (1.0 + 1e-9)) remove[smaller] = 1;
  }
  return remove;
}

// The particles the next round must move: those in an overlap or protrusion beyond
// `limit`, the `seeds` (next to a removed particle, or inserted), and `rings` rings of
// their neighbours so that the repair can spread. Empty result = nothing to repair.
template <int Dim>
std::vector<char> RepairRegion(const Domain<Dim>& domain, const ContactGraph<Dim>& graph,
                               const std::vector<Vector<Dim>>& x, const std::vector<double>& r,
                               double limit, std::vector<char> seeds, int rings, int* count) {
  for (const auto& e : graph.edges)
    if (PairGap<Dim>(x, r, e[0], e[1]) < -limit) seeds[e[0]] = seeds[e[1]] = 1;
  for (size_t i = 0; i < x.size(); ++i)
    if (r[i] - domain.SignedDistance(x[i]) > limit) seeds[i] = 1;
  for (int ring = 0; ring < rings; ++ring) {
    std::vector<char> grown = seeds;
    for (const auto& e : graph.edges)
      if (seeds[e[0]] || seeds[e[1]]) grown[e[0]] = grown[e[1]] = 1;
    seeds.swap(grown);
  }
  *count = static_cast<int>(std::count(seeds.begin(), seeds.end(), 1));
  return seeds;
}

// Final projection: every protrusion is removed exactly, and every overlap down to
// `allowed_overlap` [m] (0: exactly), by shrinking radii. Of an overlapping pair the smaller
// particle gives up the excess: that costs 2 pi r_small d of area in 2D (4 pi r_small^2 d in
// 3D), never more than halving it on both. A particle that would fall below r_min is
// removed. Returns the largest shrink.
template <int Dim>
double ProjectToNonOverlapping(const Domain<Dim>& domain, double radius_min, double ghost_band,
                               double allowed_overlap, std::vector<Vector<Dim>>& x,
                               std::vector<double>& r, int* removed) {
  double largest = 0.0;
  for (int pass = 0; pass < 8; ++pass) {
    const ContactGraph<Dim> graph = BuildContactGraph<Dim>(domain, x, r, ghost_band);
    std::vector<double> shrink(x.size(), 0.0);
    bool any = false;
    for (const auto& e : graph.edges) {
      const double excess = -PairGap<Dim>(x, r, e[0], e[1]) - allowed_overlap;
      if (excess <= 0.0) continue;
      any = true;
      const int smaller = r[e[0]] <= r[e[1]] ? e[0] : e[1];
      // A hair more than the excess, so that round-off cannot leave one behind.
      shrink[smaller] = std::max(shrink[smaller], excess * (1.0 + 1e-12) + 1e-15 * r[smaller]);
    }
    for (size_t i = 0; i < x.size(); ++i) {
      const double inside = domain.SignedDistance(x[i]);
      if (r[i] > inside) {
        any = true;
        shrink[i] = std::max(shrink[i], r[i] - inside);
      }
    }
    if (!any) break;
    std::vector<char> remove(x.size(), 0);
    for (size_t i = 0; i < x.size(); ++i) {
      if (shrink[i] <= 0.0) continue;
      largest = std::max(largest, shrink[i]);
      r[i] -= shrink[i];
      if (r[i] < radius_min * (1.0 - 1e-9)) remove[i] = 1;
    }
    *removed += RemoveFlaggedParticles<Dim>(remove, x, r);
  }
  return largest;
}

}  // namespace

template <int Dim>
GeneratorOptions DefaultGeneratorOptions() {
  GeneratorOptions options;
  if constexpr (Dim == 3) {
    options.node_size_spread = 3.0;
    options.hole_fill_radius = 0.35;
    options.max_rounds = 6;
    options.compaction = true;
  }
  return options;
}
template <int Dim>
GeneratorOptions PowerLawGeneratorOptions(double radius_ratio) {
  GeneratorOptions options = DefaultGeneratorOptions<Dim>();
  options.radius_ratio = radius_ratio;
  options.node_size_spread = std::max(1.0, radius_ratio / 1.25);
  options.node_size_exponent = 3.5;
  options.initial_radii = GeneratorOptions::InitialRadii::kNodeSpheres;
  options.compaction = true;
  options.compaction_round = 0;
  options.compaction_rounds = 1;
  // Round 0 starts from the jammed packing: it may close every pair up to half a mean
  // radius (measured on 5,000 spheres, exponent 3: 0.08 gives porosity 30.4 %, nc 5.5;
  // 0.5 gives 27.5 %, nc 6.5).
  options.compaction_close_gap = 0.5;
  // Every later round keeps closing the pairs open by up to 6 % of r_mean: nc 7.69 against
  // 6.88 with the usual 1 %, at the rigidity bound of exact contacts (README, generator
  // benchmark). Its rounds re-solve nearly the whole packing; 25 iterations leave each
  // round's cost within 2 % of where 60 leave it (30k spheres: the same nc, 7.68, and
  // porosity, 26.1 %, in 105 s against 184 s with up to 100 iterations per round).
  options.round_close_gap = 0.06;
  options.max_iterations_per_round = 25;
  options.max_rounds = 6;
  return options;
}
template GeneratorOptions PowerLawGeneratorOptions<2>(double);
template GeneratorOptions PowerLawGeneratorOptions<3>(double);
template GeneratorOptions DefaultGeneratorOptions<2>();
template GeneratorOptions DefaultGeneratorOptions<3>();

bool GeneratorOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  const bool by_radius = mean_radius > 0.0;
  const bool by_count = particle_count > 0;
  if (!std::isfinite(mean_radius) || mean_radius < 0.0)
    return fail("mean_radius = " + Number(mean_radius) + " is not allowed: it must be > 0");
  if (particle_count < 0)
    return fail("particle_count = " + std::to_string(particle_count) + " is not allowed: it must be >= 1");
  if (by_radius == by_count)
    return fail("give exactly one of mean_radius (> 0) and particle_count (>= 1)");
  if (by_count && particle_count > 50000000)
    return fail("particle_count = " + std::to_string(particle_count) + " is above the supported 5e7");
  if (!(radius_ratio >= 1.0) || !std::isfinite(radius_ratio))
    return fail("radius_ratio = " + Number(radius_ratio) + " is not allowed: it must be >= 1");
  if (!(node_size_spread >= 1.0) || node_size_spread > radius_ratio)
    return fail("node_size_spread = " + Number(node_size_spread) +
                " is not allowed: it must be in [1, radius_ratio = " + Number(radius_ratio) + "]");
  if (!(node_size_exponent >= 0.0) || node_size_exponent > 6.0)
    return fail("node_size_exponent = " + Number(node_size_exponent) +
                " is not allowed: it must be in [0, 6]");
  if (!(initial_radius_factor_min > 0.0) || !(initial_radius_factor_max >= initial_radius_factor_min) ||
      initial_radius_factor_max > 2.0)
    return fail("initial radius factor range [" + Number(initial_radius_factor_min) + ", " +
                Number(initial_radius_factor_max) + "] is not allowed: need 0 < min <= max <= 2");
  if (!(contact_tolerance > 0.0) || contact_tolerance > 0.2)
    return fail("contact_tolerance = " + Number(contact_tolerance) +
                " is not allowed: it must be in (0, 0.2] (relative to the mean radius)");
  if (!(overlap_tolerance >= 0.0) || overlap_tolerance > 0.1)
    return fail("overlap_tolerance = " + Number(overlap_tolerance) +
                " is not allowed: it must be in [0, 0.1] (relative to the mean radius)");
  if (!(conflict_overlap > overlap_tolerance) || conflict_overlap > 1.0)
    return fail("conflict_overlap = " + Number(conflict_overlap) +
                " is not allowed: it must be in (overlap_tolerance, 1]");
  if (!(hole_fill_radius > 0.0) || hole_fill_radius > 1.0)
    return fail("hole_fill_radius = " + Number(hole_fill_radius) +
                " is not allowed: it must be in (0, 1] (relative to the mean radius)");
  if (max_rounds < 1 || max_rounds > 100)
    return fail("max_rounds = " + std::to_string(max_rounds) + " is not allowed: it must be in [1, 100]");
  if (max_iterations_per_round < 1 || max_iterations_per_round > 10000)
    return fail("max_iterations_per_round = " + std::to_string(max_iterations_per_round) +
                " is not allowed: it must be in [1, 10000]");
  if (!(constraint_fraction > 0.0) || constraint_fraction > 2.0)
    return fail("constraint_fraction = " + Number(constraint_fraction) +
                " is not allowed: it must be in (0, 2]");
  if (!(round_close_gap >= 0.0) || round_close_gap > 0.5)
    return fail("round_close_gap = " + Number(round_close_gap) +
                " is not allowed: it must be in [0, 0.5] (relative to the mean radius; 0: half "
                "the contact tolerance)");
  if (!(compaction_exponent >= 0.5) || compaction_exponent > 4.0)
    return fail("compaction_exponent = " + Number(compaction_exponent) +
                " is not allowed: it must be in [0.5, 4]");
  if (compaction_round < 0 || compaction_round > 100)
    return fail("compaction_round = " + std::to_string(compaction_round) +
                " is not allowed: it must be in [0, 100]");
  if (compaction_rounds < 1 || compaction_rounds > 100)
    return fail("compaction_rounds = " + std::to_string(compaction_rounds) +
                " is not allowed: it must be in [1, 100]");
  if (!(compaction_close_gap >= 0.0) || compaction_close_gap > 0.5)
    return fail("compaction_close_gap = " + Number(compaction_close_gap) +
                " is not allowed: it must be in [0, 0.5] (relative to the mean radius)");
  if (rattler_refill_passes < 0 || rattler_refill_passes > 10)
    return fail("rattler_refill_passes = " + std::to_string(rattler_refill_passes) +
                " is not allowed: it must be in [0, 10]");
  if (contact_band_rounds < 0 || contact_band_rounds > 20)
    return fail("contact_band_rounds = " + std::to_string(contact_band_rounds) +
                " is not allowed: it must be in [0, 20]");
  if (contact_band_rounds > 0 && !keep_small_overlaps)
    return fail("contact_band_rounds = " + std::to_string(contact_band_rounds) +
                " needs keep_small_overlaps: the band places pairs anywhere in [-overlap_tolerance, "
                "contact_tolerance], and the final projection would remove every overlap");
  if (!(contact_band_candidate_gap > 0.0) || contact_band_candidate_gap > 0.5)
    return fail("contact_band_candidate_gap = " + Number(contact_band_candidate_gap) +
                " is not allowed: it must be in (0, 0.5] (relative to the mean radius)");
  if (contact_band_iterations < 1 || contact_band_iterations > 10000)
    return fail("contact_band_iterations = " + std::to_string(contact_band_iterations) +
                " is not allowed: it must be in [1, 10000]");
  if (num_threads < 1 || num_threads > 256)
    return fail("num_threads = " + std::to_string(num_threads) + " is not allowed: it must be in [1, 256]");
  return true;
}

template <int Dim>
Packing<Dim> GeneratePacking(const Domain<Dim>& domain, const GeneratorOptions& options,
                             GeneratorSummary* summary) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  GeneratorSummary local_summary;
  GeneratorSummary& s = summary ? *summary : local_summary;
  s = GeneratorSummary();
  s.dimension_and_domain = std::to_string(Dim) + "D " + domain.ToShortText();
  {
    char text[160];
    std::snprintf(text, sizeof(text), "%s, node sizes ~ s^-%g over a spread of %g",
                  options.initial_radii == GeneratorOptions::InitialRadii::kNodeSpheres
                      ? "node spheres as radii (power law)"
                      : "Stienen radii",
                  options.node_size_exponent, options.node_size_spread);
    s.radius_distribution = text;
  }
  const auto start = Clock::now();
  auto report = [&](double fraction, const std::string& message) {
    if (options.progress) options.progress(fraction, message);
  };

  // --- Size: particle count and the expected mean radius r0. ---
  const double solid_volume = (1.0 - kExpectedPorosity<Dim>)*domain.Volume();
  double expected_mean_radius = options.mean_radius;
  int count = options.particle_count;
  if (count > 0) {
    expected_mean_radius = std::pow(solid_volume / (count * ParticleVolume<Dim>(1.0)), 1.0 / Dim);
  } else {
    const double estimate = solid_volume / ParticleVolume<Dim>(options.mean_radius);
    if (estimate > 5e7)
      throw InputError("mean_radius = " + Number(options.mean_radius) + " would need about " +
                       std::to_string(static_cast<long long>(estimate)) +
                       " particles in this domain; the supported maximum is 5e7");
    count = static_cast<int>(std::lround(estimate));
  }
  if (count < 8 || domain.SmallestExtent() < 4.0 * expected_mean_radius)
    throw InputError("the domain is too small for the requested size: it holds about " +
                     std::to_string(count) + " particles and is " +
                     Number(domain.SmallestExtent() / expected_mean_radius) +
                     " mean radii across at its narrowest; at least 8 particles and 4 radii are needed");
  s.particles_requested = count;
  // Radius bounds, centred (in log scale) on the typical radius the densification gives:
  // the log-centre of the node sizes, times kRadiusCentre (measured: the radii of a
  // triangulated 2D packing of equal nodes spread over [0.34, 1.82] r_mean, log-centre 0.79).
  const double largest_node_size =
      expected_mean_radius *
      LargestToMeanSize<Dim>(options.node_size_spread, options.node_size_exponent);
  const bool node_spheres = options.initial_radii == GeneratorOptions::InitialRadii::kNodeSpheres;
  const double radius_max =
      node_spheres
          // The node sizes themselves, widened evenly (in log scale) to the radius ratio.
          ? largest_node_size * std::sqrt(options.radius_ratio / options.node_size_spread)
          : kRadiusCentre<Dim> * (largest_node_size / std::sqrt(options.node_size_spread)) *
                std::sqrt(options.radius_ratio);
  const double radius_min = radius_max / options.radius_ratio;
  s.radius_min_bound = radius_min;
  s.radius_max_bound = radius_max;
  const double ghost_band = 2.5 * radius_max;

  // --- Steps 1 and 2: nodes and Stienen-like radii. ---
  report(0.0, "placing nodes");
  std::mt19937_64 rng(options.seed);
  // Hole filling adds particles as the rounds go: start with fewer nodes, and stop filling
  // a little above the requested count.
  const double insertion_share =
      node_spheres ? kExpectedInsertionShareNodeSpheres<Dim> : kExpectedInsertionShare<Dim>;
  const int node_count = static_cast<int>(std::lround(count / (1.0 + insertion_share)));
  const NodeSet<Dim> nodes = RandomSequentialNodes<Dim>(
      domain, node_count, options.node_size_spread, options.node_size_exponent,
      kNodeFillFraction<Dim>, kNodeAttempts, rng);
  std::vector<Vector<Dim>> x = nodes.positions;
  std::vector<double> r;
  if (node_spheres) {
    // The node spheres scaled from the RSA fill to the expected solid fraction: they
    // overlap until the compaction of round 0 rearranges them.
    const double scale = std::pow((1.0 - kExpectedPorosity<Dim>) / kNodeFillFraction<Dim>, 1.0 / Dim);
    r = nodes.exclusion_radii;
    for (double& radius : r) radius = std::clamp(radius * scale, radius_min, radius_max);
  } else {
    r = StienenRadii<Dim>(domain, nodes, options.initial_radius_factor_min,
                          options.initial_radius_factor_max, radius_min, radius_max, rng);
  }
  s.nodes_placed = static_cast<int>(x.size());
  s.placement_seconds = SecondsSince(start);

  // --- Steps 3 and 4: rounds of regular triangulation + Levenberg-Marquardt. ---
  LevenbergMarquardtOptions lm;
  lm.radius_min = radius_min;
  lm.radius_max = radius_max;
  lm.length_scale = expected_mean_radius;
  lm.max_iterations = options.max_iterations_per_round;
  lm.num_threads = options.num_threads;
  // Conjugate gradients on the normal equations: sparse Cholesky of J^T J costs ~0.5 s
  // per iteration at 20,000 discs already (measured), CGNR a tenth of that.
  lm.iterative_linear_solver = true;
  // A faint proximal term: fixes the null space of particles with fewer than Dim + 1
  // exact constraints without biasing the others measurably (its residuals are 1e-3 of
  // a contact residual for the same displacement).
  lm.position_anchor_weight = 1e-3;
  // Stop once the root-mean-square gap of the exact constraints is 5 % of the overlap
  // tolerance: a residual |x|^2 - (ri + rj)^2 is about 4 gap / r_mean in units of r_mean^2.
  const double stop_residual = 4.0 * 0.05 * options.overlap_tolerance;

  const auto densification_start = Clock::now();
  const double overlap_limit = options.overlap_tolerance * expected_mean_radius;
  const double conflict_limit = options.conflict_overlap * expected_mean_radius;
  const double drop_gap = (options.round_close_gap > 0.0 ? options.round_close_gap
                                                         : 0.5 * options.contact_tolerance) *
                          expected_mean_radius;
  HoleFillingOptions hole_filling;
  hole_filling.min_radius = std::max(radius_min, options.hole_fill_radius * expected_mean_radius);
  hole_filling.max_radius = radius_max;
  // Compaction: force-biased growth until jammed (generator/compaction.h).
  auto run_compaction = [&](int round) {
    report(round < 0 ? 0.9 : static_cast<double>(round) / options.max_rounds, "compacting");
    CompactionOptions compaction;
    compaction.length_scale = expected_mean_radius;
    compaction.exponent = options.compaction_exponent;
    GeneratorSummary::Compaction record;
    record.round = round;
    record.porosity_before = NominalPorosity<Dim>(domain, r);
    const CompactionSummary c = CompactPacking<Dim>(domain, compaction, x, r);
    record.growth_factor = c.growth_factor;
    record.kept_input = c.kept_input;
    record.sweeps = c.sweeps;
    record.porosity_after = NominalPorosity<Dim>(domain, r);
    record.seconds = c.seconds;
    s.compactions.push_back(record);
  };
  ContactGraph<Dim> graph = BuildContactGraph<Dim>(domain, x, r, ghost_band);
  s.termination = "round limit reached";
  std::vector<char> free_particles;  // round 0: all
  for (int round = 0; round < options.max_rounds; ++round) {
    report(static_cast<double>(round) / options.max_rounds,
           // Rounds are numbered from 0, as in the round table and the JSON.
           "densifying: round " + std::to_string(round) + " (rounds 0 to " +
               std::to_string(options.max_rounds - 1) + ")");
    const bool compacted = options.compaction && round >= options.compaction_round &&
                           round < options.compaction_round + options.compaction_rounds;
    if (compacted) {
      run_compaction(round);
      graph = BuildContactGraph<Dim>(domain, x, r, ghost_band);
      free_particles.clear();
    }
    const size_t exact_count = static_cast<size_t>(options.constraint_fraction * (Dim + 1) * x.size());
    // Round 0 starts from the initial guess, whose gaps mean nothing yet. Later rounds drop
    // the pairs the previous round left open by more than half the contact tolerance
    // (Labra 3.2.3, defect (a)): what is left is close to consistent and nearly exact, and
    // the pairs kept are contacts of the output. (Dropping at the overlap tolerance instead
    // frees so much that the packing relaxes: measured nc 5.4-5.8 against 5.7-5.8.)
    // After a compaction the jammed packing has many near-contacts: the round closes those
    // open by up to compaction_close_gap (measured, 30k spheres: nc 5.4 -> 6.9, and the
    // porosity drops further, 35.2 -> 34.1 %).
    const double gap_limit = compacted ? options.compaction_close_gap * expected_mean_radius
                             : round == 0 ? std::numeric_limits<double>::infinity()
                                         : drop_gap;
    SelectExactConstraints<Dim>(domain, graph, x, r, exact_count, gap_limit, &lm);
    lm.free_particles = free_particles;
    if (options.record_trace) {
      const int iterations_before = s.trace.empty() ? 0 : s.trace.back().lm_iterations;
      lm.on_iteration = [&, iterations_before, round](int iteration, const std::vector<double>& blocks) {
        GeneratorTracePoint point;
        point.round = round;
        point.lm_iterations = iterations_before + iteration;
        point.seconds = SecondsSince(start);
        double volume = 0.0, worst = 0.0;
        for (size_t i = 0; i < x.size(); ++i) volume += ParticleVolume<Dim>(blocks[i * (Dim + 1) + Dim]);
        for (const auto& e : graph.edges) {
          const double* a = &blocks[e[0] * (Dim + 1)];
          const double* b = &blocks[e[1] * (Dim + 1)];
          double distance = 0.0;
          for (int k = 0; k < Dim; ++k) distance += (a[k] - b[k]) * (a[k] - b[k]);
          worst = std::max(worst, a[Dim] + b[Dim] - std::sqrt(distance));
        }
        point.nominal_porosity = 1.0 - volume / domain.Volume();
        point.max_overlap = worst / expected_mean_radius;
        s.trace.push_back(point);
      };
    }
    lm.stop_cost = 0.5 * static_cast<double>(exact_count) * stop_residual * stop_residual;
    const LevenbergMarquardtSummary solve = SolveLevenbergMarquardt<Dim>(domain, graph, lm, x, r);

    GeneratorRound stats;
    stats.round = round;
    stats.free_particles = free_particles.empty()
                               ? static_cast<int>(x.size())
                               : static_cast<int>(std::count(free_particles.begin(), free_particles.end(), 1));
    stats.graph_edges = static_cast<int>(graph.edges.size());
    stats.exact_constraints = static_cast<int>(
        std::count(lm.edge_one_sided.begin(), lm.edge_one_sided.end(), 0) +
        std::count(lm.tie_one_sided.begin(), lm.tie_one_sided.end(), 0));
    stats.lm_iterations = solve.iterations;
    stats.initial_cost = solve.initial_cost;
    stats.final_cost = solve.final_cost;

    // Remove what cannot be mended; the neighbours of a removed particle are re-solved.
    graph = BuildContactGraph<Dim>(domain, x, r, ghost_band);
    // Round 0 is a compromise from an arbitrary start: its overlaps are expected and the
    // next round, freed of the pairs it could not close, resolves them. Only what survives
    // a later round is a conflict.
    const std::vector<char> remove =
        round == 0 ? std::vector<char>(x.size(), 0)
                   : FindConflicts<Dim>(graph, radius_min, overlap_limit, conflict_limit, x, r);
    std::vector<char> seeds(x.size(), 0);
    for (const auto& e : graph.edges) {
      if (remove[e[0]]) seeds[e[1]] = 1;
      if (remove[e[1]]) seeds[e[0]] = 1;
    }
    stats.removed_particles = RemoveFlaggedParticles<Dim>(remove, x, r, &seeds);
    // Fill the holes that take a particle of useful size; new particles are re-solved too.
    graph = BuildContactGraph<Dim>(domain, x, r, ghost_band, /*with_cells=*/true);
    // The last round only repairs: what it inserts could not be checked by another round.
    hole_filling.max_insertions =
        round + 1 == options.max_rounds
            ? 0
            : std::max(0, static_cast<int>(kCountSlack * count) - static_cast<int>(x.size()));
    stats.inserted_particles = FillHoles<Dim>(domain, graph, hole_filling, x, r);
    seeds.resize(x.size(), 1);
    graph = BuildContactGraph<Dim>(domain, x, r, ghost_band);

    const double mean_radius = VolumeMeanRadius<Dim>(r);
    const RoundState<Dim> state =
        Measure<Dim>(domain, graph, x, r, options.contact_tolerance * mean_radius);
    stats.particles = static_cast<int>(x.size());
    stats.max_overlap = state.max_overlap / mean_radius;
    stats.max_protrusion = std::max(0.0, state.max_protrusion) / mean_radius;
    stats.nominal_porosity = NominalPorosity<Dim>(domain, r);
    stats.coordination_number = 2.0 * state.contacts / static_cast<double>(x.size());
    stats.seconds = SecondsSince(start);
    s.rounds.push_back(stats);

    int to_repair = 0;
    free_particles = RepairRegion<Dim>(domain, graph, x, r, overlap_limit, seeds,
                                       kRepairRings, &to_repair);
    if (to_repair == 0) {
      s.termination = "converged: largest overlap and protrusion within the overlap tolerance";
      break;
    }
  }
  s.densification_seconds = SecondsSince(densification_start);

  if (options.compaction && s.compactions.empty()) run_compaction(-1);

  // --- Contact band: more pairs within the tolerances than exact contacts allow. ---
  if (options.rattler_refill_passes > 0 || options.contact_band_rounds > 0) {
    ContactBandOptions band;
    band.contact_tolerance = options.contact_tolerance;
    band.overlap_tolerance = options.overlap_tolerance;
    band.candidate_gap = options.contact_band_candidate_gap;
    band.refill_passes = options.rattler_refill_passes;
    band.band_rounds = options.contact_band_rounds;
    band.solver = lm;
    band.solver.on_iteration = nullptr;
    band.solver.max_iterations = options.contact_band_iterations;
    band.hole_filling = hole_filling;
    band.hole_filling.max_insertions = 1 << 30;  // a rattler's hole may take several
    band.ghost_band = ghost_band;
    auto band_progress = [&](double fraction, const std::string& message) {
      report(0.9 + 0.05 * fraction, message);
    };
    s.band_steps = RunContactBand<Dim>(domain, band, x, r, band_progress);
  }

  // --- Final projection: no protrusion, and no overlap (or none above the tolerance). ---
  report(0.95, "removing the remaining overlaps");
  // The kept overlaps are measured against the mean radius after the projection, which its
  // shrinking lowers (by ~1e-5 relative): 0.1 % of headroom keeps them within the tolerance.
  const double allowed_overlap =
      options.keep_small_overlaps ? 0.999 * options.overlap_tolerance * VolumeMeanRadius<Dim>(r)
                                  : 0.0;
  s.projection_max_shrink =
      ProjectToNonOverlapping<Dim>(domain, radius_min, ghost_band, allowed_overlap, x, r,
                                   &s.projection_removed) /
      VolumeMeanRadius<Dim>(r);

  graph = BuildContactGraph<Dim>(domain, x, r, ghost_band);
  if (options.record_trace) {
    GeneratorTracePoint point;
    point.round = static_cast<int>(s.rounds.size());
    point.lm_iterations = s.trace.empty() ? 0 : s.trace.back().lm_iterations;
    point.seconds = SecondsSince(start);
    point.nominal_porosity = NominalPorosity<Dim>(domain, r);
    point.max_overlap = Measure<Dim>(domain, graph, x, r, 0.0).max_overlap / expected_mean_radius;
    s.trace.push_back(point);
  }

  // --- Step 5: output, contacts = pairs within the contact tolerance. ---
  Packing<Dim> packing(domain);
  packing.centres = std::move(x);
  packing.radii = std::move(r);
  packing.seed = options.seed;
  packing.created_by = std::string("specimen generate-packing ") + kVersion;
  SetContactsFromCandidates<Dim>(packing, graph.edges, options.contact_tolerance);
  s.particles_final = packing.size();
  s.total_seconds = SecondsSince(start);
  report(1.0, "done");
  return packing;
}

std::string GeneratorSummary::BriefReport() const {
  char line[256];
  const double porosity = !band_steps.empty() ? band_steps.back().nominal_porosity
                          : rounds.empty()     ? 0.0
                                               : rounds.back().nominal_porosity;
  std::snprintf(line, sizeof(line), "%s: %d particles, %zu rounds, porosity %.4f, %.1f s (%s)",
                dimension_and_domain.c_str(), particles_final, rounds.size(), porosity,
                total_seconds, termination.c_str());
  return line;
}

std::string GeneratorSummary::FullReport() const {
  std::ostringstream out;
  char line[256];
  out << "generate-packing: " << dimension_and_domain << "\n";
  std::snprintf(line, sizeof(line),
                "  particles requested %d, nodes placed %d, final %d\n"
                "  radius bounds [%.6g, %.6g]\n",
                particles_requested, nodes_placed, particles_final, radius_min_bound,
                radius_max_bound);
  out << line << "  radii: " << radius_distribution << "\n";
  out << "  round  particles  free     edges   exact  LM it  cost start -> end        max ovl  max prot"
         "  porosity  nc     removed  added  time [s]\n";
  for (const auto& r : rounds) {
    std::snprintf(line, sizeof(line),
                  "  %5d  %9d  %7d  %6d  %6d  %5d  %10.3e -> %10.3e  %7.4f  %8.4f  %8.4f  %5.3f  %7d  %5d  %8.2f\n",
                  r.round, r.particles, r.free_particles, r.graph_edges, r.exact_constraints, r.lm_iterations,
                  r.initial_cost, r.final_cost, r.max_overlap, r.max_protrusion,
                  r.nominal_porosity, r.coordination_number, r.removed_particles,
                  r.inserted_particles, r.seconds);
    out << line;
  }
  for (const auto& c : compactions) {
    std::snprintf(line, sizeof(line),
                  "  compaction %s %d: radii x %.5f%s, %d sweeps, porosity %.4f -> %.4f, %.2f s\n",
                  c.round < 0 ? "after round" : "before round",
                  c.round < 0 ? static_cast<int>(rounds.size()) - 1 : c.round, c.growth_factor,
                  c.kept_input ? " (input kept)" : "", c.sweeps, c.porosity_before, c.porosity_after,
                  c.seconds);
    out << line;
  }
  if (!band_steps.empty())
    out << "  contact band  particles  removed  added  band pairs  LM it  cost start -> end        "
           "max ovl  porosity  nc     time [s]\n";
  for (const auto& b : band_steps) {
    std::snprintf(line, sizeof(line),
                  "  %-12s  %9d  %7d  %5d  %10d  %5d  %10.3e -> %10.3e  %7.4f  %8.4f  %5.3f  %8.2f\n",
                  b.kind.c_str(), b.particles, b.removed, b.inserted, b.band_pairs,
                  b.lm_iterations, b.initial_cost, b.final_cost, b.max_overlap,
                  b.nominal_porosity, b.coordination_number, b.seconds);
    out << line;
  }
  std::snprintf(line, sizeof(line),
                "  final projection: largest radius reduction %.4g r_mean, %d particles removed\n"
                "  time: placement %.2f s, densification %.2f s, total %.2f s\n"
                "  termination: %s\n",
                projection_max_shrink, projection_removed, placement_seconds,
                densification_seconds, total_seconds, termination.c_str());
  out << line;
  return out.str();
}

nlohmann::json GeneratorSummary::ToJson() const {
  nlohmann::json j;
  j["domain"] = dimension_and_domain;
  j["particles_requested"] = particles_requested;
  j["nodes_placed"] = nodes_placed;
  j["particles_final"] = particles_final;
  j["radius_bounds_m"] = {radius_min_bound, radius_max_bound};
  j["radius_distribution"] = radius_distribution;
  for (const auto& r : rounds) {
    j["rounds"].push_back({{"round", r.round},
                           {"particles", r.particles},
                           {"free_particles", r.free_particles},
                           {"graph_edges", r.graph_edges},
                           {"exact_constraints", r.exact_constraints},
                           {"lm_iterations", r.lm_iterations},
                           {"initial_cost", r.initial_cost},
                           {"final_cost", r.final_cost},
                           {"max_overlap_per_r_mean", r.max_overlap},
                           {"max_protrusion_per_r_mean", r.max_protrusion},
                           {"nominal_porosity", r.nominal_porosity},
                           {"coordination_number", r.coordination_number},
                           {"removed_particles", r.removed_particles},
                           {"inserted_particles", r.inserted_particles},
                           {"wall_time_s", r.seconds}});
  }
  for (const auto& t : trace)
    j["trace"].push_back({{"round", t.round},
                          {"lm_iterations", t.lm_iterations},
                          {"wall_time_s", t.seconds},
                          {"nominal_porosity", t.nominal_porosity},
                          {"max_overlap_per_r_mean", t.max_overlap}});
  for (const auto& c : compactions)
    j["compactions"].push_back({{"round", c.round},
                                {"growth_factor", c.growth_factor},
                                {"kept_input", c.kept_input},
                                {"sweeps", c.sweeps},
                                {"porosity_before", c.porosity_before},
                                {"porosity_after", c.porosity_after},
                                {"wall_time_s", c.seconds}});
  for (const auto& b : band_steps)
    j["band_steps"].push_back({{"kind", b.kind},
                               {"particles", b.particles},
                               {"removed", b.removed},
                               {"inserted", b.inserted},
                               {"band_pairs", b.band_pairs},
                               {"lm_iterations", b.lm_iterations},
                               {"initial_cost", b.initial_cost},
                               {"final_cost", b.final_cost},
                               {"max_overlap_per_r_mean", b.max_overlap},
                               {"nominal_porosity", b.nominal_porosity},
                               {"coordination_number", b.coordination_number},
                               {"wall_time_s", b.seconds}});
  j["projection_max_shrink_per_r_mean"] = projection_max_shrink;
  j["projection_removed"] = projection_removed;
  j["placement_time_s"] = placement_seconds;
  j["densification_time_s"] = densification_seconds;
  j["total_time_s"] = total_seconds;
  j["termination"] = termination;
  return j;
}

template Packing<2> GeneratePacking<2>(const Domain<2>&, const GeneratorOptions&, GeneratorSummary*);
template Packing<3> GeneratePacking<3>(const Domain<3>&, const GeneratorOptions&, GeneratorSummary*);

}  // namespace specimen
