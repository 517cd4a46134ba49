// generate-packing: a dense isotropic packing of discs (2D) or spheres (3D) filling a
// domain, by a regular-triangulation contact graph and Levenberg-Marquardt densification
// of centres and radii (Labra 2012, section 3.2; see generator/generate.h).
//
// Sample runs:
//   generate-packing --domain "rectangle 0 0 0.05 0.05" --count 5000 --output out/ucs
//   generate-packing --domain "disc 0 0 0.025" --mean-radius 2.5e-4 --name bts
//   generate-packing --domain "polygon 5 0 0 4 0 4 2 2 3 0 2" --count 2000
//   generate-packing --domain "cylinder 0 0 0.5 0 1" --count 30000 --radius-ratio 10
//   generate-packing --domain "cylinder 0 0 0.5 0 1" --count 30000 --radius-distribution power-law
//   generate-packing --domain "cylinder 0 0 0.5 0 1" --count 30000 --radius-distribution power-law
//       --keep-overlaps --overlap-tolerance 0.02 --contact-band   (one line: nc 8.2)
//   generate-packing --domain "box 0 0 0 1 1 1" --count 10000 --seed 7 --quiet
//
// Writes into --output (default out/): the packing file, VTU, Yade and LIGGGHTS exports,
// a JSON report and pictures (see generator/packing_outputs.h); prints the generator's
// round-by-round report and the packing metrics. Bad input: a message naming the field
// and its allowed range, exit status 2, and no file written.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "common/format.h"
#include "common/progress.h"
#include "generator/contact_band.h"
#include "generator/generate.h"
#include "generator/metrics.h"
#include "generator/packing_outputs.h"
#include "specimen_version.h"
#include "tools/command_line.h"

