#pragma once
// Regular packings of equal particles, built in code: the specimens of the lattice oracles
// (Madan's SC 9x20 and HCP 110-disc specimens, hexagonal blocks for the kn/kt closed forms,
// simple cubic blocks of spheres) and small benchmark specimens. The contact list holds
// every pair of touching neighbours (centre distance 2R), so all of them become bonds.

#include "generator/packing.h"

namespace specimen {

// Square (SC) lattice of `columns` x `rows` discs of radius R: centres (2R c, 2R r),
// particle index r * columns + c; contacts between horizontal and vertical neighbours.
Packing<2> SquareLatticePacking(int columns, int rows, double radius);

// Hexagonal lattice of discs of radius R in rows along x, row pitch sqrt(3) R: row r holds
// even_row_discs (r even) or odd_row_discs (r odd) discs spaced 2R; the shorter rows (or,
// for equal rows, the odd rows) start at x = R, the others at x = 0. Index: row by row from
// the bottom (y = 0). Madan's HCP specimen: HexagonalLatticePacking(17, 6, 7, R).
Packing<2> HexagonalLatticePacking(int rows, int even_row_discs, int odd_row_discs, double radius);

// Simple cubic lattice of nx x ny x nz spheres: centres 2R (x, y, z), index (z ny + y) nx + x.
Packing<3> CubicLatticePacking(int nx, int ny, int nz, double radius);

}  // namespace specimen
