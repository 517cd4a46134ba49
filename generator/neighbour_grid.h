#pragma once
// A uniform cell list over particle centres: the neighbour search behind the overlap
// statistics and the overlap-corrected porosity. Centres are bucketed by a counting sort
// into flat arrays (cell offsets + particle indices + a copy of the coordinates in cell
// order), so memory is O(N + cells) with no per-cell allocation, and a sweep over the
// cells touches memory in order.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "common/error.h"
#include "generator/domain.h"

namespace specimen {

template <int Dim>
class NeighbourGrid {
 public:
  // Buckets `centres` into cubic cells of edge `cell_size` (> 0) over their bounding box.
  // When the box would need more than max(64, 2 N) cells (very sparse sets) the cells are
  // enlarged so that memory stays O(N); cell_size() returns the size actually used.
  NeighbourGrid(const std::vector<Vector<Dim>>& centres, double cell_size);

  // Calls visit(i, j) exactly once for every pair i < j with |x_i - x_j| < cutoff. The
  // search is cheapest for cutoff <= cell_size(); a larger cutoff widens the cell stencil.
  template <class Visit>
  void ForEachPairWithin(double cutoff, Visit&& visit) const;

  // Calls visit(j) for every centre with |x - x_j| < cutoff.
  template <class Visit>
  void ForEachNear(const Vector<Dim>& x, double cutoff, Visit&& visit) const;

  double cell_size() const { return cell_size_; }
  int particle_count() const { return static_cast<int>(particle_index_.size()); }
  std::int64_t cell_count() const { return static_cast<std::int64_t>(cell_start_.size()) - 1; }

 private:
  using Cell = std::array<int, Dim>;

  // Cell coordinate of x along `axis`, not clamped.
  double CellCoordinate(double x, int axis) const {
    return std::floor((x - lower_[axis]) / cell_size_);
  }
  std::int64_t LinearIndex(const Cell& cell) const {
    std::int64_t index = 0;
    for (int axis = Dim - 1; axis >= 0; --axis) index = index * cells_per_axis_[axis] + cell[axis];
    return index;
  }
  // Squared distance between sorted entries a and b.
  double SortedDistanceSquared(int a, int b) const {
    double sum = 0.0;
    for (int axis = 0; axis < Dim; ++axis) {
      const double d = sorted_coordinates_[Dim * a + axis] - sorted_coordinates_[Dim * b + axis];
      sum += d * d;
    }
    return sum;
  }