namespace specimen {
namespace {

// An option left out keeps the dimension's default (DefaultGeneratorOptions); one given is
// applied as given, so that a bad value is rejected by the validation, not replaced.
struct CommandLine {
  std::string domain;
  std::optional<double> mean_radius;
  std::optional<int> count;
  std::optional<double> radius_ratio;
  std::optional<double> node_spread;
  std::string radius_distribution = "stienen";  // "stienen" | "power-law"
  std::optional<double> size_exponent;
  std::vector<double> radius_factor;
  std::optional<double> contact_tolerance;
  std::optional<double> overlap_tolerance;
  std::optional<int> max_rounds;
  std::optional<double> close_gap;
  std::optional<double> exact_pairs;
  long long seed = 1;
  int threads = 2;
  PackingOutputOptions output;
  bool quiet = false;
  bool trace = false;
  bool keep_overlaps = false;
  std::string compaction;  // "on" | "off" | empty: the dimension's default
  std::optional<double> compaction_exponent;
  std::optional<int> compaction_rounds;
  bool contact_band = false;
  std::optional<int> band_rounds;
  std::optional<int> refill_passes;
  std::optional<double> band_candidate_gap;
};

// The fields of GeneratorOptions as the options that set them, for the messages.
const FieldNames kOptionNames = {
    {"mean_radius", "--mean-radius"},
    {"particle_count", "--count"},
    {"radius_ratio", "--radius-ratio"},
    {"node_size_spread", "--node-spread"},
    {"node_size_exponent", "--size-exponent"},
    {"initial radius factor range", "--radius-factor range"},
    {"contact_tolerance", "--contact-tolerance"},
    {"overlap_tolerance", "--overlap-tolerance"},
    {"max_rounds", "--max-rounds"},
    {"round_close_gap", "--close-gap"},
    {"constraint_fraction", "--exact-pairs"},
    {"num_threads", "--threads"},
    {"compaction_exponent", "--compaction-exponent"},
    {"compaction_rounds", "--compaction-rounds"},
    {"contact_band_rounds", "--band-rounds"},
    {"rattler_refill_passes", "--refill-passes"},
    {"contact_band_candidate_gap", "--band-candidate-gap"},
    {"liggghts_density_kg_per_m3", "--liggghts-density"},
    {"output name", "--name"},
};

// Rounds of the power-law preset before --contact-band (README, generator benchmark).
constexpr int kPowerLawRoundsBeforeBand = 3;

// Dimension of a domain from its first word.
int DomainDimension(const std::string& text) {
  std::istringstream in(text);
  std::string shape;
  in >> shape;
  if (shape == "rectangle" || shape == "disc" || shape == "polygon") return 2;
  if (shape == "box" || shape == "cylinder") return 3;
  throw InputError("--domain: unknown domain '" + shape +
                   "'; use rectangle, disc, polygon (2D) or box, cylinder (3D)");
}

template <int Dim>
int Run(const CommandLine& cl) {
  // 1. Options: the dimension's defaults, overridden by what was given.
  const Domain<Dim> domain = Domain<Dim>::Parse(cl.domain);
  if (cl.radius_distribution != "stienen" && cl.radius_distribution != "power-law")
    throw InputError("--radius-distribution = '" + cl.radius_distribution +
                     "' is not allowed: use stienen or power-law");
  const bool power_law = cl.radius_distribution == "power-law";
  // Settings that the chosen distribution would ignore are errors, not silently dropped.
  if (!power_law && cl.size_exponent)
    throw InputError("--size-exponent applies only to --radius-distribution power-law");
  if (power_law && !cl.radius_factor.empty())
    throw InputError("--radius-factor applies only to --radius-distribution stienen (power-law "
                     "radii are the node sizes)");
  if (power_law && cl.compaction == "off")
    throw InputError("--compaction off is not allowed with --radius-distribution power-law: its "
                     "initial spheres overlap until the compaction before round 0 jams them");
  GeneratorOptions options = power_law
                                 ? PowerLawGeneratorOptions<Dim>(cl.radius_ratio.value_or(10.0))
                                 : DefaultGeneratorOptions<Dim>();
  if (cl.size_exponent) options.node_size_exponent = *cl.size_exponent;
  options.mean_radius = cl.mean_radius.value_or(0.0);
  options.particle_count = cl.count.value_or(0);
  if (cl.mean_radius && !(*cl.mean_radius > 0.0))
    throw InputError("--mean-radius = " + Number(*cl.mean_radius) +
                     " is not allowed: it must be > 0");
  if (cl.count && *cl.count < 1)
    throw InputError("--count = " + std::to_string(*cl.count) + " is not allowed: it must be >= 1");
  if (cl.radius_ratio) options.radius_ratio = *cl.radius_ratio;
  if (cl.node_spread) options.node_size_spread = *cl.node_spread;
  if (cl.radius_ratio && !cl.node_spread && *cl.radius_ratio >= 1.0 && !power_law)
    options.node_size_spread = std::min(options.node_size_spread, options.radius_ratio);
  if (cl.radius_factor.size() == 2) {
    options.initial_radius_factor_min = cl.radius_factor[0];
    options.initial_radius_factor_max = cl.radius_factor[1];
  }
  if (cl.contact_tolerance) options.contact_tolerance = *cl.contact_tolerance;
  if (cl.overlap_tolerance) {
    options.overlap_tolerance = *cl.overlap_tolerance;
    // Pairs folded over each other must overlap by more than what a round may leave.
    options.conflict_overlap = std::max(options.conflict_overlap, 2.0 * options.overlap_tolerance);
  }
  if (cl.max_rounds) options.max_rounds = *cl.max_rounds;
  if (cl.close_gap) {
    if (!(*cl.close_gap > 0.0))
      throw InputError("--close-gap = " + Number(*cl.close_gap) +
                       " is not allowed: it must be in (0, 0.5] (relative to the mean radius)");
    options.round_close_gap = *cl.close_gap;
  }
  if (cl.exact_pairs) options.constraint_fraction = *cl.exact_pairs;
  if (cl.seed < 0)
    throw InputError("--seed = " + std::to_string(cl.seed) + " is not allowed: it must be >= 0");
  options.seed = static_cast<std::uint64_t>(cl.seed);
  options.num_threads = cl.threads;
  options.record_trace = cl.trace;
  if (!cl.compaction.empty() && cl.compaction != "on" && cl.compaction != "off")
    throw InputError("--compaction = '" + cl.compaction + "' is not allowed: use on or off");
  if (!cl.compaction.empty()) options.compaction = cl.compaction == "on";
  if (cl.compaction_exponent) options.compaction_exponent = *cl.compaction_exponent;
  options.keep_small_overlaps = cl.keep_overlaps;
  if (cl.compaction_rounds) options.compaction_rounds = *cl.compaction_rounds;
  if (!cl.contact_band && (cl.band_rounds || cl.refill_passes || cl.band_candidate_gap))
    throw InputError("--band-rounds, --refill-passes and --band-candidate-gap apply only with "
                     "--contact-band");
  if (cl.contact_band) {
    if (!cl.keep_overlaps)
      throw InputError("--contact-band needs --keep-overlaps: the band places pairs anywhere "
                       "between -overlap-tolerance and +contact-tolerance, and without it the final "
                       "projection removes every overlap again");
    options.rattler_refill_passes = cl.refill_passes.value_or(ContactBandOptions().refill_passes);
    options.contact_band_rounds = cl.band_rounds.value_or(ContactBandOptions().band_rounds);
    if (options.rattler_refill_passes == 0 && options.contact_band_rounds == 0)
      throw InputError("--contact-band with --band-rounds 0 and --refill-passes 0 has nothing to "
                       "do: leave out --contact-band instead");
    if (cl.band_candidate_gap) options.contact_band_candidate_gap = *cl.band_candidate_gap;
    // The band supersedes the preset's rounds 3 to 5 (measured, 30k spheres: nc 7.68 after
    // round 2, 7.69 after round 5), and they cost a fifth of the run.
    if (power_law && !cl.max_rounds) options.max_rounds = kPowerLawRoundsBeforeBand;
  }
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  // 2. Fail on an unusable output location now, not after the work.
  CheckPackingOutputLocation(cl.output);

  // 3. Generate, with progress on a terminal.
  TerminalProgress progress(cl.quiet);
  options.progress = progress.Callback();
  GeneratorSummary summary;
  const Packing<Dim> packing = GeneratePacking<Dim>(domain, options, &summary);
  progress.Finish();

  // 4. Measure and write.
  const PackingMetrics<Dim> metrics = ComputePackingMetrics<Dim>(packing);
  nlohmann::json report;
  report["command"] = "generate-packing";
  report["generator"] = summary.ToJson();
  const PackingOutputsWritten written = WritePackingOutputs<Dim>(packing, metrics, report, cl.output);

  // 5. Report.
  std::cout << summary.FullReport() << "\n" << MetricsReport<Dim>(metrics) << "\nfiles:\n";
  for (const auto& file : written.files) std::cout << "  " << file << "\n";
  for (const auto& warning : written.warnings) std::cerr << "warning: " << warning << "\n";
  return kExitOk;
}

}  // namespace
}  // namespace specimen

