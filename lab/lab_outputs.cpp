#include "lab/lab_outputs.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>

#include "common/atomic_file.h"
#include "common/element_kind.h"
#include "common/error.h"
#include "common/plot.h"
#include "common/unit_names.h"
#include "specimen_version.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string Exact(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}

// The code of a bond in the snapshots and the crack files (common/element_kind.h).
int BondKindCode(ContactState state) {
  switch (state) {
    case ContactState::kBrokenInTension:
      return Code(ElementKind::kBrokenInTension);
    case ContactState::kBrokenInShear:
      return Code(ElementKind::kBrokenInShear);
    default:
      return Code(ElementKind::kContact);
  }
}

int LoadingAxis(const LabTestResult& r) {
  return r.kind == LabTestKind::kBrazilian ? 1 : r.dimension - 1;
}

// The stress and strain a picture of this test plots (MPa, -).
double PlotStressMpa(const LabTestResult& r, const LabCurvePoint& p) {
  switch (r.kind) {
    case LabTestKind::kBrazilian:  // k 2 F / (pi D t), Labra (4.38); k of the lattice's jaws
      return r.tensile_strength_factor * 2.0 * p.platen_force_n / (kPi * r.width_m * r.thickness_m) * 1e-6;
    case LabTestKind::kIsotropicCompression:
    case LabTestKind::kPureShear:
      return p.control * 1e-6;
    default:
      return p.axial_stress_pa * 1e-6;
  }
}

const char* PlotStressLabel(const LabTestResult& r) {
  switch (r.kind) {
    case LabTestKind::kBrazilian:
      return r.tensile_strength_factor != 1.0 ? "k 2F / (pi D t) [MPa] (centre stress, Hondros)" : "2F / (pi D t) [MPa]";
    case LabTestKind::kIsotropicCompression:
      return "mean stress [MPa] (compression positive)";
    case LabTestKind::kPureShear:
      return "shear stress sigma_xy [MPa]";
    case LabTestKind::kConfinedCompression:
      return "axial stress sigma_1 [MPa]";
    default:
      return "axial stress [MPa] (compression positive)";
  }
}

void WriteCurveCsv(const LabTestResult& r, std::ostream& out) {
  const int a = LoadingAxis(r), dim = r.dimension;
  out << "step,time_s,boundary_strain,axial_strain,lateral_strain,volumetric_strain,shear_strain,"
         "strain_xx,strain_yy,strain_zz,strain_yz,strain_xz,strain_xy,"
         "stress_xx_pa,stress_yy_pa,stress_zz_pa,stress_yz_pa,stress_xz_pa,stress_xy_pa,"
         "axial_stress_mpa,lateral_stress_mpa,plot_stress_mpa,"
      << ControlName(r.kind, dim) << ',' << PerThickness("platen_force_n", dim) << ','
      << VolumeName("stress", dim) << ",broken_tension,broken_shear";
  for (const char* energy : {"kinetic_j", "elastic_j", "external_work_j", "dissipated_j"})
    out << ',' << PerThickness(energy, dim);
  out << '\n';
  for (const LabCurvePoint& p : r.curve) {
    double lateral = 0.0;
    for (int k = 0; k < dim; ++k)
      if (k != a) lateral += p.strain(k, k) / (dim - 1);
    const double shear = 2.0 * p.strain(0, dim - 1);
    out << p.step << ',' << Exact(p.time_s) << ',' << Exact(p.boundary_strain) << ','
        << Exact(-p.strain(a, a)) << ',' << Exact(lateral) << ',' << Exact(-p.strain.trace())
        << ',' << Exact(shear);
    for (const auto& [i, j] : {std::pair{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}})
      out << ',' << Exact(p.strain(i, j));
    for (const auto& [i, j] : {std::pair{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}})
      out << ',' << Exact(p.stress_pa(i, j));
    out << ',' << Exact(p.axial_stress_pa * 1e-6) << ',' << Exact(p.lateral_stress_pa * 1e-6)
        << ',' << Exact(PlotStressMpa(r, p)) << ',' << Exact(p.control) << ','
        << Exact(p.platen_force_n) << ',' << Exact(p.volume_m3) << ',' << p.broken_in_tension
        << ',' << p.broken_in_shear << ',' << Exact(p.kinetic_energy_j) << ','
        << Exact(p.elastic_energy_j) << ',' << Exact(p.external_work_j) << ','
        << Exact(p.dissipated_j) << '\n';
  }
}

