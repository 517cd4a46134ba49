#include "calibrate/calibration_outputs.h"

#include <algorithm>
#include <cstdio>
#include <ostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "calibrate/map_sweep.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/plot.h"
#include "common/ranks.h"
#include "common/unit_names.h"
#include "generator/packing_io.h"
#include "lab/lab_outputs.h"
#include "specimen_version.h"

namespace specimen {
namespace {

std::string Exact(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}

std::string FileName(const std::string& path) {
  const size_t slash = path.rfind('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// A run-test scene (lab/lab_scene_file.h) of one verification test; `what` says which.
void WriteScene(std::ostream& out, const std::string& packing_file, const MaterialParameters& material,
                const LabTestOptions& test, const char* kind, const std::string& name, int dimension,
                const std::string& what = "with the calibrated parameters") {
  out << "# Written by calibrate-to-material " << kVersion << ": the verification " << kind << " test " << what
      << ".\n# Rerun: run-test " << name << "_scene.toml --output DIR\n\n";
  out << "[specimen]\npacking = \"" << packing_file << "\"\nscale_density = " << (test.scale_density ? "true" : "false")
      << "\n\n";
  out << MaterialTomlTable(material, dimension) << "\n";
  out << "[test]\nkind = \"" << kind << "\"\n";
  // As the calibration ran it: a test peaking after run-test's automatic limit would read "no peak".
  out << "strain_limit = " << Exact(StrengthTestProtocol(test).strain_limit) << "\n";
  out << "loading_rate_group = " << Exact(test.loading_rate_group) << "\n";
  if (test.platen_speed_m_per_s > 0) out << "platen_speed = " << Exact(test.platen_speed_m_per_s) << "\n";
  out << "post_peak_fraction = " << Exact(test.post_peak_stress_fraction) << "\n";
  out << "modulus_window = [" << Exact(test.modulus_window_low) << ", " << Exact(test.modulus_window_high) << "]\n";
  out << "local_damping = " << Exact(test.local_damping) << "\n";
  out << "dashpot_ratio = " << Exact(test.dashpot_ratio) << "\n";
  out << "mass_scaling = " << Exact(test.mass_scaling_budget) << "\n";
  out << "safety_factor = " << Exact(test.time_step_safety_factor) << "\n";
  out << "pause_kinetic_energy_ratio = " << Exact(test.pause_kinetic_energy_ratio) << "\n";
  out << "platen_stiffness_ratio = " << Exact(test.platen_stiffness_ratio) << "\n";
  out << "platen_friction = " << Exact(test.platen_friction) << "\n";
  if (std::string(kind) == "brazilian" && test.loading_arc_deg > 0.0)
    out << "loading_arc = " << Exact(test.loading_arc_deg) << "\n";
  out << "\n";
  out << "[output]\nname = \"" << name << "\"\n";
}

void WriteSweepCsv(const StoredMaps& maps, std::ostream& out) {
  out << "index,kt_over_kn,rt_over_rn,friction,kn_over_ep_l,particle_poisson_ratio,ok,youngs_modulus_pa,"
         "poisson_ratio,ucs_pa,tensile_strength_pa,strength_ratio,elastic_group,compressive_group,"
         "tensile_group,wall_time_s\n";
  for (const SweepPoint& p : maps.points) {
    const MicroRatios& r = p.ratios;
    out << p.index << "," << r.tangential_to_normal_stiffness << "," << r.shear_to_tensile_strength << ","
        << r.friction_coefficient << "," << r.normal_stiffness_to_particle << "," << r.particle_poisson_ratio << ","
        << (p.ok ? 1 : 0) << "," << p.youngs_modulus_pa << "," << p.poisson_ratio << "," << p.ucs_pa << ","
        << p.tensile_strength_pa << "," << (p.ok ? p.ucs_pa / p.tensile_strength_pa : 0.0) << ","
        << p.elastic_group << "," << p.compressive_group << "," << p.tensile_group << "," << p.seconds << "\n";
  }
}

// The surfaces along each axis through the chosen point: axis, value, nu, Psi_E, Psi_c,
// Psi_t, Psi_c/Psi_t.
void WriteCurvesCsv(const StoredMaps& stored, const MicroRatios& chosen, std::ostream& out) {
  const MapSet& maps = stored.maps;
  out << "axis,value,poisson_ratio,elastic_group,compressive_group,tensile_group,strength_ratio\n";
  const std::vector<double> x0 = maps.InputsOf(chosen);
  for (size_t k = 0; k < maps.inputs.size(); ++k) {
    const double lo = maps.Lower()[k], hi = maps.Upper()[k];
    for (int i = 0; i <= 60; ++i) {
      Eigen::VectorXd x = Eigen::VectorXd::Map(x0.data(), static_cast<Eigen::Index>(x0.size()));
      x[k] = lo + (hi - lo) * i / 60.0;
      const double c = maps.compressive_group.Evaluate(x), t = maps.tensile_group.Evaluate(x);
      out << k << "," << x[k] << "," << maps.poisson_ratio.Evaluate(x) << "," << maps.elastic_group.Evaluate(x)
          << "," << c << "," << t << "," << (t != 0 ? c / t : 0.0) << "\n";
    }
  }
}

// Column of a ratio in the sweep CSV (1-based, gnuplot).
int SweepColumn(MicroRatio ratio) {
  switch (ratio) {
    case MicroRatio::kStiffnessRatio: return 2;
    case MicroRatio::kStrengthRatio: return 3;
    case MicroRatio::kFriction: return 4;
    case MicroRatio::kParticleCompliance: return 5;
    case MicroRatio::kParticlePoisson: return 6;
  }
  return 2;
}

std::string MapsScript(const StoredMaps& stored, const MicroRatios& chosen,
                       const std::string& sweep_csv, const std::string& curves_csv) {
  const MapSet& maps = stored.maps;
  const int first = 0, last = static_cast<int>(maps.inputs.size()) - 1;
  int stiffness_axis = first, strength_axis = last;
  for (int k = 0; k <= last; ++k) {
    if (maps.inputs[k] == MicroRatio::kStiffnessRatio) stiffness_axis = k;
    if (maps.inputs[k] == MicroRatio::kStrengthRatio) strength_axis = k;
  }
  const std::vector<double> x0 = maps.InputsOf(chosen);
  const Eigen::VectorXd x = Eigen::VectorXd::Map(x0.data(), static_cast<Eigen::Index>(x0.size()));
  const double nu = maps.poisson_ratio.Evaluate(x), psi_e = maps.elastic_group.Evaluate(x);
  const double psi_c = maps.compressive_group.Evaluate(x), psi_t = maps.tensile_group.Evaluate(x);
  const std::string a = MicroRatioName(maps.inputs[stiffness_axis]);
  const std::string b = MicroRatioName(maps.inputs[strength_axis]);
  const int ca = SweepColumn(maps.inputs[stiffness_axis]), cb = SweepColumn(maps.inputs[strength_axis]);
  std::ostringstream s;
  s << "set datafile separator ','\nset key top right font ',9'\nset grid\n";
  s << "set multiplot layout 2,2 title 'Micro-macro maps: sweep points, fitted surface through the chosen point (red)'\n";
  auto panel = [&](const std::string& xlabel, const std::string& ylabel, int xcol, const std::string& ycol, int axis,
                   const std::string& curve_col, double cx, double cy) {
    s << "set xlabel '" << xlabel << "'\nset ylabel '" << ylabel << "'\n";
    s << "plot " << GnuplotQuote(sweep_csv) << " every ::1 using " << xcol << ":(($7)>0 ? " << ycol
      << " : 1/0) with points pt 7 ps 0.8 lc rgb '#4060a0' title 'sweep points', "
      << GnuplotQuote(curves_csv) << " every ::1 using ($1==" << axis << " ? $2 : 1/0):" << curve_col
      << " with lines lw 2 lc rgb '#202020' title 'fitted surface', "
      << "'-' using 1:2 with points pt 9 ps 2.5 lc rgb '#d02020' title 'chosen'\n"
      << Exact(cx) << "," << Exact(cy) << "\ne\n";
  };
  panel(a, "nu (2D: plane strain)", ca, "$9", stiffness_axis, "3", x[stiffness_axis], nu);
  panel(a, "Psi_E = E r~ / (kn nc (1-e))", ca, "$13", stiffness_axis, "4", x[stiffness_axis], psi_e);
  panel(b, "sigma_c / sigma_t", cb, "$12", strength_axis, "7", x[strength_axis], psi_c / psi_t);
  panel(b, "Psi_c = sigma_c A~ / (Rn nc (1-e))", cb, "$14", strength_axis, "5", x[strength_axis], psi_c);
  s << "unset multiplot\n";
  return s.str();
}

// A text field of a CSV row, quoted (messages hold commas: "step 184,886").
std::string CsvText(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

// Every round; a failed one leaves its measured fields empty (gnuplot skips them) and says
// why in the last column.
void WriteVerificationCsv(const CalibrationSummary& summary, std::ostream& out) {
  const int dim = summary.dimension;
  out << "round,best,accepted," << PerThickness("kn_n_per_m", dim) << ',' << PerThickness("kt_n_per_m", dim) << ','
      << PerThickness("rn_n", dim) << ',' << PerThickness("rt_n", dim)
      << ",friction,particle_youngs_modulus_pa,particle_poisson_ratio,youngs_modulus_pa,"
         "poisson_ratio,ucs_pa,tensile_strength_pa,predicted_ucs_pa,predicted_tensile_strength_pa,error_youngs,"
         "error_poisson,error_ucs,error_tensile,wall_time_s,failed,failure\n";
  for (const VerificationRound& v : summary.rounds) {
    const MaterialParameters& m = v.material;
    auto measured = [&](double value) {
      std::ostringstream field;
      if (!v.failed) field << value;
      return field.str();
    };
    out << v.round << "," << (v.round == summary.best_round ? 1 : 0) << "," << (v.accepted ? 1 : 0) << ","
        << Exact(m.normal_stiffness_n_per_m) << "," << Exact(m.tangential_stiffness_n_per_m) << ","
        << Exact(m.bond_tensile_strength_n) << "," << Exact(m.bond_shear_strength_n) << ","
        << Exact(m.friction_coefficient) << ","
        << (m.particle_youngs_modulus_pa ? Exact(*m.particle_youngs_modulus_pa) : "")  // empty: rigid particles
        << "," << m.particle_poisson_ratio << "," << v.youngs_modulus_pa << "," << v.poisson_ratio << ","
        << measured(v.ucs_pa) << "," << measured(v.tensile_strength_pa) << "," << v.predicted_ucs_pa << ","
        << v.predicted_tensile_strength_pa << "," << v.error_youngs << "," << v.error_poisson << ","
        << measured(v.error_ucs) << "," << measured(v.error_tensile) << "," << v.seconds << ","
        << (v.failed ? 1 : 0) << "," << CsvText(v.failure) << "\n";
  }
}

void WriteElasticRunsCsv(const CalibrationSummary& summary, std::ostream& out) {
  out << "run,purpose,kt_over_kn,kn_over_ep_l,particle_poisson_ratio," << PerThickness("kn_n_per_m", summary.dimension)
      << ",youngs_modulus_pa,poisson_ratio,wall_time_s\n";
  int k = 0;
  for (const ElasticRun& r : summary.solution.elastic_runs)
    out << ++k << "," << r.purpose << "," << r.query.ratios.tangential_to_normal_stiffness << ","
        << r.query.ratios.normal_stiffness_to_particle << "," << r.query.ratios.particle_poisson_ratio << ","
        << Exact(r.query.normal_stiffness) << "," << r.measured.youngs_modulus_pa << "," << r.measured.poisson_ratio
        << "," << r.measured.seconds << "\n";
}

// The reach region of the model used: nu and the interval of sigma_c / sigma_t at each
// elastic set of the box (calibration_solver.h ReachSample), from the corrected surfaces.
void WriteReachCsv(const CalibrationSummary& summary, std::ostream& out) {
  out << "model,kt_over_kn,kn_over_ep_l,poisson_ratio,strength_ratio_min,strength_ratio_max\n";
  for (const CalibrationReach* reach : {&summary.rigid_reach, &summary.deformable_reach}) {
    if (!reach->assessed) continue;
    for (const ReachSample& r : reach->region)
      out << (reach->deformable ? "ddem" : "rigid") << "," << r.stiffness_ratio << "," << r.particle_compliance << ","
          << r.poisson_ratio << "," << r.strength_ratio_min << "," << r.strength_ratio_max << "\n";
  }
}

// The reach region of each model assessed: at each elastic set of the box, the nu it gives
// and the interval of sigma_c / sigma_t over Rt/Rn (a vertical segment), with the target.
std::string ReachScript(const CalibrationSummary& summary, const std::string& reach_csv) {
  std::ostringstream s;
  const std::string f = GnuplotQuote(reach_csv);
  s << "set datafile separator ','\nset key top left\nset grid\nset logscale y\n";
  s << "set title 'Reach on this specimen: nu (measured at the corners) and sigma_c / sigma_t (corrected maps)'\n";
  s << "set xlabel 'nu" << (summary.dimension == 2 ? " (plane strain)" : "") << "'\nset ylabel 'sigma_c / sigma_t'\n";
  s << "plot " << f << " every ::1 using ((strcol(1) eq 'rigid') ? $4 : 1/0):5:(0):($6-$5) with vectors nohead lw 3 "
    << "lc rgb '#4060a0' title 'rigid particles', " << f
    << " every ::1 using ((strcol(1) eq 'ddem') ? $4 : 1/0):5:(0):($6-$5) with vectors nohead lw 2 "
    << "lc rgb '#d08020' title 'DDEM', "
    << "'-' using 1:2 with points pt 3 ps 3 lw 2 lc rgb '#d02020' title 'target'\n"
    << Exact(summary.target.poisson_ratio) << "," << Exact(summary.target.StrengthRatio()) << "\ne\n";
  return s.str();
}

// The error of every property against the strength round (E, nu: the round's elastic set).
std::string ConvergenceScript(const CalibrationSummary& summary, const CalibrationOptions& options,
                              const std::string& verification_csv) {
  std::ostringstream s;
  s << "set datafile separator ','\nset key top right\nset grid\n";
  s << "set title 'Calibration to " << summary.target.name << ": error against the strength round'\n";
  s << "set xlabel 'strength round'\nset ylabel 'error [%]'\nset xtics 1\n";
  s << "set yrange [*:*]\n";
  const std::string f = GnuplotQuote(verification_csv);
  s << "plot " << f << " every ::1 using 1:(100*$17) with linespoints lw 2 pt 7 title 'E', " << f
    << " every ::1 using 1:(100*$18) with linespoints lw 2 pt 5 title 'nu', " << f
    << " every ::1 using 1:(100*$19) with linespoints lw 2 pt 9 title 'UCS', " << f
    << " every ::1 using 1:(100*$20) with linespoints lw 2 pt 11 title 'sigma_t', "
    << 100 * options.tolerance_ucs << " with lines dt 2 lc rgb '#808080' title 'UCS tolerance', "
    << -100 * options.tolerance_ucs << " with lines dt 2 lc rgb '#808080' notitle, "
    << 100 * options.tolerance_tensile << " with lines dt 3 lc rgb '#a0a0a0' title 'sigma_t tolerance', "
    << -100 * options.tolerance_tensile << " with lines dt 3 lc rgb '#a0a0a0' notitle\n";
  return s.str();
}

}  // namespace

namespace {

// One final verification test's files, as run-test writes them.
template <int Dim>
void WriteFinalTestOutputs(const LabTestResult& result, const Packing<Dim>& specimen, const std::string& suffix,
                           const CalibrationOutputOptions& output, CalibrationOutputsWritten* written) {
  LabOutputOptions lab;
  lab.directory = output.directory;
  lab.name = output.name + suffix;
  lab.pictures = output.pictures;
  lab.snapshots = true;
  const nlohmann::json report = {{"calibration", output.name + "_report.json"}};
  const LabOutputsWritten w = WriteLabOutputs<Dim>(result, specimen, report, lab);
  written->files.insert(written->files.end(), w.files.begin(), w.files.end());
  written->warnings.insert(written->warnings.end(), w.warnings.begin(), w.warnings.end());
}

}  // namespace

void CheckCalibrationOutputLocation(const CalibrationOutputOptions& options) {
  if (std::string rule; !IsValidOutputName(options.name, &rule))
    throw InputError("output name '" + options.name + "' is not allowed: " + rule);
  EnsureDirectory(options.directory, "output directory");
  RequireWritableDirectory(options.directory, "output directory");
}

std::string MaterialTomlTable(const MaterialParameters& m, int dimension) {
  std::ostringstream out;
  out << "[material]\n";
  out << "normal_stiffness = " << Exact(m.normal_stiffness_n_per_m) << "        # kn [N/m]\n";
  out << "tangential_stiffness = " << Exact(m.tangential_stiffness_n_per_m) << "    # kt [N/m]\n";
  out << "bond_tensile_strength = " << Exact(m.bond_tensile_strength_n) << "   # Rn [N]\n";
  out << "bond_shear_strength = " << Exact(m.bond_shear_strength_n) << "     # Rt [N]\n";
  out << "friction_coefficient = " << Exact(m.friction_coefficient) << "\n";
  if (m.bond_range != 1.0)
    out << "bond_range = " << Exact(m.bond_range) << "              # gamma: bonds within gamma (ri + rj)\n";
  out << "density = " << Exact(m.density_kg_per_m3) << "                   # [kg/m^3], before scaling\n";
  if (m.particle_youngs_modulus_pa) {
    out << "particle_youngs_modulus = " << Exact(*m.particle_youngs_modulus_pa) << "   # Ep [Pa] (DDEM)\n";
    out << "particle_poisson_ratio = " << Exact(m.particle_poisson_ratio) << "\n";
    if (dimension == 2)  // a 2D setting: refused with a 3D specimen
      out << "plane_model = \"" << (m.plane_model == PlaneModel::kPlaneStrain ? "plane_strain" : "plane_stress")
          << "\"\n";
  }
  return out.str();
}

template <int Dim>
CalibrationOutputsWritten WriteCalibrationOutputs(const CalibrationSummary& summary,
                                                  const CalibrationSpecimens<Dim>& specimens,
                                                  const CalibrationOptions& options,
                                                  const CalibrationOutputOptions& output) {
  CheckCalibrationOutputLocation(output);
  CalibrationOutputsWritten written;
  const std::string base = output.directory + "/" + output.name;
  const std::string text_report = summary.FullReport();
  const nlohmann::json json_report = summary.ToJson();

  // With no round measured there is no calibrated set: no parameters, scenes or final tests
  // (the report and the rounds say what failed).
  const bool has_result = summary.best_round >= 1;
  OutputGroup group;
  group.Add(base + "_ucs.packing", [&](std::ostream& out) { WritePacking<Dim>(specimens.ucs, out); });
  group.Add(base + "_bts.packing", [&](std::ostream& out) { WritePacking<Dim>(specimens.bts, out); });
  if (has_result) {
    group.Add(base + "_parameters.toml", [&](std::ostream& out) {
      out << "# Calibrated by calibrate-to-material " << kVersion << " for '" << summary.target.name
          << "'.\n# The [material] table of a run-test scene; " << output.name
          << "_ucs_scene.toml holds a complete one.\n\n"
          << MaterialTomlTable(summary.material, Dim);
    });
    group.Add(base + "_ucs_scene.toml", [&](std::ostream& out) {
      WriteScene(out, FileName(base + "_ucs.packing"), summary.material, options.test, "ucs", output.name + "_ucs",
                 Dim);
    });
    group.Add(base + "_bts_scene.toml", [&](std::ostream& out) {
      WriteScene(out, FileName(base + "_bts.packing"), summary.material, options.test, "brazilian",
                 output.name + "_bts", Dim);
    });
  }
  // The scenes of every failed round: run-test repeats the failure.
  for (const VerificationRound& v : summary.rounds) {
    if (!v.failed) continue;
    const std::string round = "_round" + std::to_string(v.round);
    std::string what = "of strength round " + std::to_string(v.round) + ", which failed (" + v.failure + ")";
    std::replace(what.begin(), what.end(), '\n', ' ');  // one comment line
    group.Add(base + round + "_ucs_scene.toml", [&, round, what](std::ostream& out) {
      WriteScene(out, FileName(base + "_ucs.packing"), v.material, options.test, "ucs", output.name + round + "_ucs",
                 Dim, what);
    });
    group.Add(base + round + "_bts_scene.toml", [&, round, what](std::ostream& out) {
      WriteScene(out, FileName(base + "_bts.packing"), v.material, options.test, "brazilian",
                 output.name + round + "_bts", Dim, what);
    });
  }
  group.Add(base + "_report.json", [&](std::ostream& out) { out << json_report.dump(2) << "\n"; });
  group.Add(base + "_report.txt", [&](std::ostream& out) { out << text_report; });
  group.Add(base + "_sweep.csv", [&](std::ostream& out) { WriteSweepCsv(summary.maps, out); });
  group.Add(base + "_map_curves.csv",
            [&](std::ostream& out) { WriteCurvesCsv(summary.maps, summary.solution.ratios, out); });
  group.Add(base + "_verification.csv", [&](std::ostream& out) { WriteVerificationCsv(summary, out); });
  group.Add(base + "_elastic_runs.csv", [&](std::ostream& out) { WriteElasticRunsCsv(summary, out); });
  group.Add(base + "_reach.csv", [&](std::ostream& out) { WriteReachCsv(summary, out); });
  for (const std::string& f : group.Commit()) written.files.push_back(f);

  // The final verification tests, as run-test writes them (the Brazilian test by the rank
  // that holds it).
  if (has_result) {
    WriteFinalTestOutputs<Dim>(summary.final_ucs, specimens.ucs, "_verify_ucs", output, &written);
    if (summary.final_bts_rank == Rank())
      WriteFinalTestOutputs<Dim>(summary.final_bts, specimens.bts, "_verify_bts", output, &written);
  }

  if (output.pictures) {
    std::string error;
    const std::string script =
        MapsScript(summary.maps, summary.solution.ratios, base + "_sweep.csv", base + "_map_curves.csv");
    PlotOptions plot;
    plot.width_px = 1200;
    plot.height_px = 1000;
    if (RenderGnuplot(script, base + "_maps.png", plot, &error)) written.files.push_back(base + "_maps.png");
    else written.warnings.push_back("maps picture skipped: " + error);
    if (RenderGnuplot(ReachScript(summary, base + "_reach.csv"), base + "_reach.png", PlotOptions(), &error))
      written.files.push_back(base + "_reach.png");
    else
      written.warnings.push_back("reach picture skipped: " + error);
    if (RenderGnuplot(ConvergenceScript(summary, options, base + "_verification.csv"), base + "_convergence.png", PlotOptions(),
                      &error))
      written.files.push_back(base + "_convergence.png");
    else
      written.warnings.push_back("convergence picture skipped: " + error);
  }
  return written;
}

template <int Dim>
CalibrationOutputsWritten WriteFinalBrazilianOutputs(const CalibrationSummary& summary,
                                                     const CalibrationSpecimens<Dim>& specimens,
                                                     const CalibrationOutputOptions& output) {
  CalibrationOutputsWritten written;
  if (summary.best_round >= 1)
    WriteFinalTestOutputs<Dim>(summary.final_bts, specimens.bts, "_verify_bts", output, &written);
  return written;
}

template CalibrationOutputsWritten WriteFinalBrazilianOutputs<2>(const CalibrationSummary&,
                                                                 const CalibrationSpecimens<2>&,
                                                                 const CalibrationOutputOptions&);
template CalibrationOutputsWritten WriteFinalBrazilianOutputs<3>(const CalibrationSummary&,
                                                                 const CalibrationSpecimens<3>&,
                                                                 const CalibrationOutputOptions&);
template CalibrationOutputsWritten WriteCalibrationOutputs<2>(const CalibrationSummary&, const CalibrationSpecimens<2>&,
                                                              const CalibrationOptions&, const CalibrationOutputOptions&);
template CalibrationOutputsWritten WriteCalibrationOutputs<3>(const CalibrationSummary&, const CalibrationSpecimens<3>&,
                                                              const CalibrationOptions&, const CalibrationOutputOptions&);

}  // namespace specimen