int main(int argc, char** argv) {
  using namespace specimen;
  CLI::App app{"generate-packing: dense isotropic disc (2D) and sphere (3D) packings"};
  CommandLine cl;
  app.set_version_flag("--version", std::string(kVersion));
  app.add_option("--domain", cl.domain,
                 "\"rectangle X0 Y0 X1 Y1\" | \"disc CX CY R\" | \"polygon N X1 Y1 ... XN YN\" | "
                 "\"box X0 Y0 Z0 X1 Y1 Z1\" | \"cylinder CX CY R Z0 Z1\" (metres; cylinder axis "
                 "along z)")
      ->required();
  auto* radius = app.add_option("--mean-radius", cl.mean_radius,
                                "requested volume-based mean radius [m] (> 0)");
  auto* count = app.add_option("--count", cl.count, "requested number of particles (>= 1)");
  radius->excludes(count);
  app.add_option("--radius-ratio", cl.radius_ratio, "bound on r_max / r_min (>= 1), default 10");
  app.add_option("--node-spread", cl.node_spread,
                 "spread of the initial node spacing, in [1, radius ratio]; default 2 (2D), 3 (3D), "
                 "radius ratio / 1.25 (power-law)");
  app.add_option("--radius-distribution", cl.radius_distribution,
                 "stienen (Labra: radii from the node spacing, narrow) | power-law (the node "
                 "sizes, number density ~ r^-exponent, become the radii, compacted before round "
                 "0: denser, 3D porosity 26 % against 34 %, nc 7.7 against 6.9); default stienen");
  app.add_option("--size-exponent", cl.size_exponent,
                 "power-law only: exponent of the size distribution, in [0, 6]; default 3.5");
  app.add_option("--radius-factor", cl.radius_factor,
                 "Stienen factor range MIN MAX for the initial radii, default 0.9 1.1")
      ->expected(2);
  app.add_option("--contact-tolerance", cl.contact_tolerance,
                 "pairs with |gap| <= this * mean radius are contacts (bonds), in (0, 0.2]; "
                 "default 0.02");
  app.add_flag("--keep-overlaps", cl.keep_overlaps,
               "keep overlaps up to --overlap-tolerance (about 0.2 points denser in 2D at the "
               "default 0.5 % of the mean radius, 0.25 at 2 %; the solver starts those bonds "
               "stress-free); default: exact contacts");
  app.add_option("--overlap-tolerance", cl.overlap_tolerance,
                 "largest overlap the densification may leave (relative to the mean radius), "
                 "removed exactly at the end or kept with --keep-overlaps, in [0, 0.1]; default 0.005");
  app.add_option("--max-rounds", cl.max_rounds,
                 "outer rounds (triangulation + LM), in [1, 100]; default 4 (2D), 6 (3D)");
  app.add_option("--close-gap", cl.close_gap,
                 "rounds after the first close the pairs left open by up to this (relative to "
                 "the mean radius) and drop the others, in (0, 0.5]; default half the contact "
                 "tolerance, 0.06 with power-law (3D: nc 7.7 against 6.9 with 0.01)");
  app.add_option("--exact-pairs", cl.exact_pairs,
                 "pairs solved as exact contacts in each round, as a share of (D+1) N (with free "
                 "radii D+1 contacts fix a particle), in (0, 2]; default 1. Above 1 the rounds "
                 "settle on a least-squares compromise (use with --keep-overlaps)");
  app.add_option("--compaction", cl.compaction,
                 "force-biased compaction (growth of all radii while overlaps are pushed apart) "
                 "at the start of round 3 (round 0 with power-law): on | off; default off (2D), on "
                 "(3D and power-law)");
  app.add_option("--compaction-exponent", cl.compaction_exponent,
                 "compaction displacement ~ overlap^exponent, in [0.5, 4]; default 1");
  app.add_option("--compaction-rounds", cl.compaction_rounds,
                 "rounds that start with a compaction (from round 3, or 0 with power-law), in "
                 "[1, 100]; default 1");
  app.add_flag("--contact-band", cl.contact_band,
               "after the rounds, replace rattlers (fewer than D+1 contacts) by particles "
               "refilled into their holes, then pull every pair open by up to "
               "--band-candidate-gap into the contact tolerance, overlaps kept within "
               "--overlap-tolerance: more contacts than exact contacts allow (3D, power-law, "
               "overlap tolerance 0.02: nc 8.2 against 7.7). Needs --keep-overlaps; with "
               "power-law, --max-rounds defaults to 3");
  app.add_option("--band-rounds", cl.band_rounds,
                 "least-squares solves of the contact band, in [0, 20]; default 3");
  app.add_option("--refill-passes", cl.refill_passes,
                 "rattler refill passes before the band solves, in [0, 10]; default 2");
  app.add_option("--band-candidate-gap", cl.band_candidate_gap,
                 "pairs open by up to this (relative to the mean radius) are pulled into the "
                 "band, in (0, 0.5]; default 0.16");
  app.add_option("--seed", cl.seed,
                 "random seed, >= 0, default 1; same seed, same machine: identical output");
  app.add_option("--threads", cl.threads, "threads for the least-squares solver, default 2");
  app.add_option("--output", cl.output.directory, "output directory (created), default out");
  app.add_option("--name", cl.output.name, "file name prefix, default packing");
  app.add_flag("--no-pictures", [&](std::int64_t) { cl.output.pictures = false; },
               "do not draw pictures (the CSV files are still written)");
  app.add_option("--liggghts-density", cl.output.liggghts_density_kg_per_m3,
                 "particle density written into the LIGGGHTS file [kg/m^3], default 2650");
  app.add_flag("--quiet", cl.quiet, "no progress display");
  app.add_flag("--trace", cl.trace,
               "record porosity and largest overlap after every LM iteration in the JSON report");
  if (int status = 0; !ParseCommandLine(app, argc, argv, &status)) return status;
  if (!radius->count() && !count->count()) {
    std::cerr << "generate-packing: error: give --count or --mean-radius\n";
    return kExitBadInput;
  }
  return RunCommand("generate-packing", [&] {
    return DomainDimension(cl.domain) == 2 ? Run<2>(cl) : Run<3>(cl);
  }, kOptionNames);
}