void WriteBondsCsv(const LabTestResult& r, std::ostream& out) {
  out << "i,j,kind,time_s,boundary_strain,x_m,y_m,z_m\n";
  for (const BrokenBond& b : r.broken_bonds)
    out << b.pair[0] << ',' << b.pair[1] << ','
        << Code(b.in_tension ? ElementKind::kBrokenInTension : ElementKind::kBrokenInShear) << ','
        << Exact(b.time_s) << ',' << Exact(b.boundary_strain) << ',' << Exact(b.midpoint.x())
        << ',' << Exact(b.midpoint.y()) << ',' << Exact(b.midpoint.z()) << '\n';
}

// VTK XML unstructured grid: one vertex per particle, one line per initial bond.
template <int Dim>
void WriteSnapshotVtu(const LabSnapshot& s, const Packing<Dim>& packing, std::ostream& out) {
  const size_t points = s.position.size(), lines = s.bonds.size();
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n<UnstructuredGrid>\n"
      << "<FieldData><DataArray type=\"Float64\" Name=\"TIME\" NumberOfTuples=\"1\" "
         "format=\"ascii\">"
      << Exact(s.time_s) << "</DataArray></FieldData>\n"
      << "<Piece NumberOfPoints=\"" << points << "\" NumberOfCells=\"" << points + lines
      << "\">\n<PointData Scalars=\"radius\" Vectors=\"displacement\">\n"
      << "<DataArray type=\"Float64\" Name=\"radius\" format=\"ascii\">\n";
  for (size_t q = 0; q < points; ++q) out << Exact(packing.radii[q]) << '\n';
  out << "</DataArray>\n<DataArray type=\"Float64\" Name=\"displacement\" "
         "NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const auto& d : s.displacement)
    out << Exact(d.x()) << ' ' << Exact(d.y()) << ' ' << Exact(d.z()) << '\n';
  out << "</DataArray>\n</PointData>\n<CellData Scalars=\"kind\">\n"
      << "<DataArray type=\"Int32\" Name=\"kind\" format=\"ascii\">\n";
  for (size_t q = 0; q < points; ++q) out << Code(ElementKind::kParticle) << '\n';
  for (const ContactState state : s.bond_state) out << BondKindCode(state) << '\n';
  out << "</DataArray>\n</CellData>\n<Points>\n"
      << "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const auto& x : s.position) out << Exact(x.x()) << ' ' << Exact(x.y()) << ' ' << Exact(x.z()) << '\n';
  out << "</DataArray>\n</Points>\n<Cells>\n"
      << "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (size_t q = 0; q < points; ++q) out << q << '\n';
  for (const auto& b : s.bonds) out << b[0] << ' ' << b[1] << '\n';
  out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (size_t q = 1; q <= points; ++q) out << q << '\n';
  for (size_t b = 1; b <= lines; ++b) out << points + 2 * b << '\n';
  out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (size_t q = 0; q < points; ++q) out << "1\n";   // VTK_VERTEX
  for (size_t b = 0; b < lines; ++b) out << "3\n";    // VTK_LINE
  out << "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
}

// The brief report as a plot title: its "; "-separated parts on two lines, so no figure is cut.
std::string PlotTitle(const std::string& brief) {
  std::string title = brief;
  const size_t half = title.size() / 2;
  size_t split = title.find("; ", half);
  if (split == std::string::npos) split = title.rfind("; ", half);
  if (split != std::string::npos) title.replace(split, 2, "\\n");
  return title;
}

