#include "generator/compaction.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>

#include "generator/neighbour_grid.h"

namespace specimen {
namespace {

// Candidate pairs (gap below the skin) and the particles near the boundary, valid while
// no gap has closed by more than the skin since they were collected.
template <int Dim>
struct VerletList {
  std::vector<std::array<int, 2>> pairs;
  std::vector<int> near_boundary;
  std::vector<Vector<Dim>> centres_at_build;
  double scale_at_build = 1.0;
};

template <int Dim>
void BuildVerletList(const Domain<Dim>& domain, const std::vector<Vector<Dim>>& x,
                     const std::vector<double>& r, double scale, double skin,
                     VerletList<Dim>* list) {
  const double largest = *std::max_element(r.begin(), r.end());
  const double cutoff = 2.0 * largest + skin;
  list->pairs.clear();
  NeighbourGrid<Dim> grid(x, cutoff);
  grid.ForEachPairWithin(cutoff, [&](int i, int j) {
    if ((x[i] - x[j]).norm() - r[i] - r[j] < skin) list->pairs.push_back({i, j});
  });
  // The grid visits cells in order: sort for a sweep order independent of the grid shape.
  std::sort(list->pairs.begin(), list->pairs.end());
  list->near_boundary.clear();
  for (size_t i = 0; i < x.size(); ++i)
    if (domain.SignedDistance(x[i]) < r[i] + skin)
      list->near_boundary.push_back(static_cast<int>(i));
  list->centres_at_build = x;
  list->scale_at_build = scale;
}

// One Gauss-Seidel sweep of the force-biased relaxation; returns the largest overlap or
// protrusion met (before its correction). `reference` is the largest overlap of the
// previous sweep (the exponent's normalisation).
template <int Dim>
double RelaxationSweep(const Domain<Dim>& domain, const VerletList<Dim>& list, double exponent,
                       double reference, std::vector<Vector<Dim>>& x,
                       const std::vector<double>& r) {
  double worst = 0.0;
  const bool power = std::abs(exponent - 1.0) > 1e-12;
  auto amount = [&](double overlap) {
    if (!power || reference <= 0.0) return overlap;
    return overlap * std::min(1.0, std::pow(overlap / reference, exponent - 1.0));
  };
  for (const auto& p : list.pairs) {
    const int i = p[0], j = p[1];
    Vector<Dim> d = x[j] - x[i];
    const double distance = d.norm();
    const double overlap = r[i] + r[j] - distance;
    if (overlap <= 0.0 || distance <= 0.0) continue;
    worst = std::max(worst, overlap);
    d /= distance;
    // Shares in inverse proportion to the radii: the small particle moves most.
    const double move = amount(overlap) / (r[i] + r[j]);
    x[i] -= d * (move * r[j]);
    x[j] += d * (move * r[i]);
  }
  const auto& facets = domain.Facets();
  for (int i : list.near_boundary) {
    for (const auto& facet : facets) {
      if (!domain.FacetApplies(facet, x[i])) continue;
      const double protrusion = r[i] - domain.FacetDistance(facet, x[i]);
      if (protrusion <= 0.0) continue;
      worst = std::max(worst, protrusion);
      x[i] += domain.FacetDistanceGradient(facet, x[i]) * protrusion;
    }
  }
  return worst;
}

}  // namespace

template <int Dim>
CompactionSummary CompactPacking(const Domain<Dim>& domain, const CompactionOptions& options,
                                 std::vector<Vector<Dim>>& x, std::vector<double>& r) {
  const auto start = std::chrono::steady_clock::now();
  CompactionSummary summary;
  if (x.size() < 2) return summary;
  const double skin = options.skin * options.length_scale;
  const double largest_base = *std::max_element(r.begin(), r.end());
  const std::vector<double> base = r;
  double scale = 1.0;
  auto set_radii = [&](double s) {
    scale = s;
    for (size_t i = 0; i < r.size(); ++i) r[i] = base[i] * s;
  };

  VerletList<Dim> list;
  double moved = 0.0;  // largest displacement since the list was built
  auto ensure_list = [&] {
    moved = 0.0;
    if (!list.centres_at_build.empty())
      for (size_t i = 0; i < x.size(); ++i)
        moved = std::max(moved, (x[i] - list.centres_at_build[i]).norm());
    const double closing = 2.0 * moved + 2.0 * largest_base * (scale - list.scale_at_build);
    if (list.centres_at_build.empty() || closing > skin) {
      BuildVerletList<Dim>(domain, x, r, scale, skin, &list);
      ++summary.neighbour_rebuilds;
      moved = 0.0;
    }
  };
  double reference = 0.0;  // largest overlap of the previous sweep
  auto sweep = [&] {
    ensure_list();
    reference = std::max(RelaxationSweep<Dim>(domain, list, options.exponent, reference, x, r),
                         1e-9 * options.length_scale);
    ++summary.sweeps;
  };
  // Inner scale: the largest common radius factor at which no pair overlaps and no particle
  // protrudes, at the current centres; at most as far as the list vouches for.
  auto inner_scale = [&] {
    ensure_list();
    double s_in = list.scale_at_build + (skin - 2.0 * moved) / (2.0 * largest_base);
    for (const auto& p : list.pairs)
      s_in = std::min(s_in, (x[p[0]] - x[p[1]]).norm() / (base[p[0]] + base[p[1]]));
    for (int i : list.near_boundary) s_in = std::min(s_in, domain.SignedDistance(x[i]) / base[i]);
    return s_in;
  };

  // Jodrey-Tory schedule of the force-biased algorithm: the outer scale starts above what
  // fits and contracts towards the inner scale, which rises as the sweeps rearrange the
  // packing; they meet at a jammed packing.
  const std::vector<Vector<Dim>> input = x;
  const double input_inner = inner_scale();
  double outer = std::max(1.0, input_inner) * (1.0 + options.initial_growth);
  double inner = input_inner;
  // Where the current contraction started: a run that meets the inner scale before the
  // outer one has come down half way was not jammed, and is inflated again.
  double outer_start = outer, inner_start = inner;
  while (summary.sweeps < options.max_sweeps) {
    set_radii(outer);
    sweep();
    inner = inner_scale();
    if (inner >= outer || outer - inner < options.tolerance * inner) {
      if (outer_start - outer >= 0.5 * (outer_start - inner_start)) break;  // jammed
      outer = outer_start = std::max(outer, inner) * (1.0 + options.initial_growth);
      inner_start = inner;
      continue;
    }
    outer -= options.contraction * (outer - inner);
  }
  // Never give back density: if the schedule ends looser than the input (scaled to fit),
  // the input is kept.
  if (inner <= input_inner) {
    x = input;
    inner = input_inner;
    summary.kept_input = true;
  }
  set_radii(inner);
  summary.growth_factor = inner;
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

template CompactionSummary CompactPacking<2>(const Domain<2>&, const CompactionOptions&,
                                             std::vector<Vector<2>>&, std::vector<double>&);
template CompactionSummary CompactPacking<3>(const Domain<3>&, const CompactionOptions&,
                                             std::vector<Vector<3>>&, std::vector<double>&);

}  // namespace specimen
