#include "generator/initial_placement.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "generator/contact_graph.h"
#include "generator/packing.h"

namespace specimen {
namespace {

// Incremental uniform grid for RSA: per-cell singly linked lists in flat arrays.
template <int Dim>
class InsertionGrid {
 public:
  InsertionGrid(const Vector<Dim>& lower, const Vector<Dim>& upper, double cell_size, int capacity)
      : lower_(lower), cell_size_(cell_size) {
    long total = 1;
    for (int k = 0; k < Dim; ++k) {
      cells_[k] = std::max<long>(1, static_cast<long>(std::ceil((upper[k] - lower[k]) / cell_size)));
      total *= cells_[k];
    }
    if (total > 200000000L)
      throw InputError("the requested particle size is too small for this domain (more than "
                       "2e8 search cells); use a larger mean radius or fewer particles");
    head_.assign(static_cast<size_t>(total), -1);
    next_.reserve(capacity);
  }

  void Insert(const Vector<Dim>& x, int index) {
    const long cell = Flat(CellOf(x));
    if (static_cast<int>(next_.size()) <= index) next_.resize(index + 1, -1);
    next_[index] = head_[cell];
    head_[cell] = index;
  }

  // visit(j) for the points in the cells within one cell of x's cell.
  template <typename Visit>
  bool AnyNear(const Vector<Dim>& x, Visit&& visit) const {
    const auto c = CellOf(x);
    Eigen::Matrix<long, Dim, 1> lo, hi, q;
    for (int k = 0; k < Dim; ++k) {
      lo[k] = std::max<long>(0, c[k] - 1);
      hi[k] = std::min<long>(cells_[k] - 1, c[k] + 1);
    }
    q = lo;
    while (true) {
      for (int j = head_[Flat(q)]; j >= 0; j = next_[j])
        if (visit(j)) return true;
      int k = 0;
      while (k < Dim && ++q[k] > hi[k]) q[k] = lo[k], ++k;
      if (k == Dim) return false;
    }
  }

 private:
  Eigen::Matrix<long, Dim, 1> CellOf(const Vector<Dim>& x) const {
    Eigen::Matrix<long, Dim, 1> c;
    for (int k = 0; k < Dim; ++k)
      c[k] = std::clamp<long>(static_cast<long>((x[k] - lower_[k]) / cell_size_), 0, cells_[k] - 1);
    return c;
  }
  long Flat(const Eigen::Matrix<long, Dim, 1>& c) const {
    long index = 0;
    for (int k = Dim - 1; k >= 0; --k) index = index * cells_[k] + c[k];
    return index;
  }

