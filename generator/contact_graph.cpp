#include "generator/contact_graph.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_2.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>

namespace specimen {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

// 2D regular triangulation whose vertices carry a site index.
using Vb2 = CGAL::Triangulation_vertex_base_with_info_2<int, Kernel,
                                                        CGAL::Regular_triangulation_vertex_base_2<Kernel>>;
using Fb2 = CGAL::Regular_triangulation_face_base_2<Kernel>;
using Tds2 = CGAL::Triangulation_data_structure_2<Vb2, Fb2>;
using Regular2 = CGAL::Regular_triangulation_2<Kernel, Tds2>;

using Vb3 = CGAL::Triangulation_vertex_base_with_info_3<int, Kernel,
                                                        CGAL::Regular_triangulation_vertex_base_3<Kernel>>;
using Cb3 = CGAL::Regular_triangulation_cell_base_3<Kernel>;
using Tds3 = CGAL::Triangulation_data_structure_3<Vb3, Cb3>;
using Regular3 = CGAL::Regular_triangulation_3<Kernel, Tds3>;

template <int Dim>
struct RegularTraits;
template <>
struct RegularTraits<2> {
  using Triangulation = Regular2;
  static Kernel::Weighted_point_2 Make(const Vector<2>& x, double r) {
    return Kernel::Weighted_point_2(Kernel::Point_2(x.x(), x.y()), r * r);
  }
};
template <>
struct RegularTraits<3> {
  using Triangulation = Regular3;
  static Kernel::Weighted_point_3 Make(const Vector<3>& x, double r) {
    return Kernel::Weighted_point_3(Kernel::Point_3(x.x(), x.y(), x.z()), r * r);
  }
};

using Site = GraphSite;

template <int Dim>
typename RegularTraits<Dim>::Triangulation Triangulate(
    const std::vector<Vector<Dim>>& positions, const std::vector<double>& radii) {
  using Traits = RegularTraits<Dim>;
  using Triangulation = typename Traits::Triangulation;
  std::vector<std::pair<typename Triangulation::Weighted_point, int>> points;
  points.reserve(positions.size());
  for (size_t s = 0; s < positions.size(); ++s)
    points.emplace_back(Traits::Make(positions[s], radii[s]), static_cast<int>(s));
  // Range insertion sorts the points along a space-filling curve first: near-linear time.
  return Triangulation(points.begin(), points.end());
}

// Calls visit(site_a, site_b) for every finite edge.
template <typename Visit>
void ForEachEdge(const Regular2& rt, Visit&& visit) {
  for (auto e = rt.finite_edges_begin(); e != rt.finite_edges_end(); ++e) {
    const auto face = e->first;
    visit(face->vertex(face->cw(e->second))->info(), face->vertex(face->ccw(e->second))->info());
  }
}
template <typename Visit>
void ForEachEdge(const Regular3& rt, Visit&& visit) {
  for (auto e = rt.finite_edges_begin(); e != rt.finite_edges_end(); ++e)
    visit(e->first->vertex(e->second)->info(), e->first->vertex(e->third)->info());
}

// Site indices of the finite vertices of the simplex containing the weighted point.
std::vector<int> ContainingSimplex(const Regular2& rt, const Kernel::Weighted_point_2& p) {
  std::vector<int> sites;
  const auto face = rt.locate(p);
  if (face == nullptr) return sites;
  for (int k = 0; k < 3; ++k)
    if (!rt.is_infinite(face->vertex(k))) sites.push_back(face->vertex(k)->info());
  return sites;
}
std::vector<int> ContainingSimplex(const Regular3& rt, const Kernel::Weighted_point_3& p) {
  std::vector<int> sites;
  const auto cell = rt.locate(p);
  if (cell == nullptr) return sites;
  for (int k = 0; k < 4; ++k)
    if (!rt.is_infinite(cell->vertex(k))) sites.push_back(cell->vertex(k)->info());
  return sites;
}

template <typename Triangulation>
std::vector<bool> PresentSites(const Triangulation& rt, size_t site_count) {
  std::vector<bool> present(site_count, false);
  for (auto v = rt.finite_vertices_begin(); v != rt.finite_vertices_end(); ++v)
    present[v->info()] = true;
  return present;
}

}  // namespace

