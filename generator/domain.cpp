#include "generator/domain.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>

#include "common/error.h"
#include "common/format.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;

void RequireFinite(double value, const std::string& field) {
  if (!std::isfinite(value)) throw InputError(field + " must be a finite number");
}

void RequirePositive(double value, const std::string& field) {
  RequireFinite(value, field);
  if (!(value > 0.0))
    throw InputError(field + " = " + ExactDouble(value) + " is not allowed: it must be > 0");
}

double Cross(const Vector<2>& a, const Vector<2>& b) { return a.x() * b.y() - a.y() * b.x(); }

// Orientation of (a, b, c): > 0 counter-clockwise.
double Orient(const Vector<2>& a, const Vector<2>& b, const Vector<2>& c) {
  return Cross(b - a, c - a);
}

bool OnSegment(const Vector<2>& a, const Vector<2>& b, const Vector<2>& p) {
  return std::min(a.x(), b.x()) <= p.x() && p.x() <= std::max(a.x(), b.x()) &&
         std::min(a.y(), b.y()) <= p.y() && p.y() <= std::max(a.y(), b.y());
}

bool SegmentsIntersect(const Vector<2>& p1, const Vector<2>& p2, const Vector<2>& q1,
                       const Vector<2>& q2) {
  const double d1 = Orient(q1, q2, p1), d2 = Orient(q1, q2, p2);
  const double d3 = Orient(p1, p2, q1), d4 = Orient(p1, p2, q2);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return true;
  if (d1 == 0 && OnSegment(q1, q2, p1)) return true;
  if (d2 == 0 && OnSegment(q1, q2, p2)) return true;
  if (d3 == 0 && OnSegment(p1, p2, q1)) return true;
  if (d4 == 0 && OnSegment(p1, p2, q2)) return true;
  return false;
}

double DistanceToSegment(const Vector<2>& a, const Vector<2>& b, const Vector<2>& p) {
  const Vector<2> ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + t * ab - p).norm();
}

bool InsidePolygon(const std::vector<Vector<2>>& v, const Vector<2>& p) {
  bool inside = false;
  for (size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) {
    if ((v[i].y() > p.y()) != (v[j].y() > p.y())) {
      const double x = v[j].x() + (p.y() - v[j].y()) * (v[i].x() - v[j].x()) / (v[i].y() - v[j].y());
      if (p.x() < x) inside = !inside;
    }
  }
  return inside;
}

}  // namespace

std::string ExactDouble(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}

double PolygonSignedArea(const std::vector<Vector<2>>& vertices) {
  double twice_area = 0.0;
  for (size_t i = 0; i < vertices.size(); ++i)
    twice_area += Cross(vertices[i], vertices[(i + 1) % vertices.size()]);
  return 0.5 * twice_area;
}

bool IsSimplePolygon(const std::vector<Vector<2>>& v) {
  const size_t n = v.size();
  if (n < 3) return false;
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j)
      if (v[i] == v[j]) return false;
  for (size_t i = 0; i < n; ++i) {
    const Vector<2>& a = v[i];
    const Vector<2>& b = v[(i + 1) % n];
    for (size_t j = i + 1; j < n; ++j) {
      const bool neighbours = (j == i + 1) || (i == 0 && j == n - 1);
      const Vector<2>& c = v[j];
      const Vector<2>& d = v[(j + 1) % n];
      if (neighbours) {
        // Neighbouring edges may only share their common vertex: reject folding back.
        const Vector<2>& shared = (j == i + 1) ? b : a;
        const Vector<2>& other_a = (j == i + 1) ? a : b;
        const Vector<2>& other_c = (j == i + 1) ? d : c;
        if (Orient(other_a, shared, other_c) == 0.0 &&
            (other_a - shared).dot(other_c - shared) > 0.0)
          return false;
        continue;
      }
      if (SegmentsIntersect(a, b, c, d)) return false;
    }
  }
  return std::abs(PolygonSignedArea(v)) > 0.0;
}

