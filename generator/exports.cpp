#include "generator/exports.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <ostream>
#include <vector>

#include "common/atomic_file.h"
#include "common/element_kind.h"
#include "common/error.h"

namespace specimen {
namespace {

// Provenance for a one-line comment: line breaks removed, length bounded (LIGGGHTS reads
// lines into a 256-character buffer; a longer first line would spill into the header).
std::string OneLine(const std::string& text, size_t maximum_length) {
  std::string line = text.substr(0, maximum_length);
  for (char& c : line)
    if (c == '\n' || c == '\r') c = ' ';
  return line;
}

// Text safe inside an XML comment: no control characters and no "--".
std::string XmlCommentText(const std::string& text) {
  std::string safe;
  for (char c : OneLine(text, 200)) {
    if (static_cast<unsigned char>(c) < 32) c = ' ';
    if (c == '-' && !safe.empty() && safe.back() == '-') c = ' ';
    safe += c;
  }
  return safe;
}

// The centre as three coordinates (z = 0 in 2D), each written exactly.
template <int Dim>
std::string CentreXyz(const Vector<Dim>& centre, char separator) {
  std::string text = ExactDouble(centre[0]) + separator + ExactDouble(centre[1]) + separator;
  text += Dim == 3 ? ExactDouble(centre[Dim - 1]) : std::string("0");
  return text;
}

}  // namespace

template <int Dim>
void RequireExportable(const Packing<Dim>& packing, const std::string& format) {
  if (packing.centres.size() != packing.radii.size())
    throw InputError("cannot export " + format + ": " + std::to_string(packing.centres.size()) +
                     " centres but " + std::to_string(packing.radii.size()) + " radii");
  for (const auto& contact : packing.contacts)
    if (contact[0] < 0 || contact[1] < 0 || contact[0] >= packing.size() ||
        contact[1] >= packing.size())
      throw InputError("cannot export " + format + ": contact (" + std::to_string(contact[0]) +
                       ", " + std::to_string(contact[1]) + ") refers to a particle that does " +
                       "not exist (there are " + std::to_string(packing.size()) + ")");
}

template <int Dim>
void WriteVtu(const Packing<Dim>& packing, std::ostream& out) {
  RequireExportable(packing, "VTU");
  const int particle_count = packing.size();
  const size_t contact_count = packing.contacts.size();
  std::vector<int> contacts_per_particle(particle_count, 0);
  for (const auto& contact : packing.contacts) {
    ++contacts_per_particle[contact[0]];
    ++contacts_per_particle[contact[1]];
  }
  constexpr int kVtkVertex = 1;  // VTK cell type numbers (vtkCellType.h)
  constexpr int kVtkLine = 3;

  out << "<?xml version=\"1.0\"?>\n"
      << "<!-- specimen packing: " << XmlCommentText(packing.created_by) << " -->\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n"
      << "  <UnstructuredGrid>\n"
      << "    <Piece NumberOfPoints=\"" << particle_count << "\" NumberOfCells=\""
      << particle_count + contact_count << "\">\n";

  out << "      <PointData Scalars=\"radius\">\n"
      << "        <DataArray type=\"Float64\" Name=\"radius\" format=\"ascii\">\n";
  for (double radius : packing.radii) out << ExactDouble(radius) << '\n';
  out << "        </DataArray>\n"
      << "        <DataArray type=\"Int32\" Name=\"contacts\" format=\"ascii\">\n";
  for (int count : contacts_per_particle) out << count << '\n';
  out << "        </DataArray>\n"
      << "      </PointData>\n";

  out << "      <CellData Scalars=\"kind\">\n"
      << "        <DataArray type=\"Int32\" Name=\"kind\" format=\"ascii\">\n";
  for (int i = 0; i < particle_count; ++i) out << Code(ElementKind::kParticle) << '\n';
  for (size_t c = 0; c < contact_count; ++c) out << Code(ElementKind::kContact) << '\n';
  out << "        </DataArray>\n"
      << "      </CellData>\n";

  out << "      <Points>\n"
      << "        <DataArray type=\"Float64\" Name=\"centres\" NumberOfComponents=\"3\" "
         "format=\"ascii\">\n";
  for (const auto& centre : packing.centres) out << CentreXyz<Dim>(centre, ' ') << '\n';
  out << "        </DataArray>\n"
      << "      </Points>\n";

  out << "      <Cells>\n"
      << "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (int i = 0; i < particle_count; ++i) out << i << '\n';
  for (const auto& contact : packing.contacts) out << contact[0] << ' ' << contact[1] << '\n';
  out << "        </DataArray>\n"
      << "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  // Offsets are the end of each cell's connectivity: 1, 2, ..., N, then N + 2, N + 4, ...
  for (int i = 0; i < particle_count; ++i) out << i + 1 << '\n';
  for (size_t c = 0; c < contact_count; ++c) out << particle_count + 2 * (c + 1) << '\n';
  out << "        </DataArray>\n"
      << "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (int i = 0; i < particle_count; ++i) out << kVtkVertex << '\n';
  for (size_t c = 0; c < contact_count; ++c) out << kVtkLine << '\n';
  out << "        </DataArray>\n"
      << "      </Cells>\n"
      << "    </Piece>\n"
      << "  </UnstructuredGrid>\n"
      << "</VTKFile>\n";
}

template <int Dim>
void WriteYadeSphereList(const Packing<Dim>& packing, std::ostream& out) {
  RequireExportable(packing, "Yade sphere list");
  // ymport.textExt reads "#format <name>" as a format switch and skips other lines whose
  // first word starts with '#'; comments therefore start with "# ", never "#format".
  out << "#format x_y_z_r\n"
      << "# Yade sphere list: centre x y z and radius r, one sphere per line"
      << (Dim == 2 ? " (2D packing: z = 0)" : "") << "\n"
      << "# from specimen packing: " << OneLine(packing.created_by, 200) << "\n"
      << "# spheres: " << packing.size() << "\n"
      << "# load in Yade: O.bodies.append(ymport.text('<this file>'))\n";
  for (int i = 0; i < packing.size(); ++i)
    out << CentreXyz<Dim>(packing.centres[i], ' ') << ' ' << ExactDouble(packing.radii[i]) << '\n';
}

std::string GranularCodeName(GranularCode code) { return code == GranularCode::kLammps ? "LAMMPS" : "LIGGGHTS"; }

double GranularDensityColumn(GranularCode code, int dimension, double density_kg_per_m3, double disc_thickness_m,
                             double radius_m) {
  if (dimension == 3) return density_kg_per_m3;
  // LIGGGHTS: m = pi r^2 x column; LAMMPS: m = 4/3 pi r^3 x column; wanted: rho pi r^2 t.
  return code == GranularCode::kLiggghts ? density_kg_per_m3 * disc_thickness_m
                                         : 3.0 * density_kg_per_m3 * disc_thickness_m / (4.0 * radius_m);
}

template <int Dim>
void WriteGranularData(const Packing<Dim>& packing, std::ostream& out, GranularCode code, double density_kg_per_m3,
                       double disc_thickness_m) {
  const std::string name = GranularCodeName(code);
  RequireExportable(packing, name + " data file");
  if (!std::isfinite(density_kg_per_m3) || !(density_kg_per_m3 > 0.0))
    throw InputError(name + " export: density_kg_per_m3 = " + ExactDouble(density_kg_per_m3) +
                     " is not allowed: it must be finite and > 0");
  if (!std::isfinite(disc_thickness_m) || !(disc_thickness_m > 0.0))
    throw InputError(name + " export: disc_thickness = " + ExactDouble(disc_thickness_m) +
                     " is not allowed: it must be finite and > 0 [m]");
  // Box: the domain's bounding box grown to hold every sphere whole.
  Vector<Dim> lower = packing.domain.Lower();
  Vector<Dim> upper = packing.domain.Upper();
  double largest_radius = 0.0;
  for (int i = 0; i < packing.size(); ++i) {
    const double radius = packing.radii[i];
    largest_radius = std::max(largest_radius, radius);
    for (int k = 0; k < Dim; ++k) {
      lower[k] = std::min(lower[k], packing.centres[i][k] - radius);
      upper[k] = std::max(upper[k], packing.centres[i][k] + radius);
    }
  }
  double z_lower, z_upper;
  if constexpr (Dim == 3) {
    z_lower = lower[2];
    z_upper = upper[2];
  } else {
    // A 2D box still needs a z extent; one particle thick (or half the smallest domain
    // extent for an empty packing) keeps it non-degenerate.
    const double half_thickness =
        largest_radius > 0.0 ? largest_radius : 0.5 * packing.domain.SmallestExtent();
    z_lower = -half_thickness;
    z_upper = half_thickness;
  }

  // The first line is a comment LIGGGHTS skips; it must stay under 256 characters.
  out << name << " data file, atom_style sphere, from specimen packing: " << OneLine(packing.created_by, 120)
      << "\n";
  // The mass convention, in comment lines read_data skips (each under 256 characters).
  if constexpr (Dim == 2) {
    out << "# 2D masses: discs of thickness t = " << ExactDouble(disc_thickness_m) << " m, m = rho pi r^2 t with rho = "
        << ExactDouble(density_kg_per_m3) << " kg/m^3 (this toolkit's)\n"
        << "# for " << name << ", which gives "
        << (code == GranularCode::kLiggghts ? "m = pi r^2 x density column (a disc per metre): column = rho t"
                                            : "m = 4/3 pi r^3 x density column (a sphere): column = 3 rho t / (4 r)")
        << "\n# read by " << (code == GranularCode::kLiggghts ? "LAMMPS" : "LIGGGHTS")
        << " the masses differ: export-specimen --to " << (code == GranularCode::kLiggghts ? "lammps" : "liggghts")
        << " writes its file\n"
        << "# the input needs dimension 2 and boundary f f p before read_data, and fix enforce2d\n";
  } else {
    out << "# masses: spheres, m = 4/3 pi r^3 rho, rho = " << ExactDouble(density_kg_per_m3)
        << " kg/m^3, in LAMMPS and LIGGGHTS alike\n";
  }
  out << "\n"
      << packing.size() << " atoms\n"
      << "1 atom types\n\n"
      << ExactDouble(lower[0]) << ' ' << ExactDouble(upper[0]) << " xlo xhi\n"
      << ExactDouble(lower[1]) << ' ' << ExactDouble(upper[1]) << " ylo yhi\n"
      << ExactDouble(z_lower) << ' ' << ExactDouble(z_upper) << " zlo zhi\n\n"
      << "Atoms # sphere\n\n";
  // atom-ID atom-type diameter density x y z
  for (int i = 0; i < packing.size(); ++i)
    out << i + 1 << " 1 " << ExactDouble(2.0 * packing.radii[i]) << ' '
        << ExactDouble(GranularDensityColumn(code, Dim, density_kg_per_m3, disc_thickness_m, packing.radii[i])) << ' '
        << CentreXyz<Dim>(packing.centres[i], ' ') << '\n';
}

template <int Dim>
void WriteLiggghtsData(const Packing<Dim>& packing, std::ostream& out, double density_kg_per_m3) {
  WriteGranularData(packing, out, GranularCode::kLiggghts, density_kg_per_m3, 1.0);
}

template <int Dim>
void WriteGranularInput(const Packing<Dim>& packing, std::ostream& out, GranularCode code,
                        const std::string& data_file) {
  RequireExportable(packing, GranularCodeName(code) + " input");
  const bool liggghts = code == GranularCode::kLiggghts;
  double smallest_radius = packing.radii.empty() ? 1.0 : packing.radii[0];
  for (double r : packing.radii) smallest_radius = std::min(smallest_radius, r);
  out << "# " << GranularCodeName(code) << " input for the specimen in " << OneLine(data_file, 200) << "\n"
      << "# from specimen packing: " << OneLine(packing.created_by, 200) << "\n"
      << "# Masses: this toolkit's (the data file's header says how its density column gives them).\n"
      << "# No bonds: " << (liggghts ? "LIGGGHTS-PUBLIC 3.8.0 has no bond styles at all"
                                     : "LAMMPS 29 Sep 2021 has central-force bonds only (bond_style harmonic with "
                                       "fix bond/break), no tangential stiffness or shear strength; its granular "
                                       "bonds (BPM) came later")
      << ".\n# Add the contact model (pair_style gran...), walls and loading after read_data.\n"
      << "units           si\n";
  if constexpr (Dim == 2) out << "dimension       2\n";
  out << "atom_style      sphere\n"
      << "atom_modify     map array sort 0 0\n"
      << "boundary        " << (Dim == 2 ? "f f p" : "f f f") << "\n"
      << "newton          off\n"
      << (liggghts ? "communicate     single vel yes\n" : "comm_modify     vel yes\n")
      << "neighbor        " << ExactDouble(0.2 * smallest_radius) << " bin\n"
      << "read_data       " << data_file << "\n"
      << "fix             integrate all nve/sphere\n";
  if constexpr (Dim == 2) out << "fix             plane all enforce2d\n";
}

template <int Dim>
void SaveVtu(const Packing<Dim>& packing, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) { WriteVtu(packing, out); });
}

