// export-specimen: a packing with its bonds, and optionally calibrated contact parameters, as a
// specimen another DEM code runs (lab/yade_export.h, lab/esys_export.h; docs/exports.md,
// "Yade: the bonded specimen", "ESyS-Particle: the bonded specimen").
//
// Sample runs:
//   export-specimen out/ucs/packing.packing --to yade --parameters out/cal/calibration_parameters.toml
//   export-specimen specimen.packing --to esys --output specimen_esys.py
//   yade -x -n specimen_yade.py --run at-rest
//   mpirun -np 2 esysparticle specimen_esys.py --run at-rest
//   export-specimen specimen.packing --to lammps --disc-thickness 0.01   (liggghts likewise; no bonds)
//
// Writes atomically (default: the packing's path with `.packing` replaced by `_yade.py`, or
// `_esys.py` and `_esys.geo`, `_lammps.in` and `_lammps.data`, `_liggghts.in` and `_liggghts.data`). Bad input (an option or a parameter out of range, a material the
// target's law cannot carry): a message naming it and its range, exit status 2, no file
// written; an unreadable packing or parameter file, or an output that cannot be written: status 3.

#include <CLI/CLI.hpp>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>

#include "generator/exports.h"
#include "generator/packing_io.h"
#include "lab/lab_scene_file.h"
#include "lab/esys_export.h"
#include "lab/yade_export.h"
#include "specimen_version.h"
#include "tools/command_line.h"

namespace specimen {
namespace {

struct CommandLine {
  std::string packing;
  std::string target;
  std::string parameters;
  std::string output;
  std::optional<double> bond_gap_tolerance;
  double disc_thickness = 1.0;
  bool quiet = false;
};

// The default output: next to the packing, `<stem>_<suffix>`.
std::string DefaultOutput(const std::string& packing, const std::string& suffix) {
  std::filesystem::path path(packing);
  return (path.parent_path() / (path.stem().string() + suffix)).string();
}

std::string OutputFile(const CommandLine& cl, const std::string& suffix) {
  const std::string output = cl.output.empty() ? DefaultOutput(cl.packing, suffix) : cl.output;
  if (std::filesystem::is_directory(output))
    throw FileError("--output '" + output + "' is a directory: give the script's file name");
  return output;
}

// The options every bonded export takes from the command line.
template <typename Options>
Options BondedExportOptions(const CommandLine& cl) {
  Options options;
  options.packing_source = cl.packing;
  if (cl.bond_gap_tolerance) options.bond_gap_tolerance = *cl.bond_gap_tolerance;
  if (!cl.parameters.empty()) options.material = LoadMaterialFile(cl.parameters);
  options.parameters_source = cl.parameters;
  return options;
}

template <int Dim>
void ExportYade(const CommandLine& cl, const Packing<Dim>& packing) {
  const YadeExportOptions options = BondedExportOptions<YadeExportOptions>(cl);
  const std::string output = OutputFile(cl, "_yade.py");
  SaveYadeScript<Dim>(packing, options, output);
  if (!cl.quiet) {
    std::cout << "Yade script: " << output << " (" << packing.size() << " particles, "
              << ExportedBonds(packing, options.bond_gap_tolerance).size() << " bonds"
              << (options.material ? "" : "; no parameters: set KN ... DENSITY in the file") << ")\n"
              << "run: yade -x -n " << output << " --run at-rest\n";
  }
}

template <int Dim>
void ExportEsys(const CommandLine& cl, const Packing<Dim>& packing) {
  const EsysExportOptions options = BondedExportOptions<EsysExportOptions>(cl);
  const std::string script = OutputFile(cl, "_esys.py");
  const std::filesystem::path script_path(script);
  const std::string geometry = (script_path.parent_path() / (script_path.stem().string() + ".geo")).string();
  SaveEsysSpecimen<Dim>(packing, options, script, geometry);
  if (!cl.quiet) {
    std::cout << "ESyS-Particle script: " << script << ", geometry: " << geometry << " (" << packing.size()
              << " particles, " << ExportedBonds(packing, options.bond_gap_tolerance).size() << " bonds"
              << (options.material ? "" : "; no parameters: set KN ... DENSITY in the script") << ")\n"
              << "run: mpirun -np 2 esysparticle " << script << " --run at-rest\n";
  }
}

// LAMMPS or LIGGGHTS: the data file with this toolkit's masses and the input that loads it.
template <int Dim>
void ExportGranular(const CommandLine& cl, const Packing<Dim>& packing) {
  const GranularCode code = cl.target == "lammps" ? GranularCode::kLammps : GranularCode::kLiggghts;
  if (!(cl.disc_thickness > 0.0) || !std::isfinite(cl.disc_thickness))
    throw InputError("--disc-thickness = " + Number(cl.disc_thickness) + " is not allowed: it must be > 0 [m]");
  const double density = cl.parameters.empty() ? 2650.0 : LoadMaterialFile(cl.parameters).density_kg_per_m3;
  const std::string input = OutputFile(cl, "_" + cl.target + ".in");
  const std::filesystem::path input_path(input);
  const std::string data = (input_path.parent_path() / (input_path.stem().string() + ".data")).string();
  SaveGranularSpecimen<Dim>(packing, code, density, cl.disc_thickness, input, data);
  if (!cl.quiet) {
    std::cout << GranularCodeName(code) << " input: " << input << ", data: " << data << " (" << packing.size()
              << " particles, density " << Number(density) << " kg/m^3"
              << (Dim == 2 ? ", discs of thickness " + Number(cl.disc_thickness) + " m" : std::string()) << "; no bonds)\n"
              << "run: " << (code == GranularCode::kLammps ? "lmp" : "liggghts") << " -in " << input
              << " (from its directory)\n";
  }
}

template <int Dim>
int Run(const CommandLine& cl, const PackingFile& file) {
  const Packing<Dim> packing = ParsePackingFile<Dim>(file);
  CheckPackingGeometry<Dim>(packing, cl.packing);
  if (cl.target == "yade")
    ExportYade<Dim>(cl, packing);
  else if (cl.target == "esys")
    ExportEsys<Dim>(cl, packing);
  else
    ExportGranular<Dim>(cl, packing);
  return kExitOk;
}

}  // namespace
}  // namespace specimen