template <int Dim>
Domain<Dim> Domain<Dim>::Rectangle(double x_min, double y_min, double x_max, double y_max) {
  if constexpr (Dim != 2) {
    throw InputError("domain rectangle is two-dimensional; use a box in 3D");
  } else {
    for (auto [v, name] : {std::pair{x_min, "x_min"}, {y_min, "y_min"}, {x_max, "x_max"},
                           {y_max, "y_max"}})
      RequireFinite(v, std::string("rectangle ") + name);
    RequirePositive(x_max - x_min, "rectangle width (x_max - x_min)");
    RequirePositive(y_max - y_min, "rectangle height (y_max - y_min)");
    Domain d = Polygon({Vector<2>(x_min, y_min), Vector<2>(x_max, y_min), Vector<2>(x_max, y_max),
                        Vector<2>(x_min, y_max)});
    d.shape_ = DomainShape::kRectangle;
    return d;
  }
}

template <int Dim>
Domain<Dim> Domain<Dim>::Polygon(const std::vector<Vector<2>>& vertices) {
  if constexpr (Dim != 2) {
    throw InputError("domain polygon is two-dimensional");
  } else {
    if (vertices.size() < 3)
      throw InputError("polygon vertices: " + std::to_string(vertices.size()) +
                       " given, at least 3 are needed");
    for (size_t i = 0; i < vertices.size(); ++i) {
      RequireFinite(vertices[i].x(), "polygon vertex " + std::to_string(i) + " x");
      RequireFinite(vertices[i].y(), "polygon vertex " + std::to_string(i) + " y");
    }
    if (!IsSimplePolygon(vertices))
      throw InputError(
          "polygon vertices: the polygon is self-intersecting, has repeated vertices or zero "
          "area; a simple polygon (edges meet only at shared vertices) is required");
    Domain d;
    d.shape_ = DomainShape::kPolygon;
    d.vertices_ = vertices;
    if (PolygonSignedArea(vertices) < 0.0) std::reverse(d.vertices_.begin(), d.vertices_.end());
    d.lower_ = d.upper_ = d.vertices_[0];
    for (const auto& v : d.vertices_) {
      d.lower_ = d.lower_.cwiseMin(v);
      d.upper_ = d.upper_.cwiseMax(v);
    }
    d.BuildFacets();
    return d;
  }
}

template <int Dim>
Domain<Dim> Domain<Dim>::Disc(const Vector<2>& centre, double radius) {
  if constexpr (Dim != 2) {
    throw InputError("domain disc is two-dimensional; use a cylinder in 3D");
  } else {
    RequireFinite(centre.x(), "disc centre x");
    RequireFinite(centre.y(), "disc centre y");
    RequirePositive(radius, "disc radius");
    Domain d;
    d.shape_ = DomainShape::kDisc;
    d.centre_ = centre;
    d.radius_ = radius;
    d.lower_ = centre - Vector<2>::Constant(radius);
    d.upper_ = centre + Vector<2>::Constant(radius);
    d.BuildFacets();
    return d;
  }
}

template <int Dim>
Domain<Dim> Domain<Dim>::Box(const Vector<3>& lower, const Vector<3>& upper) {
  if constexpr (Dim != 3) {
    throw InputError("domain box is three-dimensional; use a rectangle in 2D");
  } else {
    const char* axis[3] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) {
      RequireFinite(lower[k], std::string("box ") + axis[k] + "_min");
      RequireFinite(upper[k], std::string("box ") + axis[k] + "_max");
      RequirePositive(upper[k] - lower[k],
                      std::string("box size along ") + axis[k] + " (" + axis[k] + "_max - " +
                          axis[k] + "_min)");
    }
    Domain d;
    d.shape_ = DomainShape::kBox;
    d.lower_ = lower;
    d.upper_ = upper;
    d.BuildFacets();
    return d;
  }
}

