// run-test: one virtual laboratory test (UCS, Brazilian, confined biaxial with its
// Mohr-Coulomb envelope, isotropic compression, pure shear) from a scene file: the user's way
// to try a parameter set, and the same library call the calibrator makes (lab/lab_test.h).
//
// Sample runs:
//   run-test data/scenes/example_ucs_2d.toml --output out/ucs
//   run-test data/scenes/example_bts_2d.toml --output out/bts --no-quasi-static-check
//   run-test data/scenes/example_biaxial_2d.toml --output out/biaxial --quiet
//   run-test data/scenes/example_ucs_3d.toml --threads 2 --name cylinder
//   run-test data/scenes/example_lattice_ucs_2d.toml --output out/lattice   # six-spring lattice
//
// The scene (lab/lab_scene_file.h) names a packing file or a domain to generate, the
// material, the test and its options. Everything is checked before any work (a bad value,
// a Brazilian test on a rectangle, an output directory that cannot be written). The command
// prints the test's report and writes into --output (default out/): <name>_curve.csv,
// <name>_bonds.csv, <name>_summary.json, <name>_stress_strain.png, in 2D <name>_cracks.png,
// and <name>_peak.vtu / <name>_end.vtu (lab/lab_outputs.h). Exit status: 0 success,
// 2 bad input (nothing written), 3 file error, 4 computation failure - including a strength
// test that reached its strain limit without a peak (its files are written, for diagnosis).

#include <CLI/CLI.hpp>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "common/progress.h"
#include "generator/generate.h"
#include "generator/packing_io.h"
#include "lab/lab_envelope.h"
#include "lab/lab_outputs.h"
#include "lab/lab_scene_file.h"
#include "lab/lattice_lab_test.h"
#include "lab/lab_specimen.h"
#include "specimen_version.h"
#include "tools/command_line.h"

