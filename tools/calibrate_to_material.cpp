// calibrate-to-material: contact parameters (kn, kt, Rn, Rt, mu; Ep, nu_p for deformable
// particles) that make virtual UCS and Brazilian tests reproduce a target rock, within the
// DDEM convergence bound, measured on the real specimens (calibrate/calibration.h).
//
//   calibrate-to-material data/materials/labra2012_rock.toml --output out/calibration
//
// 1. Read and check the target material and the options (nothing runs on bad input).
// 2. Generate the specimens (or read the given packings).
// 3. Build or reuse the maps; measure the reach; the elastic and strength stages (progress
//    on a terminal).
// 4. Print the report and write the parameters, scenes, report, maps and pictures. Exit 0
//    when every property is met, 4 when one is out of reach (the report says which, and
//    what is reachable), the budget was spent or every strength round failed (a failed
//    round is reported and the loop goes on without it).
//
// Under mpirun (common/ranks.h; docs/calibration.md, "On a cluster"): every rank runs this
// program on the same inputs; the sweep points, the elastic runs and the two tests of a
// strength round are split over the ranks, each with --threads threads. Rank 0 generates the
// specimens (and sends them), prints, and writes every file but the other ranks' sweep
// journals and the final Brazilian test's own outputs (written by the rank that ran it).

#include <CLI/CLI.hpp>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>

#include "calibrate/calibration.h"
#include "calibrate/calibration_outputs.h"
#include "calibrate/lattice_calibration.h"
#include "calibrate/lattice_strength_map.h"
#include "calibrate/map_store.h"
#include "calibrate/target_material.h"
#include "common/atomic_file.h"
#include "common/format.h"
#include "common/progress.h"
#include "common/ranks.h"
#include "generator/metrics.h"
#include "generator/packing_io.h"
#include "lab/lab_specimen.h"
#include "specimen_version.h"
#include "tools/command_line.h"

