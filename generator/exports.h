#pragma once
// Exports of a packing to the formats users load elsewhere (docs/exports.md, "Exports to
// other codes"):
//   VTU      VTK XML unstructured grid for ParaView: centres as points, a vertex cell per
//            particle and a line cell per contact (bond).
//   Yade     the sphere list `yade.ymport.text(filename)` reads.
//   LIGGGHTS a LAMMPS-style data file for `atom_style sphere` and `read_data`, and an input
//            script that loads it in LAMMPS or LIGGGHTS with this toolkit's masses.
// Every number is written with %.17g, so the exported values are the packing's values.
// The Write* functions fill a stream; the Save* wrappers write a file atomically.

#include <iosfwd>
#include <string>

#include "generator/packing.h"

namespace specimen {

// Throws InputError unless every contact refers to existing particles and there are as many
// radii as centres: an export indexes particles by contacts, and a file the other program
// misreads is worse than none. `format` names the export in the message.
template <int Dim>
void RequireExportable(const Packing<Dim>& packing, const std::string& format);

// VTK XML UnstructuredGrid (ascii, VTK file format 1.0). Points: particle centres (z = 0
// in 2D). Cells: one VTK_VERTEX per particle (cell i is particle i), then one VTK_LINE per
// contact in packing order. PointData: "radius" (Float64, m) and "contacts" (Int32, number
// of contacts of the particle). CellData: "kind" (Int32, 0 particle, 1 contact). In
// ParaView, show the particles with the Glyph filter (sphere, scale array "radius",
// scale factor 2 since the sphere source has unit diameter).
template <int Dim>
void WriteVtu(const Packing<Dim>& packing, std::ostream& out);

// Yade sphere list: comment lines starting with '#' (the first, "#format x_y_z_r", is
// the line Yade's own export writes), then one line "x y z r" per sphere (2D: z = 0), no
// blank lines (ymport.textExt fails on them). Load in Yade with
//   O.bodies.append(ymport.text('packing.txt'))
template <int Dim>
void WriteYadeSphereList(const Packing<Dim>& packing, std::ostream& out);

// The granular codes that read a `read_data` file of `atom_style sphere`. They give a particle
// of diameter d and density rho different masses in 2D (checked in LAMMPS 29 Sep 2021 update 2,
// Debian's 20220106, and LIGGGHTS-PUBLIC 3.8.0): LAMMPS a sphere's, 4/3 pi r^3 rho; LIGGGHTS a
// disc's per metre of thickness, pi r^2 rho. In 3D both give the sphere's.
enum class GranularCode { kLiggghts, kLammps };
std::string GranularCodeName(GranularCode code);  // "LIGGGHTS" or "LAMMPS"

// The density column that gives, in `code`, this toolkit's mass of a particle of radius r:
// 3D rho (a sphere); 2D a disc of thickness t, m = rho pi r^2 t: LIGGGHTS rho t, LAMMPS
// 3 rho t / (4 r).
double GranularDensityColumn(GranularCode code, int dimension, double density_kg_per_m3, double disc_thickness_m,
                             double radius_m);

// LIGGGHTS/LAMMPS data file for `atom_style sphere`: a title line, comment lines stating the
// mass convention and the input-script lines the dimension needs, "N atoms", "1 atom types",
// the box ("xlo xhi", "ylo yhi", "zlo zhi"), then the section "Atoms # sphere" with lines
// "id type diameter density x y z", ids from 1, type 1, the density column of
// GranularDensityColumn. The box is the domain's bounding box, grown where a particle reaches
// beyond it so that every sphere lies inside (read_data drops atoms outside a non-periodic
// box). 2D: z = 0 and the z bounds are -r_max..+r_max; the input needs `dimension 2` and
// `boundary f f p` before read_data (WriteGranularInput writes them). density and thickness
// must be finite and > 0.
template <int Dim>
void WriteGranularData(const Packing<Dim>& packing, std::ostream& out, GranularCode code, double density_kg_per_m3,
                       double disc_thickness_m = 1.0);

// generate-packing's `.liggghts`: the data file for LIGGGHTS with the toolkit's masses (2D:
// discs of 1 m thickness, which LAMMPS would read as spheres; its header says so).
template <int Dim>
void WriteLiggghtsData(const Packing<Dim>& packing, std::ostream& out, double density_kg_per_m3 = 2650.0);

// An input script that loads the data file `data_file` (a name relative to the working
// directory) in `code`: units si, the dimension (2D: `dimension 2`, `boundary f f p`,
// `fix enforce2d`), atom_style sphere, ghost velocities, a neighbour skin, read_data and
// `fix nve/sphere`. No contact model, walls or bonds (the header says why there are no bonds).
template <int Dim>
void WriteGranularInput(const Packing<Dim>& packing, std::ostream& out, GranularCode code,
                        const std::string& data_file);

// The same, written to `path` atomically (temporary file + rename); an error leaves no
// file behind. Throw FileError if the file cannot be written, InputError on bad input.
template <int Dim>
void SaveVtu(const Packing<Dim>& packing, const std::string& path);
template <int Dim>
void SaveYadeSphereList(const Packing<Dim>& packing, const std::string& path);
template <int Dim>
void SaveLiggghtsData(const Packing<Dim>& packing, const std::string& path,
                      double density_kg_per_m3 = 2650.0);
// The data file and its input script for `code`, as one atomic group (an error leaves neither);
// the script reads the data file by its file name.
template <int Dim>
void SaveGranularSpecimen(const Packing<Dim>& packing, GranularCode code, double density_kg_per_m3,
                          double disc_thickness_m, const std::string& input_path, const std::string& data_path);

}  // namespace specimen