int main(int argc, char** argv) {
  using namespace specimen;
  CLI::App app{"export-specimen: a bonded packing (and its contact parameters) for another DEM code"};
  CommandLine cl;
  app.set_version_flag("--version", std::string(kVersion));
  app.add_option("packing", cl.packing, "the packing file (generate-packing, calibrate-to-material)")->required();
  app.add_option("--to", cl.target, "the target code: yade (a Python script for yade -x), esys (an ESyS-Particle geometry and script), lammps or "
                 "liggghts (a data file with this toolkit's masses and its input script; no bonds)")->required();
  app.add_option("--parameters", cl.parameters,
                 "calibrate-to-material's _parameters.toml (a [material] table of rigid bonded particles): "
                 "kn, kt, Rn, Rt, mu and the density of every bond; without it the script leaves them to set");
  app.add_option("--output", cl.output, "the script to write; default: the packing's name with _yade.py, _esys.py, _lammps.in or _liggghts.in (the "
                 "geometry or data file beside it, .geo or .data)");
  app.add_option("--bond-gap-tolerance", cl.bond_gap_tolerance,
                 "a listed pair is a bond when |gap| <= this x (ri + rj)/2, in [0, 1]; default 0.05 (run-test's)");
  app.add_option("--disc-thickness", cl.disc_thickness,
                 "lammps, liggghts, 2D: the thickness t of the discs [m], mass rho pi r^2 t; default 1 (per metre, "
                 "as this toolkit)");
  app.add_flag("--quiet", cl.quiet, "print nothing on success");
  if (int status = 0; !ParseCommandLine(app, argc, argv, &status)) return status;
  return RunCommand("export-specimen", [&] {
    if (cl.target != "yade" && cl.target != "esys" && cl.target != "lammps" && cl.target != "liggghts")
      throw InputError("--to = '" + cl.target + "' is not allowed: use yade, esys, lammps or liggghts");
    const PackingFile file = ReadPackingFile(cl.packing);
    return file.dimension == 2 ? Run<2>(cl, file) : Run<3>(cl, file);
  });
}
