#include "generator/contact_band.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include "common/error.h"
#include "generator/contact_graph.h"

namespace specimen {
namespace {

using Clock = std::chrono::steady_clock;

// The solves aim this far inside the band (both tolerances), so that the mean radius changing
// a little afterwards (refill, final projection) cannot push a pair out.
constexpr double kBandMargin = 0.9;
// Overlaps beyond the band are weighted this much more than gaps beyond it. The final
// projection would trim them and open the smaller particle's other contacts.
constexpr double kBandOverlapWeight = 4.0;
// Later solves drop the pairs the previous one left open by more than this many contact
// tolerances. A least-squares compromise over infeasible pairs would spread their gaps to
// the feasible ones (measured on 5,000 spheres: nc 6.8 with every pair open up to 0.2 r_mean
// kept, against 7.6 with the drop).
constexpr double kGiveUpTolerances = 2.0;

// One-sided pairs open by more than this (relative to the mean radius) are left out of a
// solve: a solve moves particles by a few per cent of a radius, and the final projection
// would catch the rare pair that closes anyway. They are a third of the graph's edges.
constexpr double kOneSidedReach = 0.25;

// A solve stops once the root-mean-square excess outside the band is this share of the band.
constexpr double kStopExcess = 0.01;

template <int Dim>
struct BandState {
  double max_overlap = 0.0;  // absolute
  int contacts = 0;          // pairs with |gap| <= the contact limit
  std::vector<int> degree;   // contacts per particle
};

// Contacts are pairs within the contact limit. Walls do not count towards a particle's
// degree: they are gone downstream (a UCS specimen's mantle is free, a bonded model bonds
// particles only), and a particle held by a wall and fewer than Dim + 1 others is then
// under-coordinated, as the packing metrics count it (metrics.h).
template <int Dim>
BandState<Dim> MeasureBand(const ContactGraph<Dim>& graph, const std::vector<Vector<Dim>>& x,
                           const std::vector<double>& r, double contact_limit) {
  BandState<Dim> state;
  state.degree.assign(x.size(), 0);
  for (const auto& e : graph.edges) {
    const double gap = PairGap<Dim>(x, r, e[0], e[1]);
    state.max_overlap = std::max(state.max_overlap, -gap);
    if (std::abs(gap) > contact_limit) continue;
    ++state.contacts;
    ++state.degree[e[0]];
    ++state.degree[e[1]];
  }
  return state;
}

// Fills the fields every step records: the state after the step.
template <int Dim>
void RecordState(const Domain<Dim>& domain, const ContactGraph<Dim>& graph,
                 const std::vector<Vector<Dim>>& x, const std::vector<double>& r,
                 double contact_tolerance, Clock::time_point step_start, GeneratorBandStep* step) {
  const double mean_radius = VolumeMeanRadius<Dim>(r);
  const BandState<Dim> state = MeasureBand<Dim>(graph, x, r, contact_tolerance * mean_radius);
  step->particles = static_cast<int>(x.size());
  step->max_overlap = state.max_overlap / mean_radius;
  step->nominal_porosity = NominalPorosity<Dim>(domain, r);
  step->coordination_number = 2.0 * state.contacts / static_cast<double>(x.size());
  step->seconds = std::chrono::duration<double>(Clock::now() - step_start).count();
}

// Step 1: rattlers out, holes refilled by tangent particles. `refilled` flags the particles
// an earlier pass put in: each is tangent to the Dim + 1 particles or walls of its hole, the
// best that hole allows, so it stays even when walls are among them (in 2D, removing and
// refilling those again was a cycle: 507 out, 507 in, on every pass).
template <int Dim>
GeneratorBandStep RefillRattlers(const Domain<Dim>& domain, const ContactBandOptions& options,
                                 std::vector<char>& refilled, std::vector<Vector<Dim>>& x,
                                 std::vector<double>& r) {
  const auto start = Clock::now();
  GeneratorBandStep step;
  step.kind = "refill";
  ContactGraph<Dim> graph = BuildContactGraph<Dim>(domain, x, r, options.ghost_band);
  const BandState<Dim> state =
      MeasureBand<Dim>(graph, x, r, options.contact_tolerance * VolumeMeanRadius<Dim>(r));
  std::vector<char> remove(x.size(), 0);
  for (size_t i = 0; i < x.size(); ++i) remove[i] = state.degree[i] < Dim + 1 && !refilled[i];
  step.removed = RemoveFlaggedParticles<Dim>(remove, x, r, &refilled);
  // A hole emptied by a rattler may take several particles; each pass of FillHoles puts at
  // most one into a simplex neighbourhood.
  constexpr int kFillPasses = 3;
  for (int pass = 0; pass < kFillPasses; ++pass) {
    graph = BuildContactGraph<Dim>(domain, x, r, options.ghost_band, /*with_cells=*/true);
    const int inserted = FillHoles<Dim>(domain, graph, options.hole_filling, x, r);
    step.inserted += inserted;
    if (inserted == 0) break;
  }
  refilled.resize(x.size(), 1);
  graph = BuildContactGraph<Dim>(domain, x, r, options.ghost_band);
  RecordState<Dim>(domain, graph, x, r, options.contact_tolerance, start, &step);
  return step;
}

// Step 2: one least-squares solve of the band. `band_pairs` (sorted pairs i < j) carries the
// selection from one solve to the next (no particle is removed or added between solves).
template <int Dim>
GeneratorBandStep SolveBand(const Domain<Dim>& domain, const ContactBandOptions& options,
                            bool first, std::vector<std::array<int, 2>>& band_pairs,
                            std::vector<Vector<Dim>>& x, std::vector<double>& r) {
  const auto start = Clock::now();
  GeneratorBandStep step;
  step.kind = "band";
  const double mean_radius = VolumeMeanRadius<Dim>(r);
  const double contact_limit = options.contact_tolerance * mean_radius;
  const double candidate_gap = options.candidate_gap * mean_radius;
  const double give_up_gap = kGiveUpTolerances * contact_limit;
  ContactGraph<Dim> graph = BuildContactGraph<Dim>(domain, x, r, options.ghost_band);

  LevenbergMarquardtOptions solver = options.solver;
  solver.band_overlap = kBandMargin * options.overlap_tolerance * mean_radius;
  solver.band_gap = kBandMargin * contact_limit;
  solver.overlap_weight = kBandOverlapWeight;
  solver.free_particles.clear();
  // Walls: no protrusion, and no pull either (wall ties are not contacts of the output).
  solver.tie_one_sided.assign(graph.boundary_ties.size(), 1);
  // The solve's graph: the band pairs, and the one-sided pairs near enough to overlap.
  ContactGraph<Dim> band_graph;
  band_graph.boundary_ties = graph.boundary_ties;
  solver.edge_one_sided.clear();
  const double reach = kOneSidedReach * mean_radius;
  std::vector<std::array<int, 2>> selected;
  for (const auto& e : graph.edges) {
    const double gap = PairGap<Dim>(x, r, e[0], e[1]);
    const bool in_contact = std::abs(gap) <= contact_limit;
    const bool take =
        in_contact || (first ? gap <= candidate_gap
                             : gap <= give_up_gap &&
                                   std::binary_search(band_pairs.begin(), band_pairs.end(), e));
    if (!take && gap > reach) continue;
    band_graph.edges.push_back(e);
    solver.edge_one_sided.push_back(take ? 0 : 1);
    if (take) selected.push_back(e);
  }
  std::sort(selected.begin(), selected.end());
  band_pairs.swap(selected);
  step.band_pairs = static_cast<int>(band_pairs.size());
  // Done once the root-mean-square excess over the band pairs is a small share of the band.
  const double stop_excess = kStopExcess * solver.band_gap / solver.length_scale;
  solver.stop_cost = 0.5 * static_cast<double>(band_pairs.size()) * stop_excess * stop_excess;

  const LevenbergMarquardtSummary solve =
      SolveLevenbergMarquardt<Dim>(domain, band_graph, solver, x, r);
  // Ceres does not start from a point outside the radius bounds (or a failed evaluation).
  if (solve.iterations < 0)
    throw ComputationError("contact band: the least-squares solve could not start: " +
                           solve.termination);
  step.lm_iterations = solve.iterations;
  step.initial_cost = solve.initial_cost;
  step.final_cost = solve.final_cost;
  graph = BuildContactGraph<Dim>(domain, x, r, options.ghost_band);
  RecordState<Dim>(domain, graph, x, r, options.contact_tolerance, start, &step);
  return step;
}

}  // namespace

template <int Dim>
std::vector<GeneratorBandStep> RunContactBand(const Domain<Dim>& domain,
                                              const ContactBandOptions& options,
                                              std::vector<Vector<Dim>>& centres,
                                              std::vector<double>& radii,
                                              const ProgressCallback& progress) {
  if (!(options.contact_tolerance > 0.0) || !(options.overlap_tolerance >= 0.0) ||
      !(options.candidate_gap > 0.0) || options.refill_passes < 0 || options.band_rounds < 0)
    throw InputError("contact band: contact_tolerance and candidate_gap must be > 0, "
                     "overlap_tolerance >= 0, refill_passes and band_rounds >= 0");
  std::vector<GeneratorBandStep> steps;
  const int total = options.refill_passes + options.band_rounds;
  auto report = [&](const std::string& message) {
    if (progress) progress(static_cast<double>(steps.size()) / std::max(1, total), message);
  };
  std::vector<char> refilled(centres.size(), 0);
  for (int pass = 0; pass < options.refill_passes; ++pass) {
    report("contact band: refilling rattlers, pass " + std::to_string(pass + 1));
    steps.push_back(RefillRattlers<Dim>(domain, options, refilled, centres, radii));
  }
  std::vector<std::array<int, 2>> band_pairs;
  for (int round = 0; round < options.band_rounds; ++round) {
    report("contact band: solve " + std::to_string(round + 1) + " of " +
           std::to_string(options.band_rounds));
    steps.push_back(SolveBand<Dim>(domain, options, round == 0, band_pairs, centres, radii));
  }
  return steps;
}

template std::vector<GeneratorBandStep> RunContactBand<2>(const Domain<2>&,
                                                          const ContactBandOptions&,
                                                          std::vector<Vector<2>>&,
                                                          std::vector<double>&,
                                                          const ProgressCallback&);
template std::vector<GeneratorBandStep> RunContactBand<3>(const Domain<3>&,
                                                          const ContactBandOptions&,
                                                          std::vector<Vector<3>>&,
                                                          std::vector<double>&,
                                                          const ProgressCallback&);

}  // namespace specimen
