// stability-limit: the critical time step and the DDEM convergence bound of a bonded packing
// for a parameter set, certified, and a verdict for a proposed time step (the
// analysis is stability/stability_analysis.h, the parameter file stability/stability_parameters.h).
//
// Sample runs:
//   stability-limit --packing out/packing.packing --kn 7e10 --density 2000
//   stability-limit --packing out/packing.packing --kn 7e10 --kt 3.5e10 --density 2000
//                   --Ep 2e11 --nu-p 0.35 --dt 2.5e-8 --damping 0.1
//   stability-limit --packing out/packing.packing --parameters params.toml --sweep nu_p
//   stability-limit --packing out/packing.packing --kn 7e10 --density 2000 --walls bottom,top
//                   --wall-stiffness 7e11 --damping 0.1 --output out --name ucs
//   stability-limit --packing out/packing.packing --lattice-E 40e9 --lattice-nu 0.25 --density 2650
//                   --dt 2e-8   (the six-spring lattice of a 2D packing)
// (one command per sample, continued on the indented line).
//
// Reads a packing file (generate-packing output) and the parameters (a TOML file and/or the
// options; an option wins over the file). Prints the report: the per-particle bound, the
// certified 2/omega_max of the network (DEM and DDEM), the recommended step, rho(B) of the
// DDEM force iteration and the admissible kn/(Ep l) with the lattice closed forms, and the
// verdict (stable / marginal / unstable, the binding limit and its margin in per cent).
// Writes into --output (default out/): NAME_stability.json and the printed report as
// NAME_stability.txt; with --sweep nu_p also
// NAME_sweep_nu_p.csv and NAME_sweep_nu_p.png (gnuplot). Exit statuses: tools/command_line.h
// (a successful analysis exits 0 whatever the verdict; read it from the JSON). Bad input: a
// message naming the field and its allowed range, exit status 2, and no file written.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <thread>

#include "common/atomic_file.h"
#include "common/plot.h"
#include "common/format.h"
#include "common/progress.h"
#include "generator/packing_io.h"
#include "solver/lattice_packing.h"
#include "solver/lattice_stability.h"
#include "stability/stability_parameters.h"
#include "specimen_version.h"
#include "tools/command_line.h"