template <int Dim>
Domain<Dim> Domain<Dim>::Cylinder(double centre_x, double centre_y, double radius, double z_min,
                                  double z_max) {
  if constexpr (Dim != 3) {
    throw InputError("domain cylinder is three-dimensional; use a disc in 2D");
  } else {
    RequireFinite(centre_x, "cylinder centre x");
    RequireFinite(centre_y, "cylinder centre y");
    RequirePositive(radius, "cylinder radius");
    RequireFinite(z_min, "cylinder z_min");
    RequireFinite(z_max, "cylinder z_max");
    RequirePositive(z_max - z_min, "cylinder length (z_max - z_min)");
    Domain d;
    d.shape_ = DomainShape::kCylinder;
    d.centre_ = Vector<2>(centre_x, centre_y);
    d.radius_ = radius;
    d.lower_ = Vector<3>(centre_x - radius, centre_y - radius, z_min);
    d.upper_ = Vector<3>(centre_x + radius, centre_y + radius, z_max);
    d.BuildFacets();
    return d;
  }
}

template <int Dim>
void Domain<Dim>::BuildFacets() {
  facets_.clear();
  if constexpr (Dim == 2) {
    if (shape_ == DomainShape::kDisc) {
      BoundaryFacet<2> f;
      f.kind = FacetKind::kCircle;
      f.point = centre_;
      f.radius = radius_;
      facets_.push_back(f);
      return;
    }
    for (size_t i = 0; i < vertices_.size(); ++i) {
      const Vector<2>& a = vertices_[i];
      const Vector<2>& b = vertices_[(i + 1) % vertices_.size()];
      BoundaryFacet<2> f;
      f.kind = FacetKind::kPlane;
      f.point = a;
      f.end = b;
      f.normal = Vector<2>(b.y() - a.y(), a.x() - b.x()).normalized();  // outward for CCW
      f.bounded = true;
      facets_.push_back(f);
    }
  } else {
    if (shape_ == DomainShape::kBox) {
      for (int axis = 0; axis < 3; ++axis) {
        for (int side = 0; side < 2; ++side) {
          BoundaryFacet<3> f;
          f.kind = FacetKind::kPlane;
          f.point = side == 0 ? lower_ : upper_;
          f.normal = Vector<3>::Zero();
          f.normal[axis] = side == 0 ? -1.0 : 1.0;
          facets_.push_back(f);
        }
      }
      return;
    }
    BoundaryFacet<3> mantle;
    mantle.kind = FacetKind::kCylinderMantle;
    mantle.point = Vector<3>(centre_.x(), centre_.y(), 0.0);
    mantle.radius = radius_;
    facets_.push_back(mantle);
    for (int side = 0; side < 2; ++side) {
      BoundaryFacet<3> cap;
      cap.kind = FacetKind::kPlane;
      cap.point = Vector<3>(centre_.x(), centre_.y(), side == 0 ? lower_.z() : upper_.z());
      cap.normal = Vector<3>(0, 0, side == 0 ? -1.0 : 1.0);
      facets_.push_back(cap);
    }
  }
}

template <int Dim>
std::string Domain<Dim>::ShapeName() const {
  switch (shape_) {
    case DomainShape::kRectangle: return "rectangle";
    case DomainShape::kPolygon: return "polygon";
    case DomainShape::kDisc: return "disc";
    case DomainShape::kBox: return "box";
    case DomainShape::kCylinder: return "cylinder";
  }
  return "unknown";
}

template <int Dim>
double Domain<Dim>::Volume() const {
  switch (shape_) {
    case DomainShape::kRectangle:
    case DomainShape::kPolygon: return PolygonSignedArea(vertices_);
    case DomainShape::kDisc: return kPi * radius_ * radius_;
    case DomainShape::kBox: return (upper_ - lower_).prod();
    case DomainShape::kCylinder: return kPi * radius_ * radius_ * (upper_[Dim - 1] - lower_[Dim - 1]);
  }
  return 0.0;
}