namespace specimen {
namespace {

struct CommandLine {
  std::string material;
  int dimension = 2;
  std::string model = "auto";
  std::string packing, bts_packing;
  std::string ucs_domain;
  std::optional<int> count;  // given: applied as given (0 is rejected, not the default)
  double sweep_fraction = 0.3;
  long long seed = 1;
  double radius_ratio = 10.0;
  std::optional<std::string> maps_directory;  // default: DefaultMapsDirectory()
  std::string maps_file;
  bool no_reuse = false;
  int threads = 0;
  std::optional<int> rounds;  // default: 6 bonded, 12 lattice
  double max_spectral_radius = 0.9;
  double particle_poisson_ratio = 0.45;
  double friction = 0.8;
  double bond_range = 1.0;
  std::optional<double> rate_group;
  std::optional<double> loading_arc;  // default: 0 bonded (flat platens), 30 lattice
  std::string lattice_map = "target";
  std::optional<int> sweep_levels;
  std::vector<double> sweep_stiffness_ratio;  // lower, upper; empty: the default box
  int anchor_levels = 2;
  std::string honour = "compressive";
  std::string output = "out/calibration";
  std::string name = "calibration";
  bool no_pictures = false;
  bool quiet = false;
};

// The fields of CalibrationOptions and SpecimenPlan as the options that set them.
const FieldNames kOptionNames = {
    {"max_verification_rounds", "--rounds"},
    {"max_spectral_radius", "--max-spectral-radius"},
    {"particle_poisson_ratio", "--nu-p"},
    {"friction_coefficient", "--friction"},
    {"bond_range", "--bond-range"},
    {"loading_rate_group", "--rate-group"},
    {"loading_arc_deg", "--loading-arc"},
    {"sweep_levels", "--sweep-levels"},
    {"stiffness_ratio_lower, upper", "--sweep-stiffness-ratio"},
    {"anchor_levels", "--anchor-levels"},
    {"workers", "--threads"},
    {"ucs_particles", "--count"},
    {"radius_ratio", "--radius-ratio"},
    {"output name", "--name"},
};

// data/maps of the working directory when there is one (a run from the repository), else
// the source tree's, so that the shipped maps are found from anywhere.
std::string DefaultMapsDirectory() {
  if (std::filesystem::is_directory("data/maps")) return "data/maps";
#ifdef SPECIMEN_DATA_DIR
  if (std::filesystem::is_directory(SPECIMEN_DATA_DIR "/maps")) return SPECIMEN_DATA_DIR "/maps";
#endif
  return "data/maps";
}

// The map file and directory are checked before any specimen is generated.
void CheckMapLocations(const std::string& file, const std::string& directory) {
  namespace fs = std::filesystem;
  if (!file.empty()) {
    if (!fs::exists(file)) throw FileError("--maps: the map file '" + file + "' does not exist");
    if (!fs::is_regular_file(file)) throw FileError("--maps: '" + file + "' is not a regular file");
    LoadStoredMaps(file);  // unreadable or not a map: fails now, not after the specimens
  }
  if (fs::exists(directory) && !fs::is_directory(directory))
    throw FileError("--maps-dir: '" + directory + "' exists and is not a directory");
}

// Generated specimens: on rank 0, sent to the others in the packing file format (exact
// decimals, generator/packing_io.h), so that every rank runs its tests on the same particles
// (the generator's threads need not give the same bits in another process).
template <int Dim>
CalibrationSpecimens<Dim> GenerateOnRankZero(const SpecimenPlan<Dim>& plan) {
  if (!Distributed()) return MakeCalibrationSpecimens<Dim>(plan);
  nlohmann::json text;
  if (Rank() == 0) {
    const CalibrationSpecimens<Dim> made = MakeCalibrationSpecimens<Dim>(plan);
    auto write = [](const Packing<Dim>& p) {
      std::ostringstream out;
      WritePacking<Dim>(p, out);
      return out.str();
    };
    text = {{"ucs", write(made.ucs)}, {"bts", write(made.bts)}, {"sweep_ucs", write(made.sweep_ucs)},
            {"sweep_bts", write(made.sweep_bts)}, {"description", made.description}};
  }
  text = nlohmann::json::parse(Broadcast(text.dump()));
  // Rank 0 reads them back too: every rank holds what the text says, bit for bit.
  auto read = [&](const char* which) {
    std::istringstream in(text.at(which).get<std::string>());
    return ReadPacking<Dim>(in, std::string("generated ") + which + " specimen");
  };
  CalibrationSpecimens<Dim> s(read("ucs"), read("bts"), read("sweep_ucs"), read("sweep_bts"));
  s.description = text.at("description").get<std::string>();
  return s;
}

void PrintCalibration(const CalibrationSummary& summary, const std::string& specimens,
                      const CalibrationOutputsWritten& written) {
  std::cout << "specimens: " << specimens << "\n\n";
  std::cout << summary.FullReport() << "\n" << summary.BriefReport() << "\n";
  std::cout << "files:\n";
  for (const auto& file : written.files) std::cout << "  " << file << "\n";
  for (const auto& warning : written.warnings) std::cerr << "warning: " << warning << "\n";
  for (const VerificationRound& v : summary.rounds)
    if (v.failed) std::cerr << "warning: strength round " << v.round << " failed: " << v.failure << "\n";
}

template <int Dim>
int Run(const TargetMaterial& target, CalibrationOptions options, const CommandLine& cl) {
  // Outputs are checked before hours of work.
  CalibrationOutputOptions output;
  output.directory = cl.output;
  output.name = cl.name;
  output.pictures = !cl.no_pictures;
  if (Rank() == 0) CheckCalibrationOutputLocation(output);

  // Progress on rank 0 only (in lines under mpirun, whose pipes are no terminal).
  TerminalProgress progress(cl.quiet || Rank() != 0, Distributed());
  options.progress = progress.Callback();
  auto specimens = [&]() {
    if (!cl.packing.empty()) {
      if (cl.bts_packing.empty()) throw InputError("--packing needs --bts-packing (the Brazilian disc) as well");
      Packing<Dim> ucs = LoadPacking<Dim>(cl.packing);
      Packing<Dim> bts = LoadPacking<Dim>(cl.bts_packing);
      CheckPackingGeometry<Dim>(ucs, cl.packing);
      CheckPackingGeometry<Dim>(bts, cl.bts_packing);
      // Checked against their tests before any map sweep (a refused run leaves nothing).
      DescribeSpecimen<Dim>(ucs, LabTestKind::kUniaxialCompression, options.test.strain_boundary_margin);
      DescribeSpecimen<Dim>(bts, LabTestKind::kBrazilian, options.test.strain_boundary_margin);
      CalibrationSpecimens<Dim> s(ucs, bts, ucs, bts);
      s.description = "UCS " + cl.packing + ", Brazilian " + cl.bts_packing + " (maps on the same packings)";
      return s;
    }
    SpecimenPlan<Dim> plan;
    plan.ucs_domain = cl.ucs_domain;
    plan.ucs_particles = cl.count.value_or(0);
    plan.sweep_fraction = cl.sweep_fraction;
    plan.seed = static_cast<std::uint64_t>(cl.seed);
    plan.radius_ratio = cl.radius_ratio;
    plan.progress = options.progress;
    return GenerateOnRankZero<Dim>(plan);
  }();
  const CalibrationSummary summary = CalibrateToMaterial<Dim>(specimens, target, options);
  progress.Finish();
  CalibrationOutputsWritten written;
  if (Rank() == 0) written = WriteCalibrationOutputs<Dim>(summary, specimens, options, output);
  else if (summary.final_bts_rank == Rank()) written = WriteFinalBrazilianOutputs<Dim>(summary, specimens, output);
  if (Distributed()) {  // the files of every rank, listed by rank 0
    nlohmann::json mine = {{"files", written.files}, {"warnings", written.warnings}};
    written = CalibrationOutputsWritten();
    for (const std::string& text : AllGather(mine.dump())) {
      const nlohmann::json j = nlohmann::json::parse(text);
      for (const auto& f : j.at("files")) written.files.push_back(f.get<std::string>());
      for (const auto& w : j.at("warnings")) written.warnings.push_back(w.get<std::string>());
    }
  }
  // The same outcome on every rank (the same measurements, the same decisions): the others
  // leave the report to rank 0 and end with the same status.
  if (Rank() == 0) PrintCalibration(summary, specimens.description, written);
  if (summary.best_round < 1) {
    if (Rank() == 0)
      std::cerr << "calibrate-to-material: no strength round measured anything (every one failed; the report "
                   "gives each failure and its parameters)\n";
    return kExitComputation;
  }
  if (Rank() != 0) return summary.gave_up || !summary.converged ? kExitComputation : kExitOk;
  if (summary.gave_up) {

    std::cerr << "calibrate-to-material: the target is out of reach on this specimen; given up:";
    for (const std::string& g : summary.solution.reach.given_up) std::cerr << " " << g;
    std::cerr << " (the report gives the reachable intervals and the nearest reachable point)\n";
    return kExitComputation;
  }
  if (!summary.converged) {
    std::cerr << "calibrate-to-material: the targets were not all met within tolerance (see the report)\n";
    return kExitComputation;
  }
  return kExitOk;
}

// The lattice's strength map for these specimens and tests (calibrate/lattice_strength_map.h):
// --maps FILE as given (it must match them), else the one stored in the maps directory; the
// rows the target's nu needs (--lattice-map all: every row) are measured and stored when
// missing, or with --no-reuse. None with --lattice-map none, or for an orthotropic target.
// `report` gets one line saying which map and what was built.
std::optional<LatticeStrengthMap> LatticeMapFor(const Packing<2>& ucs, const Packing<2>& bts,
                                                const TargetMaterial& target, const LatticeCalibrationOptions& options,
                                                const CommandLine& cl, std::string* report) {
  if (cl.lattice_map == "none" || target.orthotropic || target.poisson_ratio < 0.0) {
    *report = std::string("strength map: none (") +
              (target.orthotropic            ? "an orthotropic target"
               : target.poisson_ratio < 0.0 ? "its rows are for nu in [0, 0.5)"
                                            : "--lattice-map none") +
              "): the rounds start from the closed form\n";
    return std::nullopt;
  }
  const PackingDescriptors ucs_d = DescribePacking<2>(ComputePackingMetrics<2>(ucs));
  const PackingDescriptors bts_d = DescribePacking<2>(ComputePackingMetrics<2>(bts));
  const nlohmann::json protocol = LatticeMapProtocol(options.test, options.protocol);
  const std::string directory = cl.maps_directory.value_or(DefaultMapsDirectory());
  std::string path = cl.maps_file;
  if (path.empty()) path = FindLatticeStrengthMap(directory, ucs_d, bts_d, protocol);
  LatticeStrengthMap map;
  if (!path.empty()) {
    map = LoadLatticeStrengthMap(path);
    std::string why;
    if (!cl.maps_file.empty() && !LatticeMapMatches(map, ucs_d, bts_d, protocol, &why))
      throw InputError("--maps " + path + ": built for other specimens or tests: " + why);
  } else {
    map.ucs_descriptors = ucs_d;
    map.bts_descriptors = bts_d;
    map.protocol = protocol;
    path = (std::filesystem::path(directory) / LatticeMapFileName(ucs_d, bts_d, protocol)).string();
  }
  // The rows of the default grid that are wanted and not present (all of them with --no-reuse).
  const LatticeMapDesign grid;
  std::vector<double> rows;
  const std::vector<double> present = map.Rows();
  const std::vector<double> wanted =
      cl.lattice_map == "all" ? grid.poisson_ratios : grid.RowsFor(target.poisson_ratio);
  for (double nu : wanted)
    if (cl.no_reuse || std::find(present.begin(), present.end(), nu) == present.end()) rows.push_back(nu);
  if (!rows.empty()) {
    std::string text;
    for (double nu : rows) text += (text.empty() ? "" : ", ") + Number(nu);
    const double before = map.build_seconds;
    try {
      MeasureLatticeMapRows(rows, LatticeTestsOn(ucs, bts, options.test, options.protocol), options.progress, &map);
    } catch (const ComputationError& e) {
      std::cerr << "calibrate-to-material: warning: the strength map's rows could not be measured (" << e.what()
                << "); the rounds start from the closed form\n";
      *report = "strength map: none (a map point failed): the rounds start from the closed form\n";
      return std::nullopt;
    }
    *report = "strength map: " + path + ", rows nu " + text + " measured now (" +
              Number(map.build_seconds - before, 3) + " s)\n";
    try {
      const std::filesystem::path parent = std::filesystem::path(path).parent_path();
      if (!parent.empty()) std::filesystem::create_directories(parent);
      // Rows another run stored meanwhile are kept (read again just before the write).
      if (std::filesystem::exists(path)) {
        try {
          const LatticeStrengthMap stored = LoadLatticeStrengthMap(path);
          if (LatticeMapMatches(stored, ucs_d, bts_d, protocol, nullptr)) MergeLatticeMapRows(stored, &map);
        } catch (const std::exception&) {
          // Not a readable map: replaced by this one.
        }
      }
      SaveLatticeStrengthMap(map, path);
    } catch (const std::exception& e) {  // the calibration goes on with the map in memory
      std::cerr << "calibrate-to-material: warning: the strength map could not be stored (" << e.what() << ")\n";
      *report += "  (not stored: " + std::string(e.what()) + ")\n";
    }
  } else {
    *report = "strength map: " + path + " (built by " + map.code_version + ", " + map.created_utc + ")\n";
  }
  return map;
}

// --model lattice: the six-spring lattice (calibrate/lattice_calibration.h): E and nu are its
// inputs, the rounds fit the triangles' cohesion and tensile strength from the map's start.
int RunLattice(const TargetMaterial& target, const CommandLine& cl) {
  CalibrationOutputOptions output;
  output.directory = cl.output;
  output.name = cl.name;
  output.pictures = false;
  CheckCalibrationOutputLocation(output);
  TerminalProgress progress(cl.quiet);
  LatticeCalibrationOptions options;
  options.max_rounds = cl.rounds.value_or(options.max_rounds);
  if (cl.rate_group) options.test.loading_rate_group = *cl.rate_group;
  if (cl.loading_arc) options.protocol.loading_arc_deg = *cl.loading_arc;
  options.progress = progress.Callback();
  std::string error;
  if (!options.IsValid(&error)) throw InputError(InUserTerms(error, {{"max_rounds", "--rounds"},
                                                                    {"loading_rate_group", "--rate-group"},
                                                                    {"loading_arc", "--loading-arc"}}));
  if (cl.lattice_map != "target" && cl.lattice_map != "all" && cl.lattice_map != "none")
    throw InputError("--lattice-map = '" + cl.lattice_map + "', allowed target, all or none");
  if (!cl.maps_file.empty()) LoadLatticeStrengthMap(cl.maps_file);  // not a lattice map: fails now
  if (const std::string directory = cl.maps_directory.value_or(""); !directory.empty() &&
      std::filesystem::exists(directory) && !std::filesystem::is_directory(directory))
    throw FileError("--maps-dir: '" + directory + "' exists and is not a directory");
  Packing<2> ucs(Domain<2>::Rectangle(0, 0, 1, 1)), bts(Domain<2>::Rectangle(0, 0, 1, 1));
  std::string description, map_report;
  if (!cl.packing.empty()) {
    if (cl.bts_packing.empty()) throw InputError("--packing needs --bts-packing (the Brazilian disc) as well");
    ucs = LoadPacking<2>(cl.packing);
    bts = LoadPacking<2>(cl.bts_packing);
    CheckPackingGeometry<2>(ucs, cl.packing);
    CheckPackingGeometry<2>(bts, cl.bts_packing);
    CheckSpecimenShape<2>(ucs.domain, LabTestKind::kUniaxialCompression);
    CheckSpecimenShape<2>(bts.domain, LabTestKind::kBrazilian);
    description = "UCS " + cl.packing + ", Brazilian " + cl.bts_packing;
  } else {
    SpecimenPlan<2> plan;
    plan.ucs_domain = cl.ucs_domain;
    plan.ucs_particles = cl.count.value_or(0);
    plan.sweep_fraction = 1.0;  // no maps: no map specimens
    plan.seed = static_cast<std::uint64_t>(cl.seed);
    plan.radius_ratio = cl.radius_ratio;
    plan.progress = options.progress;
    const CalibrationSpecimens<2> made = MakeCalibrationSpecimens<2>(plan);
    ucs = made.ucs;
    bts = made.bts;
    description = made.description;
  }
  options.map = LatticeMapFor(ucs, bts, target, options, cl, &map_report);
  const LatticeCalibrationSummary summary = CalibrateLattice(ucs, bts, target, options);
  progress.Finish();

  // The files, together: report, JSON, parameters, the two specimens and their scenes.
  const std::string base = cl.output + "/" + cl.name;
  auto scene = [&](const char* kind, const std::string& packing) {
    return "# run-test scene of calibrate-to-material --model lattice\n[specimen]\npacking = \"" +
           std::filesystem::path(packing).filename().string() + "\"\n\n" + summary.MaterialToml() +
           "\n[test]\nkind = \"" + kind + "\"\n" +
           (cl.rate_group ? "loading_rate_group = " + Number(*cl.rate_group, 17) + "\n" : std::string()) +
           (cl.loading_arc && std::string(kind) == "brazilian" ? "loading_arc = " + Number(*cl.loading_arc, 17) + "\n"
                                                              : std::string()) +
           "\n[output]\nname = \"" + cl.name + "_" + kind + "\"\n";
  };
  nlohmann::json report = summary.ToJson();
  report["command"] = "calibrate-to-material";
  report["version"] = kVersion;
  report["specimens"]["description"] = description;
  OutputGroup group;
  group.Add(base + "_report.txt", [&](std::ostream& out) { out << summary.FullReport(); });
  group.Add(base + "_report.json", [&](std::ostream& out) { out << report.dump(2) << "\n"; });
  group.Add(base + "_parameters.toml", [&](std::ostream& out) {
    out << "# calibrate-to-material --model lattice: " << summary.BriefReport() << "\n" << summary.MaterialToml();
  });
  group.Add(base + "_ucs.packing", [&](std::ostream& out) { WritePacking<2>(ucs, out); });
  group.Add(base + "_bts.packing", [&](std::ostream& out) { WritePacking<2>(bts, out); });
  group.Add(base + "_ucs_scene.toml", [&](std::ostream& out) { out << scene("ucs", base + "_ucs.packing"); });
  group.Add(base + "_bts_scene.toml", [&](std::ostream& out) { out << scene("brazilian", base + "_bts.packing"); });
  const std::vector<std::string> files = group.Commit();
  std::cout << "specimens: " << description << "\n" << map_report << "\n" << summary.FullReport() << "\n" << summary.BriefReport()
            << "\nfiles:\n";
  for (const auto& file : files) std::cout << "  " << file << "\n";
  if (summary.tensile_capped) {
    std::cerr << "calibrate-to-material: sigma_t is out of the lattice's reach on this specimen; given up: sigma_t "
                 "(the report says where the Brazilian strength stays)\n";
    return kExitComputation;
  }
  if (!summary.converged) {
    std::cerr << "calibrate-to-material: the targets were not all met within tolerance (see the report)\n";
    return kExitComputation;
  }
  return kExitOk;
}

}  // namespace
}  // namespace specimen