std::string StressStrainScript(const LabTestResult& r, const std::string& csv) {
  std::ostringstream s;
  const std::string file = GnuplotQuote(csv);
  s << "set datafile separator comma\nset datafile columnheaders\n"
    << "set key top left\nset grid\n"
    << "set ylabel '" << PlotStressLabel(r) << "'\n"
    << "set y2label 'broken bonds'\nset ytics nomirror\nset y2tics\nset y2range [0:*]\n"
    << "set title \"" << PlotTitle(r.BriefReport()) << "\" noenhanced font ',9'\n";
  const std::string bonds = "(column('broken_tension')+column('broken_shear'))";
  switch (r.kind) {
    case LabTestKind::kBrazilian:
      s << "set xlabel 'platen approach / D'\n"
        << "plot " << file << " using 'boundary_strain':'plot_stress_mpa' with lines lw 2 "
        << "title 'stress', " << file << " using 'boundary_strain':" << bonds
        << " axes x1y2 with lines dt 2 title 'broken bonds'\n";
      break;
    case LabTestKind::kIsotropicCompression:
      s << "set xlabel 'volumetric strain (Bagi, compression positive)'\n"
        << "plot " << file << " using 'volumetric_strain':'plot_stress_mpa' with lines lw 2 "
        << "title 'mean stress', " << file << " using 'volumetric_strain':" << bonds
        << " axes x1y2 with lines dt 2 title 'broken bonds'\n";
      break;
    case LabTestKind::kPureShear:
      s << "set xlabel 'shear strain 2 eps_xy (Bagi)'\n"
        << "plot " << file << " using 'shear_strain':'plot_stress_mpa' with lines lw 2 "
        << "title 'shear stress', " << file << " using 'shear_strain':" << bonds
        << " axes x1y2 with lines dt 2 title 'broken bonds'\n";
      break;
    default:
      s << "set xlabel 'strain (axial: compression positive; lateral: plotted negative)'\n"
        << "plot " << file << " using 'axial_strain':'plot_stress_mpa' with lines lw 2 "
        << "title 'axial (Bagi)', " << file
        << " using 'boundary_strain':'plot_stress_mpa' with lines lw 1 title 'axial (platens)', "
        << file << " using (-column('lateral_strain')):'plot_stress_mpa' with lines lw 2 "
        << "title 'lateral (Bagi)', " << file << " using 'axial_strain':" << bonds
        << " axes x1y2 with lines dt 2 title 'broken bonds'\n";
  }
  return s.str();
}

// 2D: the particles at the end (grey) and the broken bonds between their centres.
std::string CracksScript(const LabSnapshot& end, const Packing<2>& packing,
                         const std::string& particles_csv, const std::string& cracks_csv,
                         const std::string& title, int* height_px) {
  Eigen::Vector2d lower = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d upper = -lower;
  for (size_t q = 0; q < end.position.size(); ++q) {
    const Eigen::Vector2d x = end.position[q].head<2>();
    lower = lower.cwiseMin(x - Eigen::Vector2d::Constant(packing.radii[q]));
    upper = upper.cwiseMax(x + Eigen::Vector2d::Constant(packing.radii[q]));
  }
  const Eigen::Vector2d margin = 0.03 * (upper - lower);
  lower -= margin;
  upper += margin;
  *height_px = std::clamp(
      static_cast<int>(std::lround(900.0 * (upper.y() - lower.y()) / (upper.x() - lower.x()))) + 120,
      300, 4000);
  std::ostringstream s;
  s << "set datafile separator comma\nset datafile columnheaders\n"
    << "set size ratio -1\nunset key\n"
    << "set xrange [" << Exact(lower.x()) << ':' << Exact(upper.x()) << "]\n"
    << "set yrange [" << Exact(lower.y()) << ':' << Exact(upper.y()) << "]\n"
    << "set xlabel 'x [m]'\nset ylabel 'y [m]'\n"
    << "set title '" << title << "' noenhanced font ',10'\n"
    << "set style fill solid 1.0 noborder\n"
    << "plot " << GnuplotQuote(particles_csv) << " using 1:2:3 with circles lc rgb '#c8c8c8', "
    << GnuplotQuote(cracks_csv)
    << " using ($5==" << Code(ElementKind::kBrokenInTension)
    << "?$1:NaN):2:($3-$1):($4-$2) with vectors nohead lw 1.5 lc rgb '#d62728', "
    << GnuplotQuote(cracks_csv) << " using ($5==" << Code(ElementKind::kBrokenInShear)
    << "?$1:NaN):2:($3-$1):($4-$2) with vectors nohead lw 1.5 lc rgb '#1f4fb4'\n";
  return s.str();
}

}  // namespace

