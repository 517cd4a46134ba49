#include "generator/neighbour_grid.h"

#include <algorithm>
#include <string>

namespace specimen {

template <int Dim>
std::vector<std::array<int, 2>> OverlappingPairs(const std::vector<Vector<Dim>>& centres,
                                                 const std::vector<double>& radii,
                                                 double min_overlap) {
  if (centres.size() != radii.size())
    throw InputError("overlapping pairs: " + std::to_string(centres.size()) + " centres but " +
                     std::to_string(radii.size()) + " radii");
  std::vector<std::array<int, 2>> pairs;
  if (centres.size() < 2) return pairs;
  const double max_radius = *std::max_element(radii.begin(), radii.end());
  // Two particles overlap by more than min_overlap only if their centres are closer than
  // r_i + r_j - min_overlap <= 2 r_max - min_overlap: that is the search cutoff and the
  // cell size (one-cell stencil).
  const double cutoff = 2.0 * max_radius - min_overlap;
  if (!(cutoff > 0.0)) return pairs;
  const NeighbourGrid<Dim> grid(centres, cutoff);
  grid.ForEachPairWithin(cutoff, [&](int i, int j) {
    const double gap = (centres[j] - centres[i]).norm() - radii[i] - radii[j];
    if (gap < -min_overlap) pairs.push_back({i, j});
  });
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

template std::vector<std::array<int, 2>> OverlappingPairs<2>(const std::vector<Vector<2>>&,
                                                             const std::vector<double>&, double);
template std::vector<std::array<int, 2>> OverlappingPairs<3>(const std::vector<Vector<3>>&,
                                                             const std::vector<double>&, double);

}  // namespace specimen