template <int Dim>
ContactGraph<Dim> BuildContactGraph(const Domain<Dim>& domain,
                                    const std::vector<Vector<Dim>>& centres,
                                    const std::vector<double>& radii, double ghost_band,
                                    bool with_cells) {
  const int n = static_cast<int>(centres.size());
  const auto& facets = domain.Facets();

  std::vector<Site> sites;
  std::vector<Vector<Dim>> positions;
  std::vector<double> weights;
  sites.reserve(n + n / 4);
  for (int i = 0; i < n; ++i) {
    sites.push_back({i, -1});
    positions.push_back(centres[i]);
    weights.push_back(radii[i]);
  }
  std::vector<std::pair<int, int>> ties;
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < static_cast<int>(facets.size()); ++k) {
      if (!domain.FacetApplies(facets[k], centres[i])) continue;
      const double distance = domain.FacetDistance(facets[k], centres[i]);
      if (distance < radii[i]) ties.emplace_back(i, k);  // protrudes: always tied
      if (distance > ghost_band) continue;
      sites.push_back({i, k});
      positions.push_back(domain.Mirror(facets[k], centres[i]));
      weights.push_back(radii[i]);
    }
  }

  const auto rt = Triangulate<Dim>(positions, weights);
  ContactGraph<Dim> graph;
  auto add = [&](int site_a, int site_b) {
    const Site& a = sites[site_a];
    const Site& b = sites[site_b];
    if (a.facet < 0 && b.facet < 0) {
      graph.edges.push_back({std::min(a.particle, b.particle), std::max(a.particle, b.particle)});
    } else if (a.particle == b.particle && (a.facet < 0) != (b.facet < 0)) {
      ties.emplace_back(a.particle, a.facet < 0 ? b.facet : a.facet);
    }
  };
  ForEachEdge(rt, add);

  if (with_cells) {
    if constexpr (Dim == 2) {
      for (auto f = rt.finite_faces_begin(); f != rt.finite_faces_end(); ++f)
        graph.cells.push_back({sites[f->vertex(0)->info()], sites[f->vertex(1)->info()],
                               sites[f->vertex(2)->info()]});
    } else {
      for (auto c = rt.finite_cells_begin(); c != rt.finite_cells_end(); ++c)
        graph.cells.push_back({sites[c->vertex(0)->info()], sites[c->vertex(1)->info()],
                               sites[c->vertex(2)->info()], sites[c->vertex(3)->info()]});
    }
  }

  // Hidden particles have no edges of their own: tie them to the particles covering them.
  const std::vector<bool> present = PresentSites(rt, sites.size());
  for (int i = 0; i < n; ++i) {
    if (present[i]) continue;
    ++graph.hidden_particles;
    for (int site : ContainingSimplex(rt, RegularTraits<Dim>::Make(centres[i], radii[i])))
      if (sites[site].facet < 0 && sites[site].particle != i) add(i, site);
  }

  std::sort(graph.edges.begin(), graph.edges.end());
  graph.edges.erase(std::unique(graph.edges.begin(), graph.edges.end()), graph.edges.end());
  std::sort(ties.begin(), ties.end());
  ties.erase(std::unique(ties.begin(), ties.end()), ties.end());
  graph.boundary_ties = std::move(ties);
  return graph;
}

template <int Dim>
std::vector<std::array<int, Dim + 1>> RegularTriangulationCells(
    const std::vector<Vector<Dim>>& centres, const std::vector<double>& radii) {
  const auto rt = Triangulate<Dim>(centres, radii);
  std::vector<std::array<int, Dim + 1>> cells;
  if constexpr (Dim == 2) {
    for (auto f = rt.finite_faces_begin(); f != rt.finite_faces_end(); ++f)
      cells.push_back({f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()});
  } else {
    for (auto c = rt.finite_cells_begin(); c != rt.finite_cells_end(); ++c)
      cells.push_back({c->vertex(0)->info(), c->vertex(1)->info(), c->vertex(2)->info(),
                       c->vertex(3)->info()});
  }
  return cells;
}

template ContactGraph<2> BuildContactGraph<2>(const Domain<2>&, const std::vector<Vector<2>>&,
                                              const std::vector<double>&, double, bool);
template ContactGraph<3> BuildContactGraph<3>(const Domain<3>&, const std::vector<Vector<3>>&,
                                              const std::vector<double>&, double, bool);
template std::vector<std::array<int, 3>> RegularTriangulationCells<2>(
    const std::vector<Vector<2>>&, const std::vector<double>&);
template std::vector<std::array<int, 4>> RegularTriangulationCells<3>(
    const std::vector<Vector<3>>&, const std::vector<double>&);

}  // namespace specimen