void CheckLabOutputLocation(const LabOutputOptions& options) {
  if (std::string rule; !IsValidOutputName(options.name, &rule))
    throw InputError("output name '" + options.name + "' is not allowed: " + rule);
  EnsureDirectory(options.directory, "output directory");
}

template <int Dim>
LabOutputsWritten WriteLabOutputs(const LabTestResult& r, const Packing<Dim>& packing,
                                  const nlohmann::json& report, const LabOutputOptions& options) {
  CheckLabOutputLocation(options);
  const std::string base = options.directory + "/" + options.name;
  nlohmann::json summary = report.is_object() ? report : nlohmann::json::object();
  summary["version"] = kVersion;
  summary["result"] = r.ToJson();
  // The crack CSV files come with the end state (recorded for pictures or snapshots), with
  // or without the picture drawn from them.
  const bool cracks = Dim == 2 && r.end_snapshot.recorded;

  // 1. The data, renamed into place together.
  OutputGroup group;
  group.Add(base + "_curve.csv", [&](std::ostream& out) { WriteCurveCsv(r, out); });
  group.Add(base + "_bonds.csv", [&](std::ostream& out) { WriteBondsCsv(r, out); });
  group.Add(base + "_summary.json", [&](std::ostream& out) { out << summary.dump(2) << '\n'; });
  if (options.snapshots)
    for (const LabSnapshot* s : {&r.peak_snapshot, &r.end_snapshot})
      if (s->recorded)
        group.Add(base + "_" + s->label + ".vtu",
                  [&](std::ostream& out) { WriteSnapshotVtu<Dim>(*s, packing, out); });
  if (cracks) {
    const LabSnapshot& end = r.end_snapshot;
    group.Add(base + "_particles.csv", [&](std::ostream& out) {
      out << "x_m,y_m,radius_m\n";
      for (size_t q = 0; q < end.position.size(); ++q)
        out << Exact(end.position[q].x()) << ',' << Exact(end.position[q].y()) << ','
            << Exact(packing.radii[q]) << '\n';
    });
    group.Add(base + "_cracks.csv", [&](std::ostream& out) {
      out << "x_i_m,y_i_m,x_j_m,y_j_m,kind\n";
      for (size_t b = 0; b < end.bonds.size(); ++b) {
        if (end.bond_state[b] == ContactState::kBonded) continue;
        const auto& x1 = end.position[end.bonds[b][0]];
        const auto& x2 = end.position[end.bonds[b][1]];
        out << Exact(x1.x()) << ',' << Exact(x1.y()) << ',' << Exact(x2.x()) << ','
            << Exact(x2.y()) << ',' << BondKindCode(end.bond_state[b]) << '\n';
      }
    });
  }
  LabOutputsWritten written;
  written.files = group.Commit();

  // 2. Pictures, from the committed CSV files.
  if (options.pictures) {
    std::string error;
    const std::string png = base + "_stress_strain.png";
    if (RenderGnuplot(StressStrainScript(r, base + "_curve.csv"), png, {1000, 700}, &error))
      written.files.push_back(png);
    else
      written.warnings.push_back(error);
    if constexpr (Dim == 2) {
      if (cracks) {
        int height = 900;
        const std::string title = std::to_string(r.broken_in_tension) + " bonds broken in tension (red), " +
                                  std::to_string(r.broken_in_shear) + " in shear (blue), at the end";
        const std::string script = CracksScript(r.end_snapshot, packing, base + "_particles.csv",
                                                base + "_cracks.csv", title, &height);
        const std::string cracks_png = base + "_cracks.png";
        if (RenderGnuplot(script, cracks_png, {1000, height}, &error))
          written.files.push_back(cracks_png);
        else
          written.warnings.push_back(error);
      } else {
        written.warnings.push_back("no end snapshot recorded: the crack picture is skipped");
      }
    }
  }
  return written;
}

