#pragma once
// Hole filling: a particle is inserted into a hole of the packing, tangent to the D + 1
// particles (or boundary facets) of a simplex of the regular triangulation: the
// Apollonius problem (in 2D, the inner Soddy circle of three mutually tangent discs).
//
// The generator uses it for two things. (1) When a least-squares round leaves a pair of
// particles folded over each other (a local minimum no further round can leave), the
// smaller one is removed and its hole refilled exactly. (2) Holes still large enough for
// a particle of reasonable size are filled: exact contacts, no overlap, lower porosity.

#include <vector>

#include "generator/contact_graph.h"
#include "generator/domain.h"

namespace specimen {

// The sphere tangent to the given spheres (centres, radii) and planes (point, outward unit
// normal: tangent from the inner side); D + 1 constraints in all, at least one sphere.
// Returns false if there is no positive solution; `centre`, `radius` get the smallest
// positive one (the sphere in the hole between them).
template <int Dim>
bool ApolloniusSphere(const std::vector<Vector<Dim>>& sphere_centres,
                      const std::vector<double>& sphere_radii,
                      const std::vector<Vector<Dim>>& plane_points,
                      const std::vector<Vector<Dim>>& plane_normals, Vector<Dim>* centre,
                      double* radius);

struct HoleFillingOptions {
  double min_radius = 0.0;  // holes whose inscribed particle is smaller stay empty
  double max_radius = 0.0;  // a larger hole gets a particle of this radius at its centre
  int max_insertions = 1 << 30;
};

// Inserts particles into the holes of `graph` (built with cells) in decreasing order of
// size; at most one insertion per simplex neighbourhood per call, each checked against
// the particles around it. Returns the number inserted (appended to x and r).
template <int Dim>
int FillHoles(const Domain<Dim>& domain, const ContactGraph<Dim>& graph,
              const HoleFillingOptions& options, std::vector<Vector<Dim>>& x,
              std::vector<double>& r);

}  // namespace specimen