  double cell_size_ = 1.0;
  Vector<Dim> lower_ = Vector<Dim>::Zero();
  Cell cells_per_axis_{};
  std::vector<int> cell_start_;             // cell c holds sorted entries [start[c], start[c+1])
  std::vector<int> particle_index_;         // sorted entry -> particle index
  std::vector<double> sorted_coordinates_;  // Dim coordinates per sorted entry
};

// All pairs i < j whose gap |x_j - x_i| - r_i - r_j is below -min_overlap (overlapping by
// more than min_overlap; min_overlap = 0 gives every overlapping pair), sorted.
template <int Dim>
std::vector<std::array<int, 2>> OverlappingPairs(const std::vector<Vector<Dim>>& centres,
                                                 const std::vector<double>& radii,
                                                 double min_overlap = 0.0);

// ---------------------------------------------------------------------------------------
// Implementation.

template <int Dim>
NeighbourGrid<Dim>::NeighbourGrid(const std::vector<Vector<Dim>>& centres, double cell_size) {
  if (!(cell_size > 0.0) || !std::isfinite(cell_size))
    throw InputError("neighbour grid cell_size = " + std::to_string(cell_size) +
                     " is not allowed: it must be finite and > 0");
  const int count = static_cast<int>(centres.size());
  cell_size_ = cell_size;
  cells_per_axis_.fill(1);
  if (count == 0) {
    cell_start_.assign(2, 0);
    return;
  }
  Vector<Dim> upper = centres[0];
  lower_ = centres[0];
  for (const auto& x : centres) {
    for (int axis = 0; axis < Dim; ++axis)
      if (!std::isfinite(x[axis]))
        throw InputError("neighbour grid: a particle centre is not a finite number");
    lower_ = lower_.cwiseMin(x);
    upper = upper.cwiseMax(x);
  }
  // Enlarge the cells until the grid has at most max(64, 2N) of them (O(N) memory).
  const double max_cells = std::max(64.0, 2.0 * count);
  for (;;) {
    double total = 1.0;
    for (int axis = 0; axis < Dim; ++axis)
      total *= std::floor((upper[axis] - lower_[axis]) / cell_size_) + 1.0;
    if (total <= max_cells) break;
    cell_size_ *= std::pow(total / max_cells, 1.0 / Dim) * 1.001;
  }
  std::int64_t total_cells = 1;
  for (int axis = 0; axis < Dim; ++axis) {
    cells_per_axis_[axis] =
        static_cast<int>(std::floor((upper[axis] - lower_[axis]) / cell_size_)) + 1;
    total_cells *= cells_per_axis_[axis];
  }

  // Counting sort by cell: count, prefix sum, place.
  std::vector<std::int64_t> cell_of(count);
  cell_start_.assign(static_cast<size_t>(total_cells) + 1, 0);
  for (int i = 0; i < count; ++i) {
    Cell cell;
    for (int axis = 0; axis < Dim; ++axis)
      cell[axis] = std::clamp(static_cast<int>(CellCoordinate(centres[i][axis], axis)), 0,
                              cells_per_axis_[axis] - 1);
    cell_of[i] = LinearIndex(cell);
    ++cell_start_[cell_of[i] + 1];
  }
  for (std::int64_t c = 0; c < total_cells; ++c) cell_start_[c + 1] += cell_start_[c];
  std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
  particle_index_.resize(count);
  sorted_coordinates_.resize(static_cast<size_t>(count) * Dim);
  for (int i = 0; i < count; ++i) {
    const int slot = fill[cell_of[i]]++;
    particle_index_[slot] = i;
    for (int axis = 0; axis < Dim; ++axis)
      sorted_coordinates_[Dim * slot + axis] = centres[i][axis];
  }
}

template <int Dim>
template <class Visit>
void NeighbourGrid<Dim>::ForEachPairWithin(double cutoff, Visit&& visit) const {
  if (!(cutoff > 0.0) || particle_index_.size() < 2) return;
  const double cutoff_squared = cutoff * cutoff;
  const int reach = std::max(1, static_cast<int>(std::ceil(cutoff / cell_size_)));

  // Half stencil: offsets whose last non-zero component is positive, so each unordered
  // pair of distinct cells is visited from exactly one side.
  std::vector<Cell> offsets;
  {
    Cell offset;
    offset.fill(-reach);
    for (;;) {
      int last_nonzero = 0;
      for (int axis = Dim - 1; axis >= 0; --axis)
        if (offset[axis] != 0) {
          last_nonzero = offset[axis];
          break;
        }
      if (last_nonzero > 0) offsets.push_back(offset);
      int axis = 0;
      while (axis < Dim && ++offset[axis] > reach) offset[axis++] = -reach;
      if (axis == Dim) break;
    }
  }

  auto emit = [&](int a, int b) {
    if (SortedDistanceSquared(a, b) < cutoff_squared) {
      const int i = particle_index_[a], j = particle_index_[b];
      if (i < j)
        visit(i, j);
      else
        visit(j, i);
    }
  };

  Cell cell;
  cell.fill(0);
  for (std::int64_t c = 0; c + 1 < static_cast<std::int64_t>(cell_start_.size()); ++c) {
    const int begin = cell_start_[c], end = cell_start_[c + 1];
    if (begin < end) {
      for (int a = begin; a < end; ++a)
        for (int b = a + 1; b < end; ++b) emit(a, b);
      for (const Cell& offset : offsets) {
        Cell other;
        bool inside = true;
        for (int axis = 0; axis < Dim && inside; ++axis) {
          other[axis] = cell[axis] + offset[axis];
          inside = other[axis] >= 0 && other[axis] < cells_per_axis_[axis];
        }
        if (!inside) continue;
        const std::int64_t o = LinearIndex(other);
        const int other_begin = cell_start_[o], other_end = cell_start_[o + 1];
        for (int a = begin; a < end; ++a)
          for (int b = other_begin; b < other_end; ++b) emit(a, b);
      }
    }
    // Advance the cell coordinates in step with the linear index (axis 0 fastest).
    int axis = 0;
    while (axis < Dim && ++cell[axis] == cells_per_axis_[axis]) cell[axis++] = 0;
  }
}

template <int Dim>
template <class Visit>
void NeighbourGrid<Dim>::ForEachNear(const Vector<Dim>& x, double cutoff, Visit&& visit) const {
  if (!(cutoff > 0.0) || particle_index_.empty()) return;
  Cell first, last;
  for (int axis = 0; axis < Dim; ++axis) {
    const double low = CellCoordinate(x[axis] - cutoff, axis);
    const double high = CellCoordinate(x[axis] + cutoff, axis);
    if (high < 0.0 || low > cells_per_axis_[axis] - 1.0) return;  // entirely off the grid
    first[axis] = static_cast<int>(std::max(low, 0.0));
    last[axis] = static_cast<int>(std::min(high, cells_per_axis_[axis] - 1.0));
  }
  const double cutoff_squared = cutoff * cutoff;
  Cell cell = first;
  for (;;) {
    const std::int64_t c = LinearIndex(cell);
    for (int a = cell_start_[c]; a < cell_start_[c + 1]; ++a) {
      double sum = 0.0;
      for (int axis = 0; axis < Dim; ++axis) {
        const double d = sorted_coordinates_[Dim * a + axis] - x[axis];
        sum += d * d;
      }
      if (sum < cutoff_squared) visit(particle_index_[a]);
    }
    int axis = 0;
    while (axis < Dim && ++cell[axis] > last[axis]) {
      cell[axis] = first[axis];
      ++axis;
    }
    if (axis == Dim) break;
  }
}

}  // namespace specimen
