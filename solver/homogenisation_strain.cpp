#include "solver/homogenisation_strain.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "common/error.h"
#include "generator/contact_graph.h"

namespace specimen {

template <int Dim>
BagiStrain<Dim>::BagiStrain(const std::vector<Vector<Dim>>& reference_centres,
                            const std::vector<bool>& included)
    : reference_(reference_centres) {
  const int count = static_cast<int>(reference_.size());
  if (count < Dim + 1)
    throw InputError("BagiStrain: " + std::to_string(count) + " centres cannot be triangulated (" +
                     std::to_string(Dim + 1) + " at least)");
  if (!included.empty() && static_cast<int>(included.size()) != count)
    throw InputError("BagiStrain: the region flags have " + std::to_string(included.size()) +
                     " entries for " + std::to_string(count) + " centres");
  // Equal weights: the regular triangulation is the Delaunay triangulation of the centres.
  const std::vector<std::array<int, Dim + 1>> all =
      RegularTriangulationCells<Dim>(reference_, std::vector<double>(count, 0.0));
  std::vector<Vector<Dim>> weight(count, Vector<Dim>::Zero());
  for (const auto& cell : all) {
    if (!included.empty() &&
        !std::all_of(cell.begin(), cell.end(), [&](int p) { return included[p]; }))
      continue;
    double cell_volume = 0.0;
    const auto a = AreaVectors(cell, &cell_volume);
    cells_.push_back(cell);
    volume_ += cell_volume;
    for (int k = 0; k <= Dim; ++k) weight[cell[k]] += a[k];
  }
  if (!(volume_ > 0.0))
    throw InputError("BagiStrain: the region holds no cell of positive volume (" +
                     std::to_string(cells_.size()) + " cells)");
  // Weights of closed stars cancel to round-off; keep the others.
  double scale = 0.0;
  for (const auto& w : weight) scale = std::max(scale, w.norm());
  for (int p = 0; p < count; ++p)
    if (weight[p].norm() > 1e-9 * scale) {
      weighted_vertex_.push_back(p);
      weight_.push_back(weight[p]);
    }
}

template <int Dim>
std::array<Vector<Dim>, Dim + 1> BagiStrain<Dim>::AreaVectors(const std::array<int, Dim + 1>& cell,
                                                               double* cell_volume) const {
  // J = [x_1 - x_0, ..., x_D - x_0]; grad N_k (k >= 1) is row k of J^-1 = adj(J) / det J,
  // so a_k = V_L grad N_k = sign(det J) / D! x row k of adj(J), defined also for flat cells.
  std::array<Vector<Dim>, Dim + 1> a;
  std::array<Vector<Dim>, Dim> e;
  for (int k = 0; k < Dim; ++k) e[k] = reference_[cell[k + 1]] - reference_[cell[0]];
  if constexpr (Dim == 2) {
    const double det = e[0].x() * e[1].y() - e[1].x() * e[0].y();
    const double sign = det >= 0.0 ? 0.5 : -0.5;
    a[1] = sign * Vector<2>(e[1].y(), -e[1].x());
    a[2] = sign * Vector<2>(-e[0].y(), e[0].x());
    *cell_volume = 0.5 * std::abs(det);
  } else {
    const double det = e[0].dot(e[1].cross(e[2]));
    const double sign = det >= 0.0 ? 1.0 / 6.0 : -1.0 / 6.0;
    a[1] = sign * e[1].cross(e[2]);
    a[2] = sign * e[2].cross(e[0]);
    a[3] = sign * e[0].cross(e[1]);
    *cell_volume = std::abs(det) / 6.0;
  }
  a[0] = Vector<Dim>::Zero();
  for (int k = 1; k <= Dim; ++k) a[0] -= a[k];  // (B.1): the area vectors close
  return a;
}

template <int Dim>
typename BagiStrain<Dim>::Matrix BagiStrain<Dim>::DisplacementGradient(
    const std::vector<Vector<Dim>>& current_centres) const {
  if (current_centres.size() != reference_.size())
    throw InputError("BagiStrain: " + std::to_string(current_centres.size()) +
                     " current centres for " + std::to_string(reference_.size()) +
                     " reference centres");
  Matrix sum = Matrix::Zero();
  for (size_t k = 0; k < weighted_vertex_.size(); ++k) {
    const int p = weighted_vertex_[k];
    sum.noalias() += (current_centres[p] - reference_[p]) * weight_[k].transpose();
  }
  return sum / volume_;
}

template <int Dim>
typename BagiStrain<Dim>::Matrix BagiStrain<Dim>::Strain(
    const std::vector<Vector<Dim>>& current_centres) const {
  const Matrix gradient = DisplacementGradient(current_centres);
  return 0.5 * (gradient + gradient.transpose());
}

template <int Dim>
std::vector<typename BagiStrain<Dim>::EdgeVector> BagiStrain<Dim>::ComplementaryAreaVectors()
    const {
  std::map<std::pair<int, int>, Vector<Dim>> edges;
  for (const auto& cell : cells_) {
    double cell_volume = 0.0;
    const auto a = AreaVectors(cell, &cell_volume);
    for (int k = 0; k <= Dim; ++k)
      for (int m = k + 1; m <= Dim; ++m) {
        // (B.3) for the ordered pair (p, q), p < q.
        const bool in_order = cell[k] < cell[m];
        const int p = in_order ? cell[k] : cell[m], q = in_order ? cell[m] : cell[k];
        const Vector<Dim> difference = in_order ? Vector<Dim>(a[k] - a[m]) : Vector<Dim>(a[m] - a[k]);
        auto [it, inserted] = edges.emplace(std::make_pair(p, q), Vector<Dim>::Zero());
        (void)inserted;
        it->second += difference / (Dim + 1);
      }
  }
  std::vector<EdgeVector> result;
  result.reserve(edges.size());
  for (const auto& [pair, d] : edges) result.push_back({pair.first, pair.second, d});
  return result;
}

template class BagiStrain<2>;
template class BagiStrain<3>;

}  // namespace specimen