template <int Dim>
double Domain<Dim>::SmallestExtent() const {
  if (shape_ == DomainShape::kDisc) return 2.0 * radius_;
  if (shape_ == DomainShape::kCylinder)
    return std::min(2.0 * radius_, upper_[Dim - 1] - lower_[Dim - 1]);
  if (shape_ == DomainShape::kPolygon) {
    // Twice the largest inscribed distance is a fair "narrowest width" for a polygon;
    // estimate it from area / half-perimeter (exact for regular shapes, safe otherwise).
    double perimeter = 0.0;
    for (size_t i = 0; i < vertices_.size(); ++i)
      perimeter += (vertices_[(i + 1) % vertices_.size()] - vertices_[i]).norm();
    return 2.0 * Volume() / (0.5 * perimeter);
  }
  return (upper_ - lower_).minCoeff();
}

template <int Dim>
double Domain<Dim>::SignedDistance(const Vector<Dim>& x) const {
  if constexpr (Dim == 2) {
    if (shape_ == DomainShape::kDisc) return radius_ - (x - centre_).norm();
    double distance = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < vertices_.size(); ++i)
      distance = std::min(distance,
                          DistanceToSegment(vertices_[i], vertices_[(i + 1) % vertices_.size()], x));
    return InsidePolygon(vertices_, x) ? distance : -distance;
  } else {
    if (shape_ == DomainShape::kBox) {
      const Vector<3> inside = (x - lower_).cwiseMin(upper_ - x);
      if (inside.minCoeff() >= 0.0) return inside.minCoeff();
      return -(x.cwiseMax(lower_).cwiseMin(upper_) - x).norm();
    }
    const double radial = radius_ - (x.template head<2>() - centre_).norm();
    const double axial = std::min(x.z() - lower_.z(), upper_.z() - x.z());
    if (radial >= 0.0 && axial >= 0.0) return std::min(radial, axial);
    return -std::hypot(std::min(radial, 0.0), std::min(axial, 0.0));
  }
}

template <int Dim>
double Domain<Dim>::FacetDistance(const BoundaryFacet<Dim>& facet, const Vector<Dim>& x) const {
  switch (facet.kind) {
    case FacetKind::kPlane: return (facet.point - x).dot(facet.normal);
    case FacetKind::kCircle: return facet.radius - (x - facet.point).norm();
    case FacetKind::kCylinderMantle:
      return facet.radius - (x.template head<2>() - facet.point.template head<2>()).norm();
  }
  return 0.0;
}

template <int Dim>
Vector<Dim> Domain<Dim>::FacetDistanceGradient(const BoundaryFacet<Dim>& facet,
                                               const Vector<Dim>& x) const {
  switch (facet.kind) {
    case FacetKind::kPlane: return -facet.normal;
    case FacetKind::kCircle: {
      const Vector<Dim> radial = x - facet.point;
      const double length = radial.norm();
      return length > 0.0 ? Vector<Dim>(-radial / length) : Vector<Dim>::Zero();
    }
    case FacetKind::kCylinderMantle: {
      Vector<Dim> radial = x - facet.point;
      radial[Dim - 1] = 0.0;
      const double length = radial.norm();
      return length > 0.0 ? Vector<Dim>(-radial / length) : Vector<Dim>::Zero();
    }
  }
  return Vector<Dim>::Zero();
}

template <int Dim>
bool Domain<Dim>::FacetApplies(const BoundaryFacet<Dim>& facet, const Vector<Dim>& x) const {
  if (!facet.bounded) return true;
  const Vector<Dim> edge = facet.end - facet.point;
  const double t = (x - facet.point).dot(edge) / edge.squaredNorm();
  return t >= 0.0 && t <= 1.0;
}

template <int Dim>
Vector<Dim> Domain<Dim>::Mirror(const BoundaryFacet<Dim>& facet, const Vector<Dim>& x) const {
  switch (facet.kind) {
    case FacetKind::kPlane: return x + 2.0 * FacetDistance(facet, x) * facet.normal;
    case FacetKind::kCircle:
    case FacetKind::kCylinderMantle: {
      // Radial reflection: same distance to the circle, on the outer side.
      Vector<Dim> radial = x - facet.point;
      if (facet.kind == FacetKind::kCylinderMantle) radial[Dim - 1] = 0.0;
      const double length = radial.norm();
      if (length == 0.0) return x;  // on the axis: no meaningful mirror (never near the wall)
      return x + radial * (2.0 * (facet.radius - length) / length);
    }
  }
  return x;
}

