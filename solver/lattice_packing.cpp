#include "solver/lattice_packing.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <sstream>
#include <unordered_map>

#include "common/error.h"
#include "generator/contact_graph.h"
#include "common/format.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;

double SmallestAngleDeg(const Vector<2>& a, const Vector<2>& b, const Vector<2>& c) {
  auto angle = [](const Vector<2>& at, const Vector<2>& p, const Vector<2>& q) {
    const Vector<2> u = p - at, v = q - at;
    return std::atan2(std::abs(u.x() * v.y() - u.y() * v.x()), u.dot(v));
  };
  return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)}) * 180.0 / kPi;
}

std::uint64_t EdgeKey(int i, int j) {
  if (i > j) std::swap(i, j);
  return (static_cast<std::uint64_t>(i) << 32) | static_cast<std::uint32_t>(j);
}

}  // namespace

bool PackingLatticeOptions::IsValid(std::string* error) const {
  if (!(surface_gap >= 0.0 && surface_gap <= 1.0)) {
    *error = "surface_gap = " + Number(surface_gap) + ": must be in [0, 1] (share of the mean radius)";
    return false;
  }
  if (!(min_hull_angle_deg >= 0.0 && min_hull_angle_deg <= 40.0)) {
    *error = "min_hull_angle_deg = " + Number(min_hull_angle_deg) + ": must be in [0, 40] degrees";
    return false;
  }
  return true;
}

std::string PackingLatticeSummary::Describe() const {
  std::ostringstream s;
  s << triangles << " triangles (" << hull_slivers_removed << " hull slivers cut away), " << surface_nodes
    << " surface nodes, " << free_nodes << " nodes in no triangle, smallest angle " << smallest_angle_deg << " deg, area " << covered_area_m2 << " m^2";
  return s.str();
}

TriangleLattice BuildPointLattice(const std::vector<Vector<2>>& centres, const PlaneElasticity& d, double thickness_m,
                                  const PackingLatticeOptions& options, PackingLatticeSummary* summary) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  if (centres.size() < 3) throw InputError("a lattice needs at least 3 nodes");
  const std::vector<std::array<int, 3>> cells =
      RegularTriangulationCells<2>(centres, std::vector<double>(centres.size(), 0.0));  // weights 0: Delaunay
  if (cells.empty()) throw InputError("the lattice nodes are collinear: no triangle");

  const int count = static_cast<int>(cells.size());
  std::vector<double> smallest(count);
  // Each edge's two triangles (-1: the hull side).
  std::unordered_map<std::uint64_t, std::array<int, 2>> sides;
  sides.reserve(3 * cells.size());
  for (int t = 0; t < count; ++t) {
    const auto& v = cells[t];
    smallest[t] = SmallestAngleDeg(centres[v[0]], centres[v[1]], centres[v[2]]);
    for (int k = 0; k < 3; ++k) {
      auto [it, inserted] = sides.try_emplace(EdgeKey(v[k], v[(k + 1) % 3]), std::array<int, 2>{t, -1});
      if (!inserted) it->second[1] = t;
    }
  }
  std::vector<char> alive(count, 1);
  auto across = [&](int t, int k) {
    const auto& s = sides.at(EdgeKey(cells[t][k], cells[t][(k + 1) % 3]));
    const int other = s[0] == t ? s[1] : s[0];
    return other >= 0 && alive[other] ? other : -1;
  };
  auto on_hull = [&](int t) { return across(t, 0) < 0 || across(t, 1) < 0 || across(t, 2) < 0; };

  // Cut hull slivers until the hull holds none; each cut puts the triangles behind it on the queue.
  std::deque<int> queue;
  for (int t = 0; t < count; ++t)
    if (on_hull(t)) queue.push_back(t);
  int removed = 0;
  while (!queue.empty()) {
    const int t = queue.front();
    queue.pop_front();
    if (!alive[t] || smallest[t] >= options.min_hull_angle_deg || !on_hull(t)) continue;
    std::array<int, 3> behind{};
    for (int k = 0; k < 3; ++k) behind[k] = across(t, k);
    alive[t] = 0;
    ++removed;
    for (int n : behind)
      if (n >= 0) queue.push_back(n);
  }

  std::vector<std::array<int, 3>> kept;
  kept.reserve(count - removed);
  std::vector<char> used(centres.size(), 0);
  double smallest_kept = std::numeric_limits<double>::infinity();
  for (int t = 0; t < count; ++t) {
    if (!alive[t]) continue;
    kept.push_back(cells[t]);
    smallest_kept = std::min(smallest_kept, smallest[t]);
    for (int i : cells[t]) used[i] = 1;
  }
  if (kept.empty()) throw InputError("every triangle of the packing is a hull sliver: lower min_hull_angle_deg");
  TriangleLattice lattice = BuildTriangleLattice(centres, kept, d, thickness_m);
  if (summary != nullptr) {
    summary->triangles = lattice.size();
    summary->hull_slivers_removed = removed;
    summary->free_nodes = static_cast<int>(std::count(used.begin(), used.end(), 0));
    summary->smallest_angle_deg = smallest_kept;
    summary->covered_area_m2 = 0.0;
    for (double a : lattice.areas) summary->covered_area_m2 += a;
  }
  return lattice;
}

