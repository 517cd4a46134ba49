#pragma once
// The contact graph of a set of weighted particles: the edges of the CGAL regular
// (weighted Delaunay) triangulation with weights r^2 (Labra section 3.2.3, "regeneration
// of the mesh by weighted Delaunay triangulation"), plus the boundary ties.
//
// Boundary ties: each particle near a facet is mirrored across it and the mirror image
// is inserted as a ghost. A particle is tied to a facet when it is adjacent to its own
// mirror, i.e. exactly when its power cell reaches the boundary (for plane facets the
// power bisector of a particle and its mirror is the facet itself). Particles that
// protrude through a facet are always tied to it.

#include <array>
#include <utility>
#include <vector>

#include "generator/domain.h"

namespace specimen {

// A vertex of the regular triangulation: a particle (facet = -1) or its mirror image
// across a boundary facet.
struct GraphSite {
  int particle = -1;
  int facet = -1;
};

template <int Dim>
struct ContactGraph {
  // Edges between particles (i < j), sorted.
  std::vector<std::array<int, 2>> edges;
  // (particle, facet index) pairs, sorted.
  std::vector<std::pair<int, int>> boundary_ties;
  // Particles hidden in the regular triangulation (covered by the power cells of others);
  // each got edges to the vertices of the simplex that contains it.
  int hidden_particles = 0;
  // The finite simplices (triangles, tetrahedra) with their sites, filled only when asked
  // for (BuildContactGraph's `with_cells`); the hole filling uses them.
  std::vector<std::array<GraphSite, Dim + 1>> cells;
};

// Builds the graph. `ghost_band`: particles farther than this from a facet get no mirror
// (they cannot reach the boundary through their neighbours' cells).
template <int Dim>
ContactGraph<Dim> BuildContactGraph(const Domain<Dim>& domain,
                                    const std::vector<Vector<Dim>>& centres,
                                    const std::vector<double>& radii, double ghost_band,
                                    bool with_cells = false);

// Delaunay simplices (triangles, tetrahedra) of the regular triangulation of the
// particles alone, as particle indices; used for the Bagi strain and for metrics.
template <int Dim>
std::vector<std::array<int, Dim + 1>> RegularTriangulationCells(
    const std::vector<Vector<Dim>>& centres, const std::vector<double>& radii);

}  // namespace specimen