namespace specimen {
namespace {

struct CommandLine {
  std::string packing;
  std::string parameters;
  StabilityParameters values;  // from the options; empty fields fall back to the file
  std::string walls;
  std::string sweep;
  std::vector<double> sweep_values;
  // Given: applied as given (a bad value is rejected, never replaced by the default).
  std::optional<double> margin_percent;
  std::optional<double> failure_probability;
  std::optional<double> tolerance_percent;
  int threads = 0;  // 0: every core of the machine
  std::string output = "out";
  std::string name = "packing";
  bool pictures = true;
  bool quiet = false;
  // The six-spring lattice of the packing instead of its bonds (2D): E and nu of the solid.
  std::optional<double> lattice_youngs, lattice_poisson;
};

// The library's field names in the messages, as the options (and file keys) that set them.
const FieldNames kOptionNames = {
    {"normal_stiffness_n_per_m (kn)", "kn (--kn, [material] normal_stiffness)"},
    {"tangential_stiffness_n_per_m (kt)", "kt (--kt, [material] tangential_stiffness)"},
    {"density_kg_per_m3", "density (--density, [material] density)"},
    {"particle_youngs_modulus_pa (Ep)", "Ep (--Ep, [material] particle_youngs_modulus)"},
    {"particle_poisson_ratio (nu_p)", "nu_p (--nu-p, [material] particle_poisson_ratio)"},
    {"translational_damping (alpha_t)", "alpha_t (--damping, [material] translational_damping)"},
    {"rotational_damping (alpha_r)", "alpha_r (--damping, [material] rotational_damping)"},
    {"normal_dashpot_ratio (xi_n)", "xi_n (--dashpot, [material] normal_dashpot_ratio)"},
    {"tangential_dashpot_ratio (xi_t)", "xi_t (--dashpot, [material] tangential_dashpot_ratio)"},
    {"mass_scaling_budget", "the mass scaling budget (--mass-scaling, [material] mass_scaling)"},
    {"bond_radius_ratio (lambda)", "lambda (--bond-radius-ratio, [material] bond_radius_ratio)"},
    {"bond_range (gamma)", "gamma (--bond-range, [material] bond_range)"},
    {"proposed_time_step_s", "the proposed time step (--dt, [time_step] time_step)"},
    {"safety_factor", "safety_factor (--safety, [time_step] safety_factor)"},
    {"time_step_margin", "the time step margin (--margin / 100, [stability] time_step_margin)"},
    {"max_spectral_radius", "max_spectral_radius (--max-rho, [stability] max_spectral_radius)"},
    {"failure_probability", "--failure-probability"},
    {"relative_tolerance", "the Lanczos tolerance (--tolerance / 100)"},
    {"num_threads", "--threads"},
    {"wall_normal_stiffness", "the wall stiffness (--wall-stiffness, [walls] normal_stiffness)"},
    {"wall_tangential_stiffness", "the wall kt (--wall-kt, [walls] tangential_stiffness)"},
    {"wall_friction", "the wall friction (--wall-friction, [walls] friction)"},
};

// --threads 0: the cores the machine leaves idle (cores minus the 1-minute load average, at
// least 1). OpenMP threads spinning at barriers on a machine busy with other work are far
// slower than one thread (measured: 17x on 2 busy cores).
int IdleCores() {
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  double load[1] = {0.0};
  if (getloadavg(load, 1) != 1) return cores;
  return std::clamp(cores - static_cast<int>(std::lround(load[0])), 1, cores);
}

// The nu_p values of --sweep nu_p when --sweep-values is not given.
const std::vector<double> kDefaultSweep = {0.0, 0.05, 0.1, 0.15, 0.2,  0.25,
                                           0.3, 0.35, 0.4, 0.45, 0.49, 0.499};

std::string SweepCsv(const StabilitySummary& summary) {
  std::ostringstream out;
  out.precision(10);
  out << "nu_p,admissible_kn_over_ep,recommended_kn_over_ep,unit_spectral_radius_pa,row,sc,hcp\n";
  for (const SweepRow& r : summary.sweep)
    out << r.poisson_ratio << "," << r.admissible_kn_over_ep << "," << r.recommended_kn_over_ep
        << "," << r.spectral_radius_times_ep_pa << "," << r.lattice.row << "," << r.lattice.square
        << "," << r.lattice.hexagonal << "\n";
  return out.str();
}

std::string SweepPlot(const std::string& csv, const StabilitySummary& summary) {
  const std::string length = summary.dimension == 2 ? "l" : "R_{mean}";
  std::ostringstream gp;
  gp << "set datafile separator ','\n"
     << "set key top right\nset grid\n"
     << "set xlabel 'particle Poisson ratio {/Symbol n}_p'\n"
     << "set ylabel 'admissible k_n/(E_p " << length << ")'\n"
     << "set title 'DDEM convergence limit rho(B) = 1 of the packing (" << summary.particles
     << " particles, " << summary.particle_model << ")'\n"
     << "plot " << GnuplotQuote(csv)
     << " using 1:2 skip 1 with linespoints lw 2 pt 7 title 'this packing, rho(B) = 1', \\\n"
     << "     '' using 1:3 skip 1 with lines dt 2 lw 2 title 'this packing, rho(B) = "
     << summary.max_spectral_radius << "', \\\n"
     << "     '' using 1:5 skip 1 with lines title 'row (Madan 3.27)', \\\n"
     << "     '' using 1:6 skip 1 with lines title 'SC (3.42)'";
  if (summary.dimension == 2) gp << ", \\\n     '' using 1:7 skip 1 with lines title 'HCP (3.78)'";
  gp << "\n";
  return gp.str();
}

template <int Dim>
int Run(const CommandLine& cl, const PackingFile& file) {
  // 1. The parameter set: options over the file, validated before any work.
  StabilityParameters values = cl.values;
  if (!cl.walls.empty()) {
    std::vector<std::string> sides;
    std::stringstream list(cl.walls);
    std::string side;
    while (std::getline(list, side, ',')) sides.push_back(side);
    values.wall_sides = sides;
  }
  if (cl.margin_percent) values.time_step_margin = *cl.margin_percent / 100.0;
  StabilityParameters file_values;
  if (!cl.parameters.empty()) {
    file_values = LoadStabilityParameters(cl.parameters);
    values = MergeStabilityParameters(values, file_values);
  }
  if (!cl.sweep.empty() && cl.sweep != "nu_p")
    throw InputError("--sweep '" + cl.sweep + "' is not allowed: the only sweep is nu_p");
  // Settings that would be silently ignored: say so instead.
  if (cl.sweep.empty() && !cl.sweep_values.empty())
    throw InputError("--sweep-values is given without --sweep nu_p");
  if ((!values.wall_sides || values.wall_sides->empty()) &&
      (values.wall_normal_stiffness_n_per_m || values.wall_tangential_stiffness_n_per_m ||
       values.wall_friction))
    throw InputError("wall stiffness or friction is given (--wall-stiffness, --wall-kt, "
                     "--wall-friction or [walls]) but no wall: give --walls or [walls] sides");
  if (values.particle_poisson_ratio && !values.particle_youngs_modulus_pa)
    throw InputError("nu_p (--nu-p, [material] particle_poisson_ratio) is given without Ep "
                     "(--Ep, [material] particle_youngs_modulus): give both for deformable "
                     "particles (DDEM), neither for rigid ones");
  if (cl.threads < 0)
    throw InputError("--threads = " + std::to_string(cl.threads) +
                     " is not allowed: it must be >= 1 (or 0 for every core)");
  if (Dim == 3 && values.plane_model)
    throw InputError("--plane (or [material] plane_model) is a 2D setting; the packing is 3D");
  const Packing<Dim> packing = ParsePackingFile<Dim>(file);
  CheckPackingGeometry<Dim>(packing, cl.packing);
  SceneOptions<Dim> scene = StabilitySceneOf<Dim>(values, packing);
  scene.num_threads = cl.threads > 0 ? cl.threads : IdleCores();
  StabilityOptions options = StabilityOptionsOf(values);
  if (!cl.parameters.empty()) {
    // The set in use is valid; a bad value in the file is still reported where an option
    // overrides it: the file is checked with its own values first (options only fill what
    // it leaves out).
    const StabilityParameters file_first = MergeStabilityParameters(file_values, values);
    try {
      StabilitySceneOf<Dim>(file_first, packing);
      StabilityOptionsOf(file_first);
    } catch (const InputError& e) {
      throw InputError(cl.parameters + ": " + e.what() + " (overridden on the command line, "
                       "but the file is wrong)");
    }
  }
  if (cl.failure_probability) options.lanczos.failure_probability = *cl.failure_probability;
  if (cl.tolerance_percent) options.lanczos.relative_tolerance = *cl.tolerance_percent / 100.0;
  if (!cl.sweep.empty())
    options.sweep_poisson_ratios = cl.sweep_values.empty() ? kDefaultSweep : cl.sweep_values;
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  if (std::string rule; !IsValidOutputName(cl.name, &rule))
    throw InputError("--name '" + cl.name + "' is not allowed: " + rule);

  // 2. Fail on an unusable output location now, not after the work.
  EnsureDirectory(cl.output, "output directory");
  RequireWritableDirectory(cl.output, "output directory");

  // 3. The analysis, with progress on a terminal.
  TerminalProgress progress(cl.quiet);
  options.progress = progress.Callback();
  const StabilitySummary summary = AnalyseStability<Dim>(packing, scene, options);
  progress.Finish();

  // 4. Files: JSON (and the sweep CSV) together, then the picture from the CSV.
  const std::string base = cl.output + "/" + cl.name;
  nlohmann::json report;
  report["command"] = "stability-limit";
  report["version"] = kVersion;
  report["packing"] = cl.packing;
  report["parameters_file"] = cl.parameters;
  report["analysis"] = summary.ToJson();
  const std::string text = summary.FullReport();
  OutputGroup group;
  group.Add(base + "_stability.json", [&](std::ostream& out) { out << report.dump(2) << "\n"; });
  group.Add(base + "_stability.txt", [&](std::ostream& out) { out << text << "\n"; });
  const std::string csv = base + "_sweep_nu_p.csv";
  if (!summary.sweep.empty()) group.Add(csv, [&](std::ostream& out) { out << SweepCsv(summary); });
  std::vector<std::string> files = group.Commit();
  std::vector<std::string> warnings;
  if (!summary.sweep.empty() && cl.pictures) {
    const std::string png = base + "_sweep_nu_p.png";
    std::string plot_error;
    if (RenderGnuplot(SweepPlot(csv, summary), png, PlotOptions(), &plot_error))
      files.push_back(png);
    else
      warnings.push_back(plot_error);
  }

  // 5. Report.
  std::cout << text << "\nfiles:\n";
  for (const auto& file : files) std::cout << "  " << file << "\n";
  for (const auto& warning : warnings) std::cerr << "warning: " << warning << "\n";
  return kExitOk;
}

// The six-spring lattice of a 2D packing (solver/lattice_packing.h): the certified critical
// step of central differences with its lumped masses, the Gershgorin bound, the closed form
// of the regular lattice at the mean edge length for comparison, and the verdict on --dt.
int RunLattice(const CommandLine& cl, const PackingFile& file) {
  const StabilityParameters& v = cl.values;
  if (!cl.lattice_youngs || !cl.lattice_poisson)
    throw InputError("--lattice-E and --lattice-nu go together (the six-spring lattice's E and nu)");
  if (v.normal_stiffness_n_per_m || v.tangential_stiffness_n_per_m || v.particle_youngs_modulus_pa ||
      v.particle_poisson_ratio || !cl.walls.empty() || !cl.sweep.empty() || !cl.parameters.empty() ||
      v.translational_damping || v.normal_dashpot_ratio || v.mass_scaling_budget ||
      v.bond_radius_ratio || v.bond_range)
    throw InputError("--lattice-E / --lattice-nu analyse the lattice alone: --kn, --kt, --Ep, --nu-p, --walls, "
                     "--sweep, --parameters, --damping, --dashpot, --mass-scaling, --bond-radius-ratio and "
                     "--bond-range are for bonded particles");
  if (!v.density_kg_per_m3) throw InputError("--density is missing (the lattice's lumped masses)");
  const double density = *v.density_kg_per_m3;
  if (!(density > 0.0 && std::isfinite(density)))
    throw InputError("density = " + Number(density) + " (--density) is not allowed: it must be > 0");
  const PlaneModel plane = !v.plane_model || *v.plane_model == "strain" ? PlaneModel::kPlaneStrain
                           : *v.plane_model == "stress"             ? PlaneModel::kPlaneStress
                                                                    : throw InputError("--plane '" + *v.plane_model +
                                                                                       "': use strain or stress");
  const double safety = v.safety_factor.value_or(0.7);
  const double margin = v.time_step_margin.value_or(0.05);
  if (!(safety > 0.0 && safety <= 1.0)) throw InputError("--safety must be in (0, 1]");
  if (!(margin >= 0.0 && margin < 1.0)) throw InputError("--margin must be in [0, 100) per cent");
  if (v.time_step_s && !(*v.time_step_s > 0.0)) throw InputError("--dt must be > 0");
  if (std::string rule; !IsValidOutputName(cl.name, &rule))
    throw InputError("--name '" + cl.name + "' is not allowed: " + rule);
  const PlaneElasticity d = IsotropicPlaneElasticity(*cl.lattice_youngs, *cl.lattice_poisson, plane);
  const Packing<2> packing = ParsePackingFile<2>(file);
  CheckPackingGeometry<2>(packing, cl.packing);
  EnsureDirectory(cl.output, "output directory");

  PackingLatticeSummary built;
  const PackingLattice lattice = BuildPackingLattice(packing, d, 1.0, {}, &built);
  LanczosOptions lanczos;
  if (cl.failure_probability) lanczos.failure_probability = *cl.failure_probability;
  if (cl.tolerance_percent) lanczos.relative_tolerance = *cl.tolerance_percent / 100.0;
  lanczos.num_threads = cl.threads > 0 ? cl.threads : IdleCores();
  std::string error;
  if (!lanczos.IsValid(&error)) throw InputError(error);
  const LatticeStability s =
      AnalyseLatticeStability(lattice.triangles, LumpedMasses(lattice.triangles, lattice.node_count(), density), lanczos);
  double edge = 0.0;
  for (const auto& lengths : lattice.triangles.rest_lengths) edge += (lengths[0] + lengths[1] + lengths[2]) / 3.0;
  edge /= lattice.triangles.size();
  const double regular = RegularLatticeStableTimeStep(*cl.lattice_youngs, *cl.lattice_poisson, plane, density, edge);
  std::string verdict = "not judged (no --dt)";
  if (v.time_step_s) {
    const double ratio = *v.time_step_s / s.critical_time_step_s;
    verdict = ratio > 1.0 ? "unstable" : ratio > 1.0 - margin ? "marginal" : "stable";
  }

  std::ostringstream text;
  text.precision(5);
  text << "stability-limit: six-spring lattice of " << cl.packing << "\n"
       << "  lattice              " << built.Describe() << "\n"
       << "  material             E " << *cl.lattice_youngs << " Pa, nu " << *cl.lattice_poisson << ", "
       << PlaneModelName(plane) << ", density " << density << " kg/m^3\n"
       << "  critical time step   " << s.critical_time_step_s << " s (certified 2/omega_max, Lanczos "
       << s.lanczos.iterations << " steps, failure probability " << s.lanczos.failure_probability << ")\n"
       << "  Gershgorin bound     " << s.gershgorin_time_step_s << " s\n"
       << "  regular lattice      " << regular << " s at the mean edge " << edge << " m (closed form)\n"
       << "  recommended          " << safety * s.critical_time_step_s << " s (safety " << safety << ")\n";
  if (v.time_step_s)
    text << "  proposed             " << *v.time_step_s << " s: " << verdict << " ("
         << 100.0 * (1.0 - *v.time_step_s / s.critical_time_step_s) << " % below the critical step)\n";
  nlohmann::json report = {{"command", "stability-limit"}, {"version", kVersion}, {"packing", cl.packing},
                           {"model", "lattice"},
                           {"lattice", {{"triangles", built.triangles}, {"surface_nodes", built.surface_nodes},
                                        {"free_nodes", built.free_nodes}, {"smallest_angle_deg", built.smallest_angle_deg}}},
                           {"critical_time_step_s", s.critical_time_step_s},
                           {"gershgorin_time_step_s", s.gershgorin_time_step_s},
                           {"regular_lattice_time_step_s", regular}, {"mean_edge_m", edge},
                           {"recommended_time_step_s", safety * s.critical_time_step_s}, {"verdict", verdict}};
  if (v.time_step_s) report["proposed_time_step_s"] = *v.time_step_s;
  const std::string base = cl.output + "/" + cl.name;
  OutputGroup group;
  group.Add(base + "_stability.json", [&](std::ostream& out) { out << report.dump(2) << "\n"; });
  group.Add(base + "_stability.txt", [&](std::ostream& out) { out << text.str(); });
  const std::vector<std::string> files = group.Commit();
  std::cout << text.str() << "\nfiles:\n";
  for (const auto& file : files) std::cout << "  " << file << "\n";
  return kExitOk;
}

}  // namespace
}  // namespace specimen

