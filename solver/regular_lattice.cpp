#include "solver/regular_lattice.h"

#include <cmath>
#include <string>

#include "common/error.h"
#include "solver/neighbour_search.h"
#include "common/format.h"

namespace specimen {

namespace {

void CheckSize(const std::string& what, int value) {
  if (value < 1)
    throw InputError(what + " = " + std::to_string(value) + " is not allowed: it must be >= 1");
}

void CheckRadius(double radius) {
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw InputError("radius = " + Number(radius) +
                     " is not allowed: it must be finite and > 0");
}

// Every pair at centre distance 2R (to round-off).
template <int Dim>
void TouchingPairs(Packing<Dim>* packing) {
  CandidateSearch<Dim> search;
  const double radius = packing->radii.front();
  search.FindPairs(packing->centres, packing->radii, 1e-9 * radius, &packing->contacts);
  packing->contact_tolerance = 1e-9;
  packing->created_by = "specimen regular lattice";
}

template <int Dim>
Domain<Dim> BoundingDomain(const std::vector<Vector<Dim>>& centres, double radius) {
  Vector<Dim> lower = centres.front(), upper = centres.front();
  for (const auto& x : centres) {
    lower = lower.cwiseMin(x);
    upper = upper.cwiseMax(x);
  }
  lower.array() -= radius;
  upper.array() += radius;
  if constexpr (Dim == 2) {
    return Domain<2>::Rectangle(lower.x(), lower.y(), upper.x(), upper.y());
  } else {
    return Domain<3>::Box(lower, upper);
  }
}

}  // namespace

Packing<2> SquareLatticePacking(int columns, int rows, double radius) {
  CheckSize("columns", columns);
  CheckSize("rows", rows);
  CheckRadius(radius);
  std::vector<Vector<2>> centres;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < columns; ++c) centres.emplace_back(2.0 * radius * c, 2.0 * radius * r);
  Packing<2> packing(BoundingDomain<2>(centres, radius));
  packing.centres = centres;
  packing.radii.assign(centres.size(), radius);
  TouchingPairs(&packing);
  return packing;
}

Packing<2> HexagonalLatticePacking(int rows, int even_row_discs, int odd_row_discs, double radius) {
  CheckSize("rows", rows);
  CheckSize("even_row_discs", even_row_discs);
  CheckSize("odd_row_discs", odd_row_discs);
  CheckRadius(radius);
  const bool shift_even = even_row_discs < odd_row_discs;
  std::vector<Vector<2>> centres;
  for (int r = 0; r < rows; ++r) {
    const bool even = r % 2 == 0;
    const int discs = even ? even_row_discs : odd_row_discs;
    const double start = (even == shift_even) ? radius : 0.0;
    for (int c = 0; c < discs; ++c)
      centres.emplace_back(start + 2.0 * radius * c, std::sqrt(3.0) * radius * r);
  }
  Packing<2> packing(BoundingDomain<2>(centres, radius));
  packing.centres = centres;
  packing.radii.assign(centres.size(), radius);
  TouchingPairs(&packing);
  return packing;
}

Packing<3> CubicLatticePacking(int nx, int ny, int nz, double radius) {
  CheckSize("nx", nx);
  CheckSize("ny", ny);
  CheckSize("nz", nz);
  CheckRadius(radius);
  std::vector<Vector<3>> centres;
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x)
        centres.emplace_back(2.0 * radius * x, 2.0 * radius * y, 2.0 * radius * z);
  Packing<3> packing(BoundingDomain<3>(centres, radius));
  packing.centres = centres;
  packing.radii.assign(centres.size(), radius);
  TouchingPairs(&packing);
  return packing;
}

}  // namespace specimen
