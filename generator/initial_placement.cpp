#include "generator/initial_placement.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "common/error.h"
#include "generator/contact_graph.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Uniform sample in the spherical shell spacing <= |d| < 2 spacing.
template <int Dim>
Vector<Dim> SampleShell(double spacing, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  Vector<Dim> direction;
  do {
    for (int k = 0; k < Dim; ++k) direction[k] = normal(rng);
  } while (direction.squaredNorm() < 1e-12);
  direction.normalize();
  // Radius with density proportional to r^(Dim-1) on [spacing, 2 spacing].
  const double lo = std::pow(spacing, Dim), hi = std::pow(2.0 * spacing, Dim);
  const double radius = std::pow(lo + (hi - lo) * unit(rng), 1.0 / Dim);
  return radius * direction;
}

}  // namespace

template <int Dim>
std::vector<Vector<Dim>> PoissonDiscSample(const Domain<Dim>& domain, double spacing,
                                           double boundary_margin, std::mt19937_64& rng) {
  const Vector<Dim> lower = domain.Lower();
  const Vector<Dim> extent = domain.Upper() - lower;
  const double cell = spacing / std::sqrt(static_cast<double>(Dim));
  Eigen::Matrix<long, Dim, 1> cells;
  long total_cells = 1;
  for (int k = 0; k < Dim; ++k) {
    cells[k] = std::max<long>(1, static_cast<long>(std::ceil(extent[k] / cell)));
    total_cells *= cells[k];
  }
  if (total_cells > 400000000L)
    throw InputError("the requested particle size is too small for this domain (more than 4e8 "
                     "sampling cells); use a larger mean radius or fewer particles");
  std::vector<int> grid(static_cast<size_t>(total_cells), -1);
  auto cell_of = [&](const Vector<Dim>& x) {
    Eigen::Matrix<long, Dim, 1> c;
    for (int k = 0; k < Dim; ++k)
      c[k] = std::clamp<long>(static_cast<long>((x[k] - lower[k]) / cell), 0, cells[k] - 1);
    return c;
  };
  auto flat = [&](const Eigen::Matrix<long, Dim, 1>& c) {
    long index = 0;
    for (int k = Dim - 1; k >= 0; --k) index = index * cells[k] + c[k];
    return index;
  };

  std::vector<Vector<Dim>> points;
  std::vector<int> active;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto acceptable = [&](const Vector<Dim>& x) {
    if (domain.SignedDistance(x) < boundary_margin) return false;
    const auto c = cell_of(x);
    Eigen::Matrix<long, Dim, 1> lo, hi;
    for (int k = 0; k < Dim; ++k) {
      lo[k] = std::max<long>(0, c[k] - 2);
      hi[k] = std::min<long>(cells[k] - 1, c[k] + 2);
    }
    Eigen::Matrix<long, Dim, 1> q = lo;
    while (true) {
      const int other = grid[flat(q)];
      if (other >= 0 && (points[other] - x).squaredNorm() < spacing * spacing) return false;
      int k = 0;
      while (k < Dim && ++q[k] > hi[k]) q[k] = lo[k], ++k;
      if (k == Dim) break;
    }
    return true;
  };
  auto accept = [&](const Vector<Dim>& x) {
    grid[flat(cell_of(x))] = static_cast<int>(points.size());
    active.push_back(static_cast<int>(points.size()));
    points.push_back(x);
  };

  // Seed points: random positions inside, until one is accepted.
  for (int attempt = 0; attempt < 100000 && points.empty(); ++attempt) {
    Vector<Dim> x;
    for (int k = 0; k < Dim; ++k) x[k] = lower[k] + extent[k] * unit(rng);
    if (acceptable(x)) accept(x);
  }
  if (points.empty())
    throw InputError("the domain is too small for the requested particle size: no node fits");

  constexpr int kAttempts = 30;  // Bridson's k
  while (!active.empty()) {
    const size_t pick = static_cast<size_t>(unit(rng) * active.size()) % active.size();
    const Vector<Dim> origin = points[active[pick]];
    bool found = false;
    for (int attempt = 0; attempt < kAttempts; ++attempt) {
      const Vector<Dim> x = origin + SampleShell<Dim>(spacing, rng);
      if (acceptable(x)) {
        accept(x);
        found = true;
        break;
      }
    }
    if (!found) {
      active[pick] = active.back();
      active.pop_back();
    }
  }
  return points;
}

