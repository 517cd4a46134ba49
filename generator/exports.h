#pragma once
// Exports of a packing to the formats users load elsewhere (docs/exports.md, "Exports to
// other codes"):
//   VTU      VTK XML unstructured grid for ParaView: centres as points, a vertex cell per
//            particle and a line cell per contact (bond).
//   Yade     the sphere list `yade.ymport.text(filename)` reads.
//   LIGGGHTS a LAMMPS-style data file for `atom_style sphere` and `read_data`.
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

// LIGGGHTS/LAMMPS data file for `atom_style sphere`: a comment line, "N atoms",
// "1 atom types", the box ("xlo xhi", "ylo yhi", "zlo zhi"), then the section
// "Atoms # sphere" with lines "id type diameter density x y z", ids from 1, type 1.
// The box is the domain's bounding box, grown where a particle reaches beyond it so that
// every sphere lies inside (read_data drops atoms outside a non-periodic box). 2D: z = 0
// and the z bounds are -r_max..+r_max (LIGGGHTS wants z periodic in 2D; use
// `dimension 2` and `boundary f f p` or similar). `density_kg_per_m3` must be > 0.
template <int Dim>
void WriteLiggghtsData(const Packing<Dim>& packing, std::ostream& out,
                       double density_kg_per_m3 = 2650.0);

// The same, written to `path` atomically (temporary file + rename); an error leaves no
// file behind. Throw FileError if the file cannot be written, InputError on bad input.
template <int Dim>
void SaveVtu(const Packing<Dim>& packing, const std::string& path);
template <int Dim>
void SaveYadeSphereList(const Packing<Dim>& packing, const std::string& path);
template <int Dim>
void SaveLiggghtsData(const Packing<Dim>& packing, const std::string& path,
                      double density_kg_per_m3 = 2650.0);

}  // namespace specimen