  Vector<Dim> lower_;
  double cell_size_;
  Eigen::Matrix<long, Dim, 1> cells_;
  std::vector<int> head_;
  std::vector<int> next_;
};

}  // namespace

double PowerLawSize(double spread, double exponent, double u) {
  if (spread <= 1.0) return 1.0;
  const double a = 1.0 - exponent;
  if (std::abs(a) < 1e-12) return std::pow(spread, u);  // log-uniform
  return std::pow(1.0 + u * (std::pow(spread, a) - 1.0), 1.0 / a);
}

double PowerLawMoment(double spread, double exponent, double k) {
  if (spread <= 1.0) return 1.0;
  // integral of s^p over [1, spread]
  auto integral = [&](double p) {
    return std::abs(p + 1.0) < 1e-12 ? std::log(spread) : (std::pow(spread, p + 1.0) - 1.0) / (p + 1.0);
  };
  return integral(k - exponent) / integral(-exponent);
}

template <int Dim>
NodeSet<Dim> RandomSequentialNodes(const Domain<Dim>& domain, int target_count, double size_spread,
                                   double size_exponent, double fill_fraction, int attempts_per_node,
                                   std::mt19937_64& rng) {
  if (target_count < 1) throw InputError("particle count must be >= 1");
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> sizes(static_cast<size_t>(target_count));
  for (double& s : sizes) s = PowerLawSize(size_spread, size_exponent, unit(rng));
  double volume = 0.0;
  for (double s : sizes) volume += ParticleVolume<Dim>(s);
  const double scale = std::pow(fill_fraction * domain.Volume() / volume, 1.0 / Dim);
  for (double& s : sizes) s *= scale;
  std::sort(sizes.begin(), sizes.end(), std::greater<double>());  // largest first

  const Vector<Dim> lower = domain.Lower();
  const Vector<Dim> extent = domain.Upper() - lower;
  NodeSet<Dim> nodes;
  nodes.positions.reserve(sizes.size());
  nodes.exclusion_radii.reserve(sizes.size());
  InsertionGrid<Dim> grid(lower, domain.Upper(), 2.0 * sizes.front(), target_count);
  for (double radius : sizes) {
    for (int attempt = 0; attempt < attempts_per_node; ++attempt) {
      Vector<Dim> x;
      for (int k = 0; k < Dim; ++k) x[k] = lower[k] + extent[k] * unit(rng);
      if (domain.SignedDistance(x) < radius) continue;
      const bool blocked = grid.AnyNear(x, [&](int j) {
        const double reach = radius + nodes.exclusion_radii[j];
        return (nodes.positions[j] - x).squaredNorm() < reach * reach;
      });
      if (blocked) continue;
      grid.Insert(x, static_cast<int>(nodes.positions.size()));
      nodes.positions.push_back(x);
      nodes.exclusion_radii.push_back(radius);
      break;
    }
  }
  if (nodes.positions.size() < 2)
    throw InputError("the domain is too small for the requested particle size: fewer than two "
                     "particles fit");
  return nodes;
}

template <int Dim>
std::vector<double> StienenRadii(const Domain<Dim>& domain, const NodeSet<Dim>& nodes,
                                 double factor_min, double factor_max, double radius_min,
                                 double radius_max, std::mt19937_64& rng) {
  const auto& x = nodes.positions;
  const auto& rho = nodes.exclusion_radii;
  const int n = static_cast<int>(x.size());
  std::vector<std::vector<double>> shares(n);
  const ContactGraph<Dim> graph = BuildContactGraph<Dim>(domain, x, rho, 0.0);
  for (const auto& e : graph.edges) {
    const double d = (x[e[0]] - x[e[1]]).norm();
    const double total = rho[e[0]] + rho[e[1]];
    shares[e[0]].push_back(d * rho[e[0]] / total);
    shares[e[1]].push_back(d * rho[e[1]] / total);
  }
  std::uniform_real_distribution<double> factor(factor_min, factor_max);
  std::vector<double> radii(n);
  for (int i = 0; i < n; ++i) {
    // The nearer half of the neighbours only: nodes on the hull also have long, nearly
    // flat hull edges that say nothing about the local spacing.
    auto& s = shares[i];
    std::sort(s.begin(), s.end());
    const size_t used = std::max<size_t>(1, s.size() / 2);
    double sum = 0.0;
    for (size_t k = 0; k < used && k < s.size(); ++k) sum += s[k];
    const double share = s.empty() ? rho[i] : sum / used;
    radii[i] = std::clamp(share * factor(rng), radius_min, radius_max);
  }
  return radii;
}

template NodeSet<2> RandomSequentialNodes<2>(const Domain<2>&, int, double, double, double, int,
                                             std::mt19937_64&);
template NodeSet<3> RandomSequentialNodes<3>(const Domain<3>&, int, double, double, double, int,
                                             std::mt19937_64&);
template std::vector<double> StienenRadii<2>(const Domain<2>&, const NodeSet<2>&, double, double,
                                             double, double, std::mt19937_64&);
template std::vector<double> StienenRadii<3>(const Domain<3>&, const NodeSet<3>&, double, double,
                                             double, double, std::mt19937_64&);

}  // namespace specimen
