#include "solver/neighbour_search.h"

#include <algorithm>
#include <cmath>

namespace specimen {

template <int Dim>
void CandidateSearch<Dim>::FindPairs(const std::vector<Vector<Dim>>& position,
                                     const std::vector<double>& radius, double margin,
                                     std::vector<std::array<int, 2>>* pairs) {
  pairs->clear();
  const int count = static_cast<int>(position.size());
  if (count < 2) return;
  double max_radius = 0.0;
  Vector<Dim> lower = position[0], upper = position[0];
  for (int i = 0; i < count; ++i) {
    max_radius = std::max(max_radius, radius[i]);
    lower = lower.cwiseMin(position[i]);
    upper = upper.cwiseMax(position[i]);
  }
  // One cell reaches the largest possible partner: 2 r_max + margin. Very spread sets get
  // larger cells so that the grid has at most max(64, 2N) cells (O(N) memory).
  double cell_size = 2.0 * max_radius + margin;
  const double max_cells = std::max(64.0, 2.0 * count);
  for (;;) {
    double total = 1.0;
    for (int axis = 0; axis < Dim; ++axis)
      total *= std::floor((upper[axis] - lower[axis]) / cell_size) + 1.0;
    if (total <= max_cells) break;
    cell_size *= std::pow(total / max_cells, 1.0 / Dim) * 1.001;
  }
  std::int64_t total_cells = 1;
  for (int axis = 0; axis < Dim; ++axis) {
    cells_per_axis_[axis] =
        static_cast<int>(std::floor((upper[axis] - lower[axis]) / cell_size)) + 1;
    total_cells *= cells_per_axis_[axis];
  }

  // Counting sort of the particles by cell.
  cell_of_.resize(count);
  cell_start_.assign(static_cast<size_t>(total_cells) + 1, 0);
  for (int i = 0; i < count; ++i) {
    Cell cell;
    for (int axis = 0; axis < Dim; ++axis)
      cell[axis] = std::clamp(static_cast<int>((position[i][axis] - lower[axis]) / cell_size), 0,
                              cells_per_axis_[axis] - 1);
    cell_of_[i] = Linear(cell);
    ++cell_start_[cell_of_[i] + 1];
  }
  for (std::int64_t c = 0; c < total_cells; ++c) cell_start_[c + 1] += cell_start_[c];
  fill_.assign(cell_start_.begin(), cell_start_.end() - 1);
  sorted_particle_.resize(count);
  for (int i = 0; i < count; ++i) sorted_particle_[fill_[cell_of_[i]]++] = i;

  // Half stencil: neighbour offsets whose last non-zero component is positive, so every
  // pair of distinct cells is visited once.
  if (half_stencil_.empty()) {
    Cell offset;
    offset.fill(-1);
    for (;;) {
      int last = 0;
      for (int axis = Dim - 1; axis >= 0; --axis)
        if (offset[axis] != 0) {
          last = offset[axis];
          break;
        }
      if (last > 0) half_stencil_.push_back(offset);
      int axis = 0;
      while (axis < Dim && ++offset[axis] > 1) offset[axis++] = -1;
      if (axis == Dim) break;
    }
  }

  auto test = [&](int a, int b) {
    const double reach = radius[a] + radius[b] + margin;
    if ((position[b] - position[a]).squaredNorm() < reach * reach)
      pairs->push_back(a < b ? std::array<int, 2>{a, b} : std::array<int, 2>{b, a});
  };
  Cell cell;
  cell.fill(0);
  for (std::int64_t c = 0; c < total_cells; ++c) {
    const int begin = cell_start_[c], end = cell_start_[c + 1];
    if (begin < end) {
      for (int a = begin; a < end; ++a)
        for (int b = a + 1; b < end; ++b) test(sorted_particle_[a], sorted_particle_[b]);
      for (const Cell& offset : half_stencil_) {
        Cell other;
        bool inside = true;
        for (int axis = 0; axis < Dim && inside; ++axis) {
          other[axis] = cell[axis] + offset[axis];
          inside = other[axis] >= 0 && other[axis] < cells_per_axis_[axis];
        }
        if (!inside) continue;
        const std::int64_t o = Linear(other);
        for (int a = begin; a < end; ++a)
          for (int b = cell_start_[o]; b < cell_start_[o + 1]; ++b)
            test(sorted_particle_[a], sorted_particle_[b]);
      }
    }
    int axis = 0;
    while (axis < Dim && ++cell[axis] == cells_per_axis_[axis]) cell[axis++] = 0;
  }
  std::sort(pairs->begin(), pairs->end());
}

template class CandidateSearch<2>;
template class CandidateSearch<3>;

}  // namespace specimen
