#include "calibrate/sweep_grid.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "calibrate/map_sweep.h"

namespace specimen {

SweepGrid::SweepGrid(const SweepDesign& design, const std::vector<SweepPoint>& points) {
  if (design.axes.empty()) return;
  int count = 1;
  for (const SweepAxis& a : design.axes) {
    Axis axis;
    axis.ratio = a.ratio;
    axis.logarithmic = a.geometric;
    for (int k = 0; k < a.levels; ++k) {
      const double v = a.At(a.levels > 1 ? static_cast<double>(k) / (a.levels - 1) : 0.0);
      axis.levels.push_back(a.geometric ? std::log(v) : v);
    }
    if (a.levels < 2 || !(axis.levels.back() > axis.levels.front())) return;
    axes_.push_back(axis);
    count *= a.levels;
  }
  for (int k = static_cast<int>(axes_.size()) - 1, stride = 1; k >= 0; --k) {
    axes_[k].stride = stride;
    stride *= static_cast<int>(axes_[k].levels.size());
  }
  std::vector<double> nodes(count, 0.0);
  std::vector<bool> seen(count, false);
  for (const SweepPoint& p : points) {
    if (!p.ok || !(p.compressive_group > 0.0) || !(p.tensile_group > 0.0) || p.index < 0 || p.index >= count)
      continue;
    nodes[p.index] = std::log(p.compressive_group / p.tensile_group);
    seen[p.index] = true;
  }
  if (std::find(seen.begin(), seen.end(), false) != seen.end()) {
    axes_.clear();
    return;
  }
  nodes_ = std::move(nodes);
}

double SweepGrid::LogGroupRatio(const MicroRatios& ratios) const {
  if (!valid()) return 0.0;
  // Per axis: up to three nodes and their Lagrange weights.
  struct Weights {
    int first = 0, count = 0;
    std::array<double, 3> w{};
  };
  std::vector<Weights> per_axis(axes_.size());
  for (size_t a = 0; a < axes_.size(); ++a) {
    const Axis& axis = axes_[a];
    const std::vector<double>& u = axis.levels;
    const int n = static_cast<int>(u.size());
    const double value = RatioValue(ratios, axis.ratio);
    const double x = std::clamp(axis.logarithmic ? std::log(std::max(value, 1e-300)) : value, u.front(), u.back());
    Weights& w = per_axis[a];
    if (n == 2) {
      const double t = (x - u[0]) / (u[1] - u[0]);
      w.first = 0, w.count = 2, w.w = {1.0 - t, t, 0.0};
      continue;
    }
    int nearest = 0;
    for (int k = 1; k < n; ++k)
      if (std::abs(x - u[k]) < std::abs(x - u[nearest])) nearest = k;
    w.first = std::clamp(nearest - 1, 0, n - 3), w.count = 3;
    const double u0 = u[w.first], u1 = u[w.first + 1], u2 = u[w.first + 2];
    w.w = {(x - u1) * (x - u2) / ((u0 - u1) * (u0 - u2)), (x - u0) * (x - u2) / ((u1 - u0) * (u1 - u2)),
           (x - u0) * (x - u1) / ((u2 - u0) * (u2 - u1))};
  }
  // The tensor product: every combination of the axes' nodes.
  double sum = 0.0;
  std::vector<int> k(axes_.size(), 0);
  while (true) {
    double weight = 1.0;
    int index = 0;
    for (size_t a = 0; a < axes_.size(); ++a) {
      weight *= per_axis[a].w[k[a]];
      index += (per_axis[a].first + k[a]) * axes_[a].stride;
    }
    sum += weight * nodes_[index];
    size_t a = axes_.size();
    while (a > 0 && ++k[a - 1] == per_axis[a - 1].count) k[--a] = 0;
    if (a == 0) break;
  }
  return sum;
}

}  // namespace specimen