template <int Dim>
std::string Domain<Dim>::ToText() const {
  return Text(/*exact=*/true);
}

template <int Dim>
std::string Domain<Dim>::ToShortText() const {
  return Text(/*exact=*/false);
}

template <int Dim>
std::string Domain<Dim>::Text(bool exact) const {
  auto number = [exact](double v) {
    if (exact) return ExactDouble(v);
    std::ostringstream short_form;
    short_form.precision(10);
    short_form << v;
    return short_form.str();
  };
  std::ostringstream out;
  out << ShapeName();
  switch (shape_) {
    case DomainShape::kRectangle:
      out << ' ' << number(lower_[0]) << ' ' << number(lower_[1]) << ' '
          << number(upper_[0]) << ' ' << number(upper_[1]);
      break;
    case DomainShape::kPolygon:
      out << ' ' << vertices_.size();
      for (const auto& v : vertices_) out << ' ' << number(v.x()) << ' ' << number(v.y());
      break;
    case DomainShape::kDisc:
      out << ' ' << number(centre_.x()) << ' ' << number(centre_.y()) << ' '
          << number(radius_);
      break;
    case DomainShape::kBox:
      for (int k = 0; k < Dim; ++k) out << ' ' << number(lower_[k]);
      for (int k = 0; k < Dim; ++k) out << ' ' << number(upper_[k]);
      break;
    case DomainShape::kCylinder:
      out << ' ' << number(centre_.x()) << ' ' << number(centre_.y()) << ' '
          << number(radius_) << ' ' << number(lower_[Dim - 1]) << ' '
          << number(upper_[Dim - 1]);
      break;
  }
  return out.str();
}

template <int Dim>
Domain<Dim> Domain<Dim>::Parse(const std::string& text) {
  std::istringstream in(text);
  std::string name;
  in >> name;
  std::vector<double> values;
  std::string token;
  while (in >> token) {
    double v = 0.0;
    if (!ParseDecimal(token, &v))
      throw InputError("domain '" + text + "': '" + token + "' is not a finite decimal number");
    values.push_back(v);
  }
  auto expect = [&](size_t count) {
    if (values.size() != count)
      throw InputError("domain " + name + " needs " + std::to_string(count) + " numbers, got " +
                       std::to_string(values.size()));
  };
  if constexpr (Dim == 2) {
    if (name == "rectangle") {
      expect(4);
      return Rectangle(values[0], values[1], values[2], values[3]);
    }
    if (name == "disc") {
      expect(3);
      return Disc(Vector<2>(values[0], values[1]), values[2]);
    }
    if (name == "polygon") {
      if (values.empty()) throw InputError("domain polygon needs a vertex count");
      if (!(values[0] >= 3.0) || values[0] != std::floor(values[0]) || values[0] > 1e6)
        throw InputError("domain polygon: vertex count " + ExactDouble(values[0]) +
                         " is not allowed: it must be a whole number >= 3");
      const size_t count = static_cast<size_t>(values[0]);
      expect(1 + 2 * count);
      std::vector<Vector<2>> vertices;
      for (size_t i = 0; i < count; ++i)
        vertices.emplace_back(values[1 + 2 * i], values[2 + 2 * i]);
      Domain d = Polygon(vertices);
      return d;
    }
    throw InputError("unknown 2D domain '" + name + "': use rectangle, disc or polygon");
  } else {
    if (name == "box") {
      expect(6);
      return Box(Vector<3>(values[0], values[1], values[2]),
                 Vector<3>(values[3], values[4], values[5]));
    }
    if (name == "cylinder") {
      expect(5);
      return Cylinder(values[0], values[1], values[2], values[3], values[4]);
    }
    throw InputError("unknown 3D domain '" + name + "': use box or cylinder");
  }
}

template class Domain<2>;
template class Domain<3>;

}  // namespace specimen
