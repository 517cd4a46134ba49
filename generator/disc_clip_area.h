#pragma once
// Exact area of a disc clipped by half-planes and by a domain (a simple polygon, possibly
// non-convex, or a disc), by Green's theorem: area = 1/2 of the boundary integral of
// (x dy - y dx). Every boundary curve (the disc's circle, each half-plane's line cut to
// the disc, each polygon edge cut to the disc, the domain circle) is split at its crossings
// with the other curves; a piece is on the boundary of the region when it lies inside all
// the other sets, and then contributes its integral in closed form (segments and arcs).
//
// This is the building block of the overlap-corrected porosity (union_volume.h): in 2D
// for each particle's disc cut by its power cell, in 3D for the slices of a sphere.
//
// Degenerate input is handled with one length tolerance (kDiscClipTolerance, in units of
// the disc radius): a line closer than that to tangency is treated as not cutting (the
// sliver it would cut has area < 2e-15), coincident lines with the same orientation are
// merged, and a half-plane line lying on a polygon edge with the domain on the same side
// is not counted twice. A piece is classified by its midpoint when that is clearly away
// from the other boundaries, else by a vote of three interior points, so a single tangent
// touching point cannot flip it.

#include <vector>

#include "generator/domain.h"

namespace specimen {

// Length tolerance of the clipping, relative to the disc radius.
inline constexpr double kDiscClipTolerance = 1e-10;

// The half-plane {y : normal . y <= offset}; normal has unit length.
struct HalfPlane {
  Vector<2> normal = Vector<2>::Zero();
  double offset = 0.0;
};

// A polygon edge from `start` to `end` with the domain on its left (counter-clockwise
// polygon). `before` is the vertex preceding `start` and `after` the one following `end`:
// they decide inside/outside for points nearest to a vertex (convex or reflex corner).
struct PolygonEdge {
  Vector<2> before = Vector<2>::Zero();
  Vector<2> start = Vector<2>::Zero();
  Vector<2> end = Vector<2>::Zero();
  Vector<2> after = Vector<2>::Zero();
};

// The region unit disc ∩ half-planes ∩ domain, in coordinates centred on the disc and
// scaled so that the disc has radius 1.
struct DiscClipProblem {
  std::vector<HalfPlane> half_planes;
  // Polygon domain: its edges that come closer than 1 to the origin (edges that do not
  // meet the disc may be omitted). If none of the given edges meets the disc, the disc is
  // inside the domain when centre_inside_polygon is set and outside otherwise.
  bool use_polygon = false;
  std::vector<PolygonEdge> polygon_edges;
  bool centre_inside_polygon = true;
  // Disc domain.
  bool use_domain_circle = false;
  Vector<2> domain_centre = Vector<2>::Zero();
  double domain_radius = 0.0;

  void Clear() {
    half_planes.clear();
    use_polygon = false;
    polygon_edges.clear();
    centre_inside_polygon = true;
    use_domain_circle = false;
  }
};

// Computes areas of clipped discs; keeps its scratch buffers between calls (one object per
// thread).
class DiscClipper {
 public:
  // Area of the region, in units of the squared disc radius (pi for an unclipped disc).
  double Area(const DiscClipProblem& problem);

 private:
  struct Line {  // active half-plane line y = offset n + s t, s in [-half_chord, half_chord]
    Vector<2> normal, tangent;
    double offset, half_chord;
  };
  struct Edge {  // polygon edge a + u (b - a), u in [u_begin, u_end] inside the disc
    PolygonEdge edge;
    Vector<2> direction;
    double u_begin, u_end;
  };
  enum class Curve { kCircle, kLine, kEdge, kDomainCircle };

  // Whether p is in every set except the one whose boundary carries it (the curve
  // `skip_kind` / `skip_index`); boundaries count as inside within the tolerance.
  bool Inside(const Vector<2>& p, Curve skip_kind, int skip_index) const;
  // +1 if p is clearly inside those sets, -1 if clearly outside one, 0 if near a boundary.
  int ClearSide(const Vector<2>& p, Curve skip_kind, int skip_index) const;
  // Signed distance from p (inside the unit disc) to the polygon boundary, positive inside,
  // using only the edges that meet the disc.
  double PolygonSignedDistance(const Vector<2>& p) const;
  // Whether the piece is on the boundary of the region: its midpoint if clearly on one
  // side, else two out of three interior points inside.
  template <class PointAt>
  bool PieceOnBoundary(PointAt&& point_at, double begin, double end, Curve kind, int index) const;

  std::vector<Line> lines_;
  std::vector<Edge> edges_;
  bool use_domain_circle_ = false;
  Vector<2> domain_centre_ = Vector<2>::Zero();
  double domain_radius_ = 0.0;
  // Split parameters per curve: the circle (angles), lines (s), edges (u), domain circle.
  std::vector<double> circle_splits_;
  std::vector<std::vector<double>> line_splits_;
  std::vector<std::vector<double>> edge_splits_;
  std::vector<double> domain_splits_;
};

}  // namespace specimen
