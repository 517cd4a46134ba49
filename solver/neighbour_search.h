#pragma once
// Candidate pairs for new (unbonded) contacts: a uniform cell list over the particle
// centres, rebuilt only when some particle may have come within contact range of a pair
// that was not a candidate (see Simulation: the search runs when twice the largest
// displacement since the last search, plus the growth of the DDEM deformation margin,
// exceeds the skin). Bonds are permanent pairs and do not depend on the search.
//
// The buffers live in the object and are reused, so a rebuild allocates only while the
// arrays are still growing to their working size.

#include <array>
#include <cstdint>
#include <vector>

#include "solver/vector_algebra.h"

namespace specimen {

template <int Dim>
class CandidateSearch {
 public:
  // Writes to *pairs (cleared first) every pair i < j with |xj - xi| < ri + rj + margin,
  // sorted by (i, j). margin >= 0 [m].
  void FindPairs(const std::vector<Vector<Dim>>& position, const std::vector<double>& radius,
                 double margin, std::vector<std::array<int, 2>>* pairs);

 private:
  using Cell = std::array<int, Dim>;
  std::int64_t Linear(const Cell& cell) const {
    std::int64_t index = 0;
    for (int axis = Dim - 1; axis >= 0; --axis) index = index * cells_per_axis_[axis] + cell[axis];
    return index;
  }

  Cell cells_per_axis_{};
  std::vector<int> cell_start_;  // cell c holds sorted entries [start[c], start[c + 1])
  std::vector<std::int64_t> cell_of_;
  std::vector<int> fill_;
  std::vector<int> sorted_particle_;
  std::vector<Cell> half_stencil_;
};

}  // namespace specimen