template <int Dim>
void SaveYadeSphereList(const Packing<Dim>& packing, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) { WriteYadeSphereList(packing, out); });
}

template <int Dim>
void SaveLiggghtsData(const Packing<Dim>& packing, const std::string& path,
                      double density_kg_per_m3) {
  WriteFileAtomically(
      path, [&](std::ostream& out) { WriteLiggghtsData(packing, out, density_kg_per_m3); });
}

template <int Dim>
void SaveGranularSpecimen(const Packing<Dim>& packing, GranularCode code, double density_kg_per_m3,
                          double disc_thickness_m, const std::string& input_path, const std::string& data_path) {
  OutputGroup files;
  files.Add(data_path, [&](std::ostream& out) {
    WriteGranularData(packing, out, code, density_kg_per_m3, disc_thickness_m);
  });
  const std::string data_name = std::filesystem::path(data_path).filename().string();
  files.Add(input_path, [&](std::ostream& out) { WriteGranularInput(packing, out, code, data_name); });
  files.Commit();
}

template void RequireExportable<2>(const Packing<2>&, const std::string&);
template void RequireExportable<3>(const Packing<3>&, const std::string&);
template void WriteVtu<2>(const Packing<2>&, std::ostream&);
template void WriteVtu<3>(const Packing<3>&, std::ostream&);
template void WriteYadeSphereList<2>(const Packing<2>&, std::ostream&);
template void WriteYadeSphereList<3>(const Packing<3>&, std::ostream&);
template void WriteLiggghtsData<2>(const Packing<2>&, std::ostream&, double);
template void WriteLiggghtsData<3>(const Packing<3>&, std::ostream&, double);
template void WriteGranularData<2>(const Packing<2>&, std::ostream&, GranularCode, double, double);
template void WriteGranularData<3>(const Packing<3>&, std::ostream&, GranularCode, double, double);
template void WriteGranularInput<2>(const Packing<2>&, std::ostream&, GranularCode, const std::string&);
template void WriteGranularInput<3>(const Packing<3>&, std::ostream&, GranularCode, const std::string&);
template void SaveGranularSpecimen<2>(const Packing<2>&, GranularCode, double, double, const std::string&,
                                      const std::string&);
template void SaveGranularSpecimen<3>(const Packing<3>&, GranularCode, double, double, const std::string&,
                                      const std::string&);
template void SaveVtu<2>(const Packing<2>&, const std::string&);
template void SaveVtu<3>(const Packing<3>&, const std::string&);
template void SaveYadeSphereList<2>(const Packing<2>&, const std::string&);
template void SaveYadeSphereList<3>(const Packing<3>&, const std::string&);
template void SaveLiggghtsData<2>(const Packing<2>&, const std::string&, double);
template void SaveLiggghtsData<3>(const Packing<3>&, const std::string&, double);

}  // namespace specimen