template <int Dim>
LabOutputsWritten WriteEnvelopeOutputs(const ConfinedEnvelope& envelope,
                                       const Packing<Dim>& packing, const nlohmann::json& report,
                                       const LabOutputOptions& options) {
  CheckLabOutputLocation(options);
  LabOutputsWritten written;
  for (size_t k = 0; k < envelope.tests.size(); ++k) {
    LabOutputOptions one = options;
    one.name = options.name + "_s3_" + std::to_string(k + 1);
    nlohmann::json test_report = report;
    test_report["confining_stress_pa"] = envelope.confining_stress_pa[k];
    const LabOutputsWritten w = WriteLabOutputs<Dim>(envelope.tests[k], packing, test_report, one);
    written.files.insert(written.files.end(), w.files.begin(), w.files.end());
    written.warnings.insert(written.warnings.end(), w.warnings.begin(), w.warnings.end());
  }
  const std::string base = options.directory + "/" + options.name;
  nlohmann::json summary = report.is_object() ? report : nlohmann::json::object();
  summary["version"] = kVersion;
  summary["envelope"] = envelope.ToJson();
  OutputGroup group;
  group.Add(base + "_envelope.csv", [&](std::ostream& out) {
    out << "confining_stress_pa,peak_stress_pa,peak_reached,fit_stress_pa\n";
    for (size_t k = 0; k < envelope.tests.size(); ++k) {
      const double s3 = envelope.confining_stress_pa[k];
      out << Exact(s3) << ',' << Exact(envelope.tests[k].peak_stress_pa) << ','
          << (envelope.tests[k].peak_reached ? 1 : 0) << ','
          << (envelope.fit.valid ? Exact(envelope.fit.intercept_pa + envelope.fit.slope * s3) : "")
          << '\n';  // empty without a fit
    }
  });
  group.Add(base + "_summary.json", [&](std::ostream& out) { out << summary.dump(2) << '\n'; });
  const std::vector<std::string> files = group.Commit();
  written.files.insert(written.files.end(), files.begin(), files.end());
  if (options.pictures) {
    std::ostringstream s;
    const std::string csv = GnuplotQuote(base + "_envelope.csv");
    s << "set datafile separator comma\nset datafile columnheaders\nset key top left\nset grid\n"
      << "set xlabel 'confining stress sigma_3 [MPa]'\nset ylabel 'peak axial stress sigma_1 [MPa]'\n"
      << "set title '" << envelope.BriefReport() << "' noenhanced font ',9'\n"
      << "plot " << csv << " using ($1*1e-6):($2*1e-6) with points pt 7 ps 1.5 title 'peaks'";
    if (envelope.fit.valid)
      s << ", " << Exact(envelope.fit.intercept_pa * 1e-6) << " + " << Exact(envelope.fit.slope)
        << "*x with lines lw 2 title 'Mohr-Coulomb fit'";
    s << '\n';
    std::string error;
    const std::string png = base + "_envelope.png";
    if (RenderGnuplot(s.str(), png, {900, 700}, &error))
      written.files.push_back(png);
    else
      written.warnings.push_back(error);
  }
  return written;
}

template LabOutputsWritten WriteLabOutputs<2>(const LabTestResult&, const Packing<2>&,
                                              const nlohmann::json&, const LabOutputOptions&);
template LabOutputsWritten WriteLabOutputs<3>(const LabTestResult&, const Packing<3>&,
                                              const nlohmann::json&, const LabOutputOptions&);
template LabOutputsWritten WriteEnvelopeOutputs<2>(const ConfinedEnvelope&, const Packing<2>&,
                                                   const nlohmann::json&, const LabOutputOptions&);
template LabOutputsWritten WriteEnvelopeOutputs<3>(const ConfinedEnvelope&, const Packing<3>&,
                                                   const nlohmann::json&, const LabOutputOptions&);

}  // namespace specimen