int main(int argc, char** argv) {
  using namespace specimen;
  RankSession ranks(&argc, &argv);
  CLI::App app{"calibrate-to-material: contact parameters of a bonded DEM/DDEM model for a target rock, "
               "from maps of virtual UCS and Brazilian tests, verified by running them"};
  CommandLine cl;
  app.set_version_flag("--version", std::string(kVersion));
  app.add_option("material", cl.material, "target material (TOML; see data/materials/)")->required();
  app.add_option("--dimension", cl.dimension, "2 (discs, plane strain) or 3 (spheres), default 2");
  app.add_option("--model", cl.model,
                 "rigid | ddem | auto (DDEM when nu is beyond rigid particles; the lattice for an orthotropic target) | "
                 "lattice (six-spring, 2D), default auto");
  app.add_option("--packing", cl.packing, "UCS specimen packing file (else generated)");
  app.add_option("--bts-packing", cl.bts_packing, "Brazilian disc packing file (with --packing)");
  app.add_option("--ucs-domain", cl.ucs_domain,
                 "UCS specimen domain to generate, default 'rectangle 0 0 0.05 0.05' (2D), "
                 "'cylinder 0 0 0.025 0 0.1' (3D)");
  app.add_option("--count", cl.count, "particles of the UCS specimen, default 5000 (2D), 20000 (3D)");
  app.add_option("--sweep-fraction", cl.sweep_fraction,
                 "share of the particles of the map specimens, in (0, 1], default 0.3");
  app.add_option("--seed", cl.seed, "generator seed, >= 0, default 1");
  app.add_option("--radius-ratio", cl.radius_ratio, "bound on r_max / r_min, default 10");
  app.add_option("--maps-dir", cl.maps_directory, "where maps are stored and reused, default data/maps (of the working directory, else "
                 "of the source tree: the shipped maps)");
  app.add_option("--maps", cl.maps_file, "use this map file (must have been built for an equivalent packing)");
  app.add_flag("--no-reuse", cl.no_reuse, "build the maps again even if stored ones match");
  app.add_option("--lattice-map", cl.lattice_map,
                 "--model lattice: the strength map rows measured when missing: target (the target's nu), all "
                 "(every row), none (no map: start from the closed form), default target");
  app.add_option("--threads,--workers", cl.threads,
                 "sweep points (and elastic runs) at once on each rank, default: hardware threads");
  app.add_option("--rounds", cl.rounds, "strength rounds (UCS + BTS) at most, 1 to 20, default 6 (lattice: 12)");
  app.add_option("--max-spectral-radius", cl.max_spectral_radius,
                 "bound on rho(B) of the DDEM iteration, in (0, 1), default 0.9");
  app.add_option("--nu-p", cl.particle_poisson_ratio, "particle Poisson ratio of the DDEM maps, default 0.45");
  app.add_option("--friction", cl.friction, "friction coefficient mu of broken bonds, default 0.8");
  app.add_option("--bond-range", cl.bond_range,
                 "bond every pair within gamma (ri + rj), in [1, 1.5]; above 1 it raises sigma_c/sigma_t "
                 "(spheres); default 1: the packing's contacts");
  app.add_option("--sweep-levels", cl.sweep_levels,
                 "levels of kt/kn in the map sweep (Rt/Rn and kn/(Ep l): one fewer, at least 3), 3 to 12; "
                 "default 4 (rigid), 3 (DDEM)");
  app.add_option("--sweep-stiffness-ratio", cl.sweep_stiffness_ratio,
                 "LO HI: the box of kt/kn of the maps (and so of the calibration), 0 < LO < HI <= 1; default "
                 "0.15 0.9 (rigid), 0.15 0.6 (DDEM); nu rises as kt/kn falls")
      ->expected(2);
  app.add_option("--anchor-levels", cl.anchor_levels,
                 "transfer anchors measured on the real specimens: 2 (four, a two-level design) or 3 (besides "
                 "them nine at the edges and middle of the maps' box); stored maps with fewer are completed; "
                 "default 2");
  app.add_option("--rate-group", cl.rate_group, "loading-rate group V / sqrt(kn/rho), default: run-test's");
  app.add_option("--loading-arc", cl.loading_arc,
                 "Brazilian test: the jaws' loading arc 2 alpha in degrees, 0 to 60 (0: flat platens); default 0 for "
                 "bonded particles (the shipped maps), 30 for the lattice");
  app.add_option("--honour", cl.honour,
                 "strength matched when sigma_c/sigma_t is unreachable: compressive | tensile, default compressive");
  app.add_option("--output", cl.output, "output directory (created), default out/calibration");
  app.add_option("--name", cl.name, "file name prefix, default calibration");
  app.add_flag("--no-pictures", cl.no_pictures, "no PNG pictures (the CSV files are written)");
  app.add_flag("--quiet", cl.quiet, "no progress display");
  if (int status = 0; !ParseCommandLine(app, argc, argv, &status)) return status;
  // An error on one rank of several: the others may wait for it in an exchange, so the job
  // ends with it (each rank's message names its rank).
  auto body = [&]() -> int {
    if (cl.dimension != 2 && cl.dimension != 3)
      throw InputError("--dimension = " + std::to_string(cl.dimension) + ", allowed 2 or 3");
    const TargetMaterial target = LoadTargetMaterial(cl.material);
    // Only the lattice takes an anisotropic D: --model auto picks it for an orthotropic target.
    if (target.orthotropic && cl.model != "lattice" && cl.model != "auto")
      throw InputError(cl.material + ": an orthotropic target (youngs_modulus_1, ...) needs --model lattice (or auto); "
                       "bonded particles are isotropic, not --model " + cl.model);
    if (cl.model == "lattice" || (target.orthotropic && cl.model == "auto")) {
      if (cl.dimension != 2) throw InputError("--model lattice: the six-spring lattice is 2D (--dimension 2)");
      // Settings of the bonded calibration that the lattice has no use for: refused, not ignored.
      for (const char* option : {"--threads", "--sweep-fraction", "--sweep-levels", "--sweep-stiffness-ratio",
                                 "--anchor-levels", "--nu-p", "--friction", "--bond-range", "--max-spectral-radius",
                                 "--honour"})
        if (app.count(option) > 0)
          throw InputError(std::string(option) + " is a setting of the bonded calibration, not of --model lattice");
      if (Distributed())
        throw InputError("--model lattice runs in one process (its rounds are one test pair each): start it "
                         "without mpirun");
      return RunLattice(target, cl);
    }
    if (app.count("--lattice-map") > 0) throw InputError("--lattice-map is a setting of --model lattice");
    CalibrationOptions options;
    if (!ParseCalibrationModel(cl.model, &options.model))
      throw InputError("--model = '" + cl.model + "', allowed rigid, ddem, auto or lattice");
    if (cl.honour != "compressive" && cl.honour != "tensile")
      throw InputError("--honour = '" + cl.honour + "', allowed compressive or tensile");
    options.honour = cl.honour == "tensile" ? HonouredStrength::kTensile : HonouredStrength::kCompressive;
    options.maps_directory = cl.maps_directory.value_or(DefaultMapsDirectory());
    options.maps_file = cl.maps_file;
    options.reuse_maps = !cl.no_reuse;
    options.workers = cl.threads;
    options.max_verification_rounds = cl.rounds.value_or(options.max_verification_rounds);
    options.max_spectral_radius = cl.max_spectral_radius;
    options.particle_poisson_ratio = cl.particle_poisson_ratio;
    options.friction_coefficient = cl.friction;
    options.bond_range = cl.bond_range;
    options.anchor_levels = cl.anchor_levels;
    if (cl.rate_group) options.test.loading_rate_group = *cl.rate_group;
    if (cl.loading_arc) options.test.loading_arc_deg = *cl.loading_arc;
    if (cl.sweep_levels) {
      if (*cl.sweep_levels < 3 || *cl.sweep_levels > 12)
        throw InputError("--sweep-levels = " + std::to_string(*cl.sweep_levels) + ", allowed 3 to 12");
      options.sweep_levels = *cl.sweep_levels;
    }
    if (!cl.sweep_stiffness_ratio.empty()) {
      const double lo = cl.sweep_stiffness_ratio[0], hi = cl.sweep_stiffness_ratio[1];
      if (!(lo > 0.0 && lo < hi && hi <= 1.0))
        throw InputError("--sweep-stiffness-ratio = " + Number(lo) + " " + Number(hi) +
                         ": the kt/kn box, allowed 0 < LO < HI <= 1");
      options.stiffness_ratio_lower = lo;
      options.stiffness_ratio_upper = hi;
    }
    std::string error;
    if (!options.IsValid(&error)) throw InputError(error);
    if (!(cl.sweep_fraction > 0.0 && cl.sweep_fraction <= 1.0))
      throw InputError("--sweep-fraction = " + Number(cl.sweep_fraction) + ", allowed (0, 1]");
    if (cl.count && *cl.count < 1)
      throw InputError("--count = " + std::to_string(*cl.count) + ", allowed >= 1");
    if (cl.seed < 0) throw InputError("--seed = " + std::to_string(cl.seed) + ", allowed >= 0");
    // The design of maps to build: a given map file has its own (refused, not ignored).
    if (!options.maps_file.empty())
      for (const char* option : {"--sweep-levels", "--sweep-stiffness-ratio"})
        if (app.count(option) > 0)
          throw InputError(std::string(option) + " sets the design of maps to build; --maps " + options.maps_file +
                           " uses that file's");
    CheckMapLocations(options.maps_file, options.maps_directory);
    return cl.dimension == 2 ? Run<2>(target, options, cl) : Run<3>(target, options, cl);
  };
  bool failed = true;
  const std::string program = Distributed() ? "calibrate-to-material (rank " + std::to_string(Rank()) + ")"
                                            : "calibrate-to-material";
  const int status = RunCommand(program, [&] {
    const int body_status = body();
    failed = false;
    return body_status;
  }, kOptionNames);
  if (failed) AbortAllRanks(status);
  return status;
}