PackingLattice BuildPackingLattice(const Packing<2>& packing, const PlaneElasticity& d, double thickness_m,
                                   const PackingLatticeOptions& options, PackingLatticeSummary* summary) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  PackingLattice out;
  out.nodes = packing.centres;
  out.particle_nodes = packing.size();
  if (options.surface_nodes && packing.size() > 0) {
    const Domain<2>& domain = packing.domain;
    const double mean_radius = VolumeMeanRadius<2>(packing.radii);
    const auto& facets = domain.Facets();
    std::vector<Vector<2>> feet;
    for (int f = 0; f < static_cast<int>(facets.size()); ++f)
      for (int i = 0; i < packing.size(); ++i) {
        const Vector<2>& x = packing.centres[i];
        if (!domain.FacetApplies(facets[f], x)) continue;
        const double distance = domain.FacetDistance(facets[f], x);
        if (distance - packing.radii[i] > options.surface_gap * mean_radius) continue;
        out.nodes.push_back(x - distance * domain.FacetDistanceGradient(facets[f], x));
        out.surface_facet.push_back(f);
        out.surface_particle.push_back(i);
      }
    // Corners, unless a foot already stands on one (a quarter radius away at most).
    const std::vector<Vector<2>>& corners = domain.PolygonVertices();
    const int feet_end = out.node_count();
    for (int c = 0; c < static_cast<int>(corners.size()); ++c) {
      bool taken = false;
      for (int k = out.particle_nodes; k < feet_end && !taken; ++k)
        taken = (out.nodes[k] - corners[c]).norm() < 0.25 * mean_radius;
      if (taken) continue;
      out.nodes.push_back(corners[c]);
      out.surface_facet.push_back(c);  // polygon edge c starts at vertex c
      out.surface_particle.push_back(-1);
    }
  }
  // With surface nodes the hull runs along the sides themselves: cutting a triangle there
  // would open a notch in a straight side, so nothing is cut.
  PackingLatticeOptions point_options = options;
  if (out.node_count() > out.particle_nodes) point_options.min_hull_angle_deg = 0.0;
  out.triangles = BuildPointLattice(out.nodes, d, thickness_m, point_options, summary);
  if (summary != nullptr) summary->surface_nodes = out.node_count() - out.particle_nodes;
  return out;
}

Eigen::Vector3d TriangleStrain(const TriangleLattice& lattice, int triangle,
                               const std::vector<Vector<2>>& displacements) {
  // h_k / L_k = n_k^T eps n_k = C_k^T eps with column k of C = (cx^2, cy^2, cx cy) (A4, Voigt).
  std::array<Vector<2>, 3> direction;
  const Eigen::Vector3d h = EdgeStretches(lattice, triangle, displacements, &direction);
  Eigen::Matrix3d ct;
  Eigen::Vector3d stretch;
  for (int k = 0; k < 3; ++k) {
    const Vector<2> n = lattice.rest_edges[triangle][k] / lattice.rest_lengths[triangle][k];
    ct.row(k) << n.x() * n.x(), n.y() * n.y(), n.x() * n.y();
    stretch[k] = h[k] / lattice.rest_lengths[triangle][k];
  }
  return ct.partialPivLu().solve(stretch);
}

Eigen::Vector3d TriangleStress(const TriangleLattice& lattice, int triangle,
                               const std::vector<Vector<2>>& displacements) {
  std::array<Vector<2>, 3> direction;
  const Eigen::Vector3d h = EdgeStretches(lattice, triangle, displacements, &direction);
  const Eigen::Vector3d force = lattice.stiffness[triangle] * h;
  Eigen::Vector3d sigma = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    const Vector<2> n = direction[k];
    const Vector<2> du = displacements[lattice.nodes[triangle][(k + 1) % 3]] - displacements[lattice.nodes[triangle][k]];
    const double length = (lattice.rest_edges[triangle][k] + du).norm();
    sigma += force[k] * length * Eigen::Vector3d(n.x() * n.x(), n.y() * n.y(), n.x() * n.y());
  }
  return sigma / (lattice.areas[triangle] * lattice.thickness_m);
}

}  // namespace specimen
