#pragma once
// generate-packing: dense isotropic packings of discs (2D) and spheres (3D) by a
// regular-triangulation contact graph and Levenberg-Marquardt densification of centres
// and radii (Labra 2012, section 3.2). Options in, Packing plus GeneratorSummary out.
//
//   GeneratorOptions options;
//   options.particle_count = 20000;
//   GeneratorSummary summary;
//   Packing<2> packing = GeneratePacking(Domain<2>::Rectangle(0, 0, 50, 50), options, &summary);
//   std::cout << summary.FullReport();

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "common/progress.h"
#include "generator/packing.h"

namespace specimen {

struct GeneratorOptions {
  // --- Size: set exactly one of the two. ---
  // Requested volume-based mean radius [m] (Labra 3.12); the particle count follows from
  // the domain volume and the expected porosity, so the achieved mean is close, not exact.
  double mean_radius = 0.0;
  // Requested number of particles; the achieved count is within a few per cent (particles
  // that do not fit are dropped, see GeneratorSummary).
  int particle_count = 0;

  // Bound on r_max / r_min, >= 1 (Labra's assemblies: 5-10). The radii of the packing stay
  // within [r_min, r_max] chosen around the expected mean radius.
  double radius_ratio = 10.0;
  // Spread (ratio of largest to smallest) of the node spacing of step 1, in [1, radius_ratio].
  // Wider spreads give denser packings with a broader radius distribution.
  double node_size_spread = 2.0;
  // Shape of the node size distribution over that spread: number density ~ s^-exponent
  // (1 = log-uniform, the default; larger values give more small nodes). In [0, 6].
  double node_size_exponent = 1.0;
  // Step 2, the initial radii.
  enum class InitialRadii {
    // Labra: each node's share of the distance to its neighbours (factor range below).
    kStienen,
    // The node spheres of step 1, scaled to the expected porosity: the node size
    // distribution becomes the radius distribution. They overlap until a compaction
    // (compaction_round 0) rearranges them; see PowerLawGeneratorOptions.
    kNodeSpheres,
  };
  InitialRadii initial_radii = InitialRadii::kStienen;
  // Step 2, Stienen factor range: initial radius = share of the neighbour distance times
  // a uniform random factor in [initial_radius_factor_min, initial_radius_factor_max].
  double initial_radius_factor_min = 0.9;
  double initial_radius_factor_max = 1.1;

  // Contact (bond) tolerance: pairs with |gap| <= contact_tolerance * mean radius are
  // contacts of the output (Labra section 3.2.3 updates the contact list with a tolerance
  // it does not give). In (0, 0.2].
  double contact_tolerance = 0.02;
  // Largest overlap, relative to the mean radius, the densification may leave before the
  // final projection removes it exactly (the projection gives back that much density).
  double overlap_tolerance = 0.005;
  // Keep overlaps up to overlap_tolerance (the projection removes only what exceeds it and
  // every protrusion): about 0.2 points of porosity denser in 2D. The overlapping pairs are
  // contacts (bonds) of the output; a solver that stores each bond's initial gap (this one:
  // ContactArrays::reference_gap) starts them stress-free, one that does not (a plain linear
  // contact law) starts them with a force of kn x overlap. Off: exact contacts, no overlap.
  bool keep_small_overlaps = false;

  // Pairs still overlapping by more than this (relative to the mean radius) after a round
  // are folded over each other, a local minimum further rounds cannot leave: the smaller
  // particle is removed and its hole refilled. In (overlap_tolerance, 1].
  double conflict_overlap = 0.05;
  // Holes that can take a particle of at least this radius (relative to the mean radius)
  // get one, tangent to the particles around the hole (hole_filling.h). In (0, 1]; the
  // particle radius is also bounded below by r_max / radius_ratio.
  double hole_fill_radius = 0.1;

  // Outer loop (Labra section 3.2.3): rounds of triangulation + least squares.
  int max_rounds = 4;
  // Levenberg-Marquardt iterations per round.
  int max_iterations_per_round = 100;
  // Rounds after the first keep closing the pairs the previous round left open by at most
  // this (relative to the mean radius) and drop the others (Labra's fix of defect (a)).
  // 0 = half the contact tolerance (the default). Larger values close more near-contacts
  // (higher nc) but leave conflicts that every round then re-solves in full (measured with
  // the power-law preset, 30k spheres: 0.06 gives nc 7.69 against 6.88 with 0.01, and the
  // preset uses it; README, generator benchmark). In [0, 0.5].
  double round_close_gap = 0.0;
  // Share of (Dim + 1) N constraints selected as exact contacts in each round: with radii
  // free, (Dim + 1) constraints per particle fix it (2D: the triangulation, 6 contacts).
  double constraint_fraction = 1.0;

  // Compaction (generator/compaction.h): rounds compaction_round ..
  // compaction_round + compaction_rounds - 1 (round 0: the initial packing) start with a
  // force-biased compaction of the packing (all radii grow by one factor while overlapping
  // pairs are pushed apart, until jammed), and their least-squares solve then closes the pairs left open by at most
  // compaction_close_gap (relative to the mean radius) instead of half the contact
  // tolerance. If max_rounds ends before compaction_round, the packing is compacted once
  // after the rounds. Off by default in 2D (the rounds reach 9.2 % there), on in 3D.
  bool compaction = false;
  int compaction_round = 3;         // in [0, 100]
  int compaction_rounds = 1;        // in [1, 100]
  double compaction_close_gap = 0.08;  // in [0, 0.5]
  // Displacement of an overlapping pair ~ overlap^exponent (normalised), in [0.5, 4].
  double compaction_exponent = 1.0;