namespace specimen {
namespace {

struct CommandLine {
  std::string scene;
  std::string output = "out";
  std::optional<std::string> name;  // given: replaces the scene's [output] name
  std::optional<int> threads;       // given: replaces the scene's [test] threads
  bool no_pictures = false;
  bool no_snapshots = false;
  bool no_quasi_static_check = false;
  bool quiet = false;
};

template <int Dim>
Packing<Dim> SceneSpecimen(const LabScene& scene, const PackingFile* file, bool quiet) {
  if (file) {
    Packing<Dim> packing = ParsePackingFile<Dim>(*file);
    CheckPackingGeometry<Dim>(packing, scene.packing_path);
    return packing;
  }
  GeneratorOptions options = DefaultGeneratorOptions<Dim>();
  options.particle_count = scene.particle_count;
  options.mean_radius = scene.mean_radius_m;
  options.seed = scene.seed;
  std::string error;
  if (!options.IsValid(&error)) throw InputError(scene.source + " [specimen]: " + error);
  TerminalProgress progress(quiet);
  options.progress = progress.Callback();
  GeneratorSummary summary;
  Packing<Dim> packing = GeneratePacking<Dim>(Domain<Dim>::Parse(scene.domain), options, &summary);
  progress.Finish();
  if (!quiet) std::cout << summary.BriefReport() << "\n";
  return packing;
}

template <int Dim>
int Run(LabScene scene, const PackingFile* file, const CommandLine& cl) {
  // 1. The command line overrides the scene's output and run settings.
  scene.output.directory = cl.output;
  if (cl.name) scene.output.name = *cl.name;  // an empty name is rejected below
  if (cl.threads) scene.test.num_threads = *cl.threads;
  if (cl.no_pictures) scene.output.pictures = false;
  if (cl.no_snapshots) scene.output.snapshots = false;
  if (cl.no_quasi_static_check) scene.test.check_quasi_static = false;
  scene.test.record_snapshots = scene.output.pictures || scene.output.snapshots;
  std::string error;
  if (!scene.test.IsValid(&error))
    throw InputError(InUserTerms(error, {{"num_threads", "--threads (or [test] threads)"}}));

  // 2. The specimen, checked against the test before the run; then the output location.
  const Packing<Dim> packing = SceneSpecimen<Dim>(scene, file, cl.quiet);
  if (scene.lattice && Dim != 2) throw InputError(scene.source + ": the lattice model is 2D; the specimen is 3D");
  if (scene.plane_model_given && Dim == 3)
    throw InputError(scene.source + " [material]: plane_model is a 2D setting; the specimen is 3D");
  DescribeSpecimen<Dim>(packing, scene.test.kind, scene.test.strain_boundary_margin);
  CheckLabOutputLocation(scene.output);

  // 3. The test (or the envelope), with progress on a terminal.
  TerminalProgress progress(cl.quiet);
  scene.test.progress = progress.Callback();
  nlohmann::json report;
  report["command"] = "run-test";
  report["scene"] = scene.source;
  report["specimen"] = scene.packing_path.empty() ? "generated: " + scene.domain : scene.packing_path;
  LabOutputsWritten written;
  bool missing_peak = false;
  std::string missing_message;
  if (!scene.confining_stresses_pa.empty()) {
    const ConfinedEnvelope envelope =
        RunConfinedEnvelope<Dim>(packing, scene.material, scene.test, scene.confining_stresses_pa);
    progress.Finish();
    written = WriteEnvelopeOutputs<Dim>(envelope, packing, report, scene.output);
    for (const LabTestResult& t : envelope.tests) std::cout << t.BriefReport() << "\n";
    std::cout << envelope.FullReport();
    for (const LabTestResult& t : envelope.tests)
      if (!t.peak_reached) {
        missing_peak = true;
        missing_message = t.termination_message;
      }
  } else {
    LabTestResult result;
    if constexpr (Dim == 2) {
      result = scene.lattice ? RunLatticeLabTest(packing, scene.lattice_material, scene.test, scene.lattice_protocol)
                             : RunLabTest<Dim>(packing, scene.material, scene.test);
    } else {
      if (scene.lattice) throw InputError(scene.source + ": the lattice model is 2D; the specimen is 3D");
      result = RunLabTest<Dim>(packing, scene.material, scene.test);
    }
    progress.Finish();
    written = WriteLabOutputs<Dim>(result, packing, report, scene.output);
    std::cout << result.FullReport() << "\n" << result.BriefReport() << "\n";
    missing_peak = IsStrengthTest(result.kind) && !result.peak_reached;
    missing_message = result.termination_message;
  }

  // 4. Files, warnings, and the verdict on a missing peak.
  std::cout << "files:\n";
  for (const auto& file : written.files) std::cout << "  " << file << "\n";
  for (const auto& warning : written.warnings) std::cerr << "warning: " << warning << "\n";
  if (missing_peak) {
    std::cerr << "run-test: error: the test " << missing_message << "\n";
    return kExitComputation;
  }
  return kExitOk;
}

}  // namespace
}  // namespace specimen

int main(int argc, char** argv) {
  using namespace specimen;
  CLI::App app{"run-test: one virtual laboratory test (UCS, Brazilian, biaxial, isotropic, shear) "
               "from a scene file"};
  CommandLine cl;
  app.set_version_flag("--version", std::string(kVersion));
  app.add_option("scene", cl.scene, "the scene file (TOML; see data/scenes/)")->required();
  app.add_option("--output", cl.output, "output directory (created), default out");
  app.add_option("--name", cl.name, "file name prefix, default [output] name or the scene's name");
  app.add_option("--threads", cl.threads, "threads of the solver (overrides [test] threads)");
  app.add_flag("--no-pictures", cl.no_pictures, "no PNG pictures (the CSV files are written)");
  app.add_flag("--no-snapshots", cl.no_snapshots, "no VTU snapshots");
  app.add_flag("--no-quasi-static-check", cl.no_quasi_static_check,
               "skip the half-rate repeat of the quasi-static check");
  app.add_flag("--quiet", cl.quiet, "no progress display");
  if (int status = 0; !ParseCommandLine(app, argc, argv, &status)) return status;
  return RunCommand("run-test", [&] {
    LabScene scene = LoadLabScene(cl.scene);
    std::optional<PackingFile> file;  // read once: it may be a pipe
    if (!scene.packing_path.empty()) file = ReadPackingFile(scene.packing_path);
    if (scene.dimension == 0) scene.dimension = file->dimension;
    const PackingFile* packing = file ? &*file : nullptr;
    return scene.dimension == 2 ? Run<2>(scene, packing, cl) : Run<3>(scene, packing, cl);
  }, SceneKeyNames());
}
