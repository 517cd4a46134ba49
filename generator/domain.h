#pragma once
// The region a packing fills: rectangle, simple polygon or disc in 2D; box or cylinder
// (axis along z) in 3D. Besides volume and inside/outside tests, a domain exposes its
// boundary as facets: the pieces (segments, planes, a circle, a cylinder mantle) that
// the generator ties boundary particles to with Labra's residual (3.8)
//   b = d_k(x)^2 - r^2,   d_k = distance from x to facet k, positive inside.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace specimen {

template <int Dim>
using Vector = Eigen::Matrix<double, Dim, 1>;

enum class DomainShape { kRectangle, kPolygon, kDisc, kBox, kCylinder };

// The kinds of boundary pieces.
enum class FacetKind {
  kPlane,           // straight segment (2D) or plane (3D); `bounded` edges of polygons
  kCircle,          // inner side of a circle (2D disc domain)
  kCylinderMantle,  // inner side of the mantle of a z-axis cylinder (3D)
};

template <int Dim>
struct BoundaryFacet {
  FacetKind kind = FacetKind::kPlane;
  Vector<Dim> point = Vector<Dim>::Zero();   // plane: a point on it; circle/mantle: centre
  Vector<Dim> normal = Vector<Dim>::Zero();  // plane: outward unit normal
  double radius = 0.0;                       // circle/mantle radius
  // Polygon edges (2D) are segments from `point` to `end`: a particle is tied to one only
  // where the foot of its perpendicular lies on the segment (matters at reflex corners).
  bool bounded = false;
  Vector<Dim> end = Vector<Dim>::Zero();
};

template <int Dim>
class Domain {
 public:
  // Factories validate their arguments and throw InputError naming the field and range.
  static Domain Rectangle(double x_min, double y_min, double x_max, double y_max);
  // A simple polygon (no self-intersection), either orientation; stored counter-clockwise.
  static Domain Polygon(const std::vector<Vector<2>>& vertices);
  static Domain Disc(const Vector<2>& centre, double radius);
  static Domain Box(const Vector<3>& lower, const Vector<3>& upper);
  // Cylinder with axis along z through (centre_x, centre_y), from z_min to z_max.
  static Domain Cylinder(double centre_x, double centre_y, double radius, double z_min,
                         double z_max);

  DomainShape shape() const { return shape_; }
  // "rectangle", "polygon", "disc", "box", "cylinder".
  std::string ShapeName() const;
  // Area in 2D (per unit thickness: also the volume), volume in 3D.
  double Volume() const;
  // Axis-aligned bounding box.
  Vector<Dim> Lower() const { return lower_; }
  Vector<Dim> Upper() const { return upper_; }
  // Distance from x to the boundary, positive inside, negative outside.
  double SignedDistance(const Vector<Dim>& x) const;
  bool Contains(const Vector<Dim>& x) const { return SignedDistance(x) >= 0.0; }
  // Smallest extent of the domain (width of the narrowest side, or diameter).
  double SmallestExtent() const;

  const std::vector<BoundaryFacet<Dim>>& Facets() const { return facets_; }
  // Distance from x to facet f, positive on the inner side (Labra 3.8: (w - x).n).
  double FacetDistance(const BoundaryFacet<Dim>& facet, const Vector<Dim>& x) const;
  // Gradient of FacetDistance with respect to x (a unit vector pointing inwards).
  Vector<Dim> FacetDistanceGradient(const BoundaryFacet<Dim>& facet, const Vector<Dim>& x) const;
  // Whether a particle at x can be tied to facet f (always, except polygon edges whose
  // segment does not contain the foot of the perpendicular from x).
  bool FacetApplies(const BoundaryFacet<Dim>& facet, const Vector<Dim>& x) const;
  // Mirror image of x across facet f (radial reflection for circles and mantles). The
  // generator adds mirrored particles as ghosts to the regular triangulation: a particle
  // is adjacent to its own mirror exactly when its power cell reaches the facet.
  Vector<Dim> Mirror(const BoundaryFacet<Dim>& facet, const Vector<Dim>& x) const;

  // Polygon vertices (counter-clockwise), 2D polygons and rectangles only.
  const std::vector<Vector<2>>& PolygonVertices() const { return vertices_; }
  // Disc and cylinder parameters.
  double CircleRadius() const { return radius_; }
  Vector<2> CircleCentre() const { return centre_; }
  double ZMin() const { return lower_[Dim - 1]; }
  double ZMax() const { return upper_[Dim - 1]; }

  // One-line text form, e.g. "rectangle 0 0 100 100"; Parse() reads it back bit-exactly.
  std::string ToText() const;
  // The same with 10 significant digits, for reports a person reads: "0.05", not
  // "0.050000000000000003".
  std::string ToShortText() const;
  static Domain Parse(const std::string& text);

 private:
  Domain() = default;
  std::string Text(bool exact) const;
  void BuildFacets();

  DomainShape shape_ = DomainShape::kBox;
  Vector<Dim> lower_ = Vector<Dim>::Zero();
  Vector<Dim> upper_ = Vector<Dim>::Zero();
  std::vector<Vector<2>> vertices_;   // polygon / rectangle
  Vector<2> centre_ = Vector<2>::Zero();  // disc / cylinder axis
  double radius_ = 0.0;               // disc / cylinder
  std::vector<BoundaryFacet<Dim>> facets_;
};

// Whether the closed polygon through `vertices` is simple (no two edges cross or touch
// except neighbours at their shared vertex). Used to validate polygon domains.
bool IsSimplePolygon(const std::vector<Vector<2>>& vertices);
// Signed area (positive counter-clockwise).
double PolygonSignedArea(const std::vector<Vector<2>>& vertices);

// Formats a double so that strtod reads back the identical value.
std::string ExactDouble(double value);

}  // namespace specimen