  // Contact band (generator/contact_band.h), its solves with keep_small_overlaps only: after
  // the rounds, rattlers (fewer than Dim + 1 contacts) are replaced by particles refilled into
  // their holes, then least-squares solves pull every pair open by at most
  // contact_band_candidate_gap (relative to the mean radius) to within the contact tolerance,
  // with overlaps kept within the overlap tolerance. It passes the rigidity bound of exact
  // contacts: 3D, 30k spheres, power-law radii, overlap tolerance 0.02: nc 8.2 against 7.7
  // (README, generator benchmark). 0 rounds and 0 passes = off; the candidate gap and the
  // iteration cap apply to the solves only.
  int rattler_refill_passes = 0;            // in [0, 10]
  int contact_band_rounds = 0;              // in [0, 20]
  double contact_band_candidate_gap = 0.16;  // in (0, 0.5]
  int contact_band_iterations = 50;         // Levenberg-Marquardt iterations per solve, [1, 10000]

  // Record porosity and largest overlap after every Levenberg-Marquardt iteration in
  // GeneratorSummary::trace (for error-against-run-time studies; costs one pass over the
  // graph per iteration).
  bool record_trace = false;

  std::uint64_t seed = 1;  // same seed, same machine: identical output
  int num_threads = 2;
  ProgressCallback progress;  // may be empty

  // Names the first invalid field, its value and the allowed range.
  bool IsValid(std::string* error) const;
};

// The defaults that work best for each dimension (measured, see the README benchmark):
// 2D: node spread 2, holes filled down to r_min, 4 rounds; 3D: node spread 3, holes filled
// from 0.35 mean radii, 6 rounds, a compaction before round 3.
template <int Dim>
GeneratorOptions DefaultGeneratorOptions();

// The dense preset (generate-packing --radius-distribution power-law), for 3D above all:
// node sizes with number density ~ s^-3.5 over a spread of radius_ratio / 1.25 become the
// radii (InitialRadii::kNodeSpheres), a compaction jams them before round 0, round 0
// closes the pairs left open by up to half a mean radius and later rounds those open by up
// to 6 % of it (at most 25 iterations each). A broad, skewed distribution packs denser than
// the narrow one Stienen radii give (measured, 30k spheres in the unit cylinder: porosity
// 26.1 % against 34.1 %, nc 7.69 against 6.91, 103 s against 117 s; README, generator
// benchmark). The radius bounds are [smallest, largest] node size widened to radius_ratio.
template <int Dim>
GeneratorOptions PowerLawGeneratorOptions(double radius_ratio = 10.0);

struct GeneratorRound {
  int round = 0;
  int particles = 0;
  int free_particles = 0;       // particles the round let move (all in round 0)
  int graph_edges = 0;
  int exact_constraints = 0;  // two-sided residuals (edges + boundary ties)
  int lm_iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  double max_overlap = 0.0;       // after the round, relative to the mean radius
  double max_protrusion = 0.0;    // after the round, relative to the mean radius
  double nominal_porosity = 0.0;
  double coordination_number = 0.0;  // pairs within the contact tolerance
  int removed_particles = 0;      // folded or not fitting at r_min: removed
  int inserted_particles = 0;     // holes filled
  double seconds = 0.0;           // wall time since the start of generation
};

// One point of the convergence trace.
struct GeneratorTracePoint {
  int round = 0;
  int lm_iterations = 0;         // cumulative over rounds
  double seconds = 0.0;          // since the start of generation
  double nominal_porosity = 0.0;
  double max_overlap = 0.0;      // over the graph edges, relative to the expected mean radius
};

// One step of the contact band (contact_band.h): the state after it.
struct GeneratorBandStep {
  std::string kind;              // "refill" (rattlers replaced) or "band" (a solve)
  int particles = 0;
  int removed = 0;               // refill: rattlers removed
  int inserted = 0;              // refill: particles put into their holes
  int band_pairs = 0;            // band: pairs pulled into the band (two-sided)
  int lm_iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  double max_overlap = 0.0;      // relative to the mean radius
  double nominal_porosity = 0.0;
  double coordination_number = 0.0;  // pairs within the contact tolerance
  double seconds = 0.0;          // duration of the step
};

struct GeneratorSummary {
  std::string dimension_and_domain;
  // How the radii were drawn, e.g. "Stienen radii, node sizes ~ s^-1 over a spread of 3".
  std::string radius_distribution;
  int particles_requested = 0;
  int nodes_placed = 0;
  int particles_final = 0;
  double radius_min_bound = 0.0;
  double radius_max_bound = 0.0;
  std::vector<GeneratorRound> rounds;
  std::vector<GeneratorTracePoint> trace;  // only with GeneratorOptions::record_trace
  struct Compaction {
    int round = -1;             // the round it started (-1: after the rounds)
    double growth_factor = 1.0;  // common radius factor reached
    bool kept_input = false;    // the input was denser: kept
    int sweeps = 0;
    double porosity_before = 0.0;  // nominal
    double porosity_after = 0.0;
    double seconds = 0.0;
  };
  std::vector<Compaction> compactions;
  std::vector<GeneratorBandStep> band_steps;  // only with the contact band
  double projection_max_shrink = 0.0;  // largest radius reduction of the final projection, rel.
  int projection_removed = 0;
  double placement_seconds = 0.0;
  double densification_seconds = 0.0;
  double total_seconds = 0.0;
  std::string termination;

  std::string BriefReport() const;
  std::string FullReport() const;
  nlohmann::json ToJson() const;
};

// Generates a packing filling `domain`. Throws InputError for invalid options or a
// domain too small for the requested size.
template <int Dim>
Packing<Dim> GeneratePacking(const Domain<Dim>& domain, const GeneratorOptions& options,
                             GeneratorSummary* summary);

}  // namespace specimen