int main(int argc, char** argv) {
  using namespace specimen;
  CLI::App app{"stability-limit: critical time step and DDEM convergence bound of a packing"};
  CommandLine cl;
  StabilityParameters& v = cl.values;
  app.set_version_flag("--version", std::string(kVersion));
  app.add_option("--packing", cl.packing, "packing file (generate-packing output)")->required();
  app.add_option("--parameters", cl.parameters,
                 "TOML parameter file (stability/stability_parameters.h); options override it");
  auto number = [&](const char* flag, std::optional<double>& field, const char* help) {
    app.add_option_function<double>(
        flag, [&field](double x) { field = x; }, help);
  };
  number("--kn", v.normal_stiffness_n_per_m, "normal contact stiffness kn [N/m] (> 0)");
  number("--kt", v.tangential_stiffness_n_per_m, "tangential contact stiffness kt [N/m] (>= 0)");
  number("--density", v.density_kg_per_m3, "particle density [kg/m^3] (> 0)");
  number("--Ep", v.particle_youngs_modulus_pa, "DDEM particle Young's modulus [Pa]; absent: rigid");
  number("--nu-p", v.particle_poisson_ratio, "DDEM particle Poisson ratio, in (-1, 0.5)");
  app.add_option_function<std::string>(
      "--plane", [&v](const std::string& s) { v.plane_model = s; },
      "2D DDEM particles: strain (default) or stress");
  app.add_option_function<double>(
      "--damping", [&v](double x) { v.translational_damping = v.rotational_damping = x; },
      "local damping alpha_t = alpha_r, in [0, 1)");
  app.add_option_function<double>(
      "--dashpot", [&v](double x) { v.normal_dashpot_ratio = v.tangential_dashpot_ratio = x; },
      "contact dashpot ratio xi_n = xi_t (>= 0)");
  number("--mass-scaling", v.mass_scaling_budget,
         "inertia scaling: share of the total mass that may be added to the particles that "
         "limit the time step, in [0, 0.05] (run-test's mass_scaling)");
  number("--bond-radius-ratio", v.bond_radius_ratio,
         "bonds with a moment: bond radius over the smaller particle radius, in [0, 1] "
         "(0: no moment)");
  number("--bond-range", v.bond_range,
         "interaction range of bonding: pairs within gamma (ri + rj) are bonded too, in [1, 1.5] "
         "(1: the packing's contacts)");
  number("--dt", v.time_step_s, "proposed time step to judge [s] (> 0)");
  number("--safety", v.safety_factor,
         "recommended step = safety x critical, in (0, 1], default 0.9");
  number("--max-rho", v.max_spectral_radius,
         "rho(B) above this is marginal, in (0, 1], default 0.95");
  app.add_option("--margin", cl.margin_percent,
                 "a step within this many per cent of the critical one is marginal, default 5");
  app.add_option("--walls", cl.walls,
                 "fixed walls on the packing's bounding box: comma-separated sides of left, "
                 "right, bottom, top (and back, front in 3D)");
  number("--wall-stiffness", v.wall_normal_stiffness_n_per_m,
         "wall normal stiffness [N/m], default kn");
  number("--wall-kt", v.wall_tangential_stiffness_n_per_m, "wall tangential stiffness [N/m]");
  number("--wall-friction", v.wall_friction, "wall friction coefficient (with --wall-kt)");
  app.add_option("--sweep", cl.sweep, "nu_p: the admissible kn/(Ep l) against nu_p (CSV + PNG)");
  app.add_option("--sweep-values", cl.sweep_values, "the nu_p values of the sweep")->delimiter(',');
  app.add_option("--failure-probability", cl.failure_probability,
                 "probability that a certified bound fails, in (0, 0.1], default 1e-6");
  app.add_option("--tolerance", cl.tolerance_percent,
                 "per cent between the certified bound and the Ritz value of omega_max^2 and "
                 "rho(B), default 0.4");
  app.add_option("--threads", cl.threads, "OpenMP threads for the products, default 0: the idle cores (cores minus the load average)");
  app.add_option("--output", cl.output, "output directory (created), default out");
  app.add_option("--name", cl.name, "file name prefix, default packing");
  app.add_flag(
      "--no-pictures", [&](std::int64_t) { cl.pictures = false; },
      "do not draw the sweep picture (the CSV is still written)");
  app.add_flag("--quiet", cl.quiet, "no progress display");
  app.add_option("--lattice-E", cl.lattice_youngs,
                 "analyse the six-spring lattice of the packing (2D) of this Young's modulus [Pa] instead of its bonds");
  app.add_option("--lattice-nu", cl.lattice_poisson, "the lattice's Poisson ratio (with --lattice-E)");
  if (int status = 0; !ParseCommandLine(app, argc, argv, &status)) return status;
  return RunCommand("stability-limit", [&] {
    const PackingFile file = ReadPackingFile(cl.packing);  // once: it may be a pipe
    if (cl.lattice_youngs || cl.lattice_poisson) {
      if (file.dimension != 2) throw InputError("--lattice-E: the six-spring lattice is 2D; the packing is 3D");
      return RunLattice(cl, file);
    }
    return file.dimension == 2 ? Run<2>(cl, file) : Run<3>(cl, file);
  }, kOptionNames);
}