template <int Dim>
std::vector<Vector<Dim>> PoissonDiscSampleWithCount(const Domain<Dim>& domain, int target_count,
                                                    std::mt19937_64& rng) {
  if (target_count < 1) throw InputError("particle count must be >= 1");
  // Maximal Poisson-disc sets cover about this fraction of space with spheres of
  // diameter `spacing` (measured: ~0.70 in 2D, ~0.48 in 3D); only a first guess.
  const double fill = Dim == 2 ? 0.70 : 0.48;
  const double unit_ball = Dim == 2 ? kPi / 4.0 : kPi / 6.0;  // volume of a unit-diameter ball
  double spacing = std::pow(fill * domain.Volume() / (unit_ball * target_count), 1.0 / Dim);
  std::vector<Vector<Dim>> points;
  for (int pass = 0; pass < 4; ++pass) {
    std::mt19937_64 trial_rng = rng;  // every pass starts from the same state: repeatable
    points = PoissonDiscSample<Dim>(domain, spacing, 0.5 * spacing, trial_rng);
    const double ratio = static_cast<double>(points.size()) / target_count;
    if (pass == 3 || std::abs(ratio - 1.0) < 0.01) {
      rng = trial_rng;
      break;
    }
    spacing *= std::pow(ratio, 1.0 / Dim);
  }
  return points;
}

template <int Dim>
std::vector<double> StienenRadii(const Domain<Dim>& domain, const std::vector<Vector<Dim>>& nodes,
                                 double factor_min, double factor_max, double radius_min,
                                 double radius_max, std::mt19937_64& rng) {
  const int n = static_cast<int>(nodes.size());
  std::vector<std::vector<double>> distances(n);
  const ContactGraph<Dim> graph =
      BuildContactGraph<Dim>(domain, nodes, std::vector<double>(n, 0.0), 0.0);
  for (const auto& e : graph.edges) {
    const double d = (nodes[e[0]] - nodes[e[1]]).norm();
    distances[e[0]].push_back(d);
    distances[e[1]].push_back(d);
  }
  std::uniform_real_distribution<double> factor(factor_min, factor_max);
  std::vector<double> radii(n);
  for (int i = 0; i < n; ++i) {
    // Mean over the nearer half of the Delaunay neighbours: nodes on the hull also have
    // long, nearly flat hull edges that say nothing about the local spacing.
    auto& d = distances[i];
    std::sort(d.begin(), d.end());
    const size_t used = std::max<size_t>(1, d.size() / 2);
    double sum = 0.0;
    for (size_t k = 0; k < used && k < d.size(); ++k) sum += d[k];
    const double mean_distance = d.empty() ? 2.0 * radius_min : sum / used;
    radii[i] = std::clamp(0.5 * mean_distance * factor(rng), radius_min, radius_max);
  }
  return radii;
}

template std::vector<Vector<2>> PoissonDiscSample<2>(const Domain<2>&, double, double,
                                                     std::mt19937_64&);
template std::vector<Vector<3>> PoissonDiscSample<3>(const Domain<3>&, double, double,
                                                     std::mt19937_64&);
template std::vector<Vector<2>> PoissonDiscSampleWithCount<2>(const Domain<2>&, int,
                                                              std::mt19937_64&);
template std::vector<Vector<3>> PoissonDiscSampleWithCount<3>(const Domain<3>&, int,
                                                              std::mt19937_64&);
template std::vector<double> StienenRadii<2>(const Domain<2>&, const std::vector<Vector<2>>&,
                                             double, double, double, double, std::mt19937_64&);
template std::vector<double> StienenRadii<3>(const Domain<3>&, const std::vector<Vector<3>>&,
                                             double, double, double, double, std::mt19937_64&);

}  // namespace specimen
