#include "generator/disc_clip_area.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTolerance = kDiscClipTolerance;
// Lines or edges closer to parallel than this (sine of the angle) are not intersected.
constexpr double kParallel = 1e-14;
// A clipped edge end this close to the unit circle splits the circle there.
constexpr double kOnCircle = 1e-9;
// Distance of the probe that tells on which side of a coincident polygon edge the domain is.
constexpr double kProbe = 1e-7;
// A piece whose midpoint is farther than this from every other boundary is classified by
// the midpoint alone (a piece has no crossing inside, so one point decides).
constexpr double kClearance = 1e-6;

double Cross(const Vector<2>& a, const Vector<2>& b) { return a.x() * b.y() - a.y() * b.x(); }
double Angle(const Vector<2>& p) { return std::atan2(p.y(), p.x()); }

// Green's theorem: 1/2 of the integral of (x dy - y dx) along the arc of the circle with
// centre c and radius R from angle a to angle b (counter-clockwise).
double ArcTerm(const Vector<2>& c, double radius, double a, double b) {
  return 0.5 * (radius * radius * (b - a) + radius * (c.x() * (std::sin(b) - std::sin(a)) -
                                                      c.y() * (std::cos(b) - std::cos(a))));
}

}  // namespace

template <class PointAt>
bool DiscClipper::PieceOnBoundary(PointAt&& point_at, double begin, double end, Curve kind,
                                  int index) const {
  // The midpoint decides unless it lies near another boundary; then three points vote.
  const int clear = ClearSide(point_at(0.5 * (begin + end)), kind, index);
  if (clear != 0) return clear > 0;
  int inside = 0;
  for (double fraction : {0.25, 0.5, 0.75}) {
    if (Inside(point_at(begin + fraction * (end - begin)), kind, index)) ++inside;
    if (inside == 2) return true;
  }
  return false;
}

double DiscClipper::PolygonSignedDistance(const Vector<2>& p) const {
  double best = std::numeric_limits<double>::infinity();
  bool inside = true;
  for (const Edge& e : edges_) {
    // Nearest point of the part of the edge that lies in the disc: the segment from p to it
    // stays in the disc (convex) and crosses no other edge, so p is on the side of the
    // domain boundary seen there (the segment's side, or the corner's wedge at a vertex).
    const double u = std::clamp((p - e.edge.start).dot(e.direction) / e.direction.squaredNorm(),
                                e.u_begin, e.u_end);
    const Vector<2> nearest = e.edge.start + u * e.direction;
    const double distance = (p - nearest).norm();
    if (distance >= best) continue;
    best = distance;
    if (u == 0.0 || u == 1.0) {
      const Vector<2>& previous = u == 0.0 ? e.edge.before : e.edge.start;
      const Vector<2>& vertex = u == 0.0 ? e.edge.start : e.edge.end;
      const Vector<2>& next = u == 0.0 ? e.edge.end : e.edge.after;
      const bool convex = Cross(vertex - previous, next - vertex) > 0.0;
      const bool left_of_incoming = Cross(vertex - previous, p - previous) >= 0.0;
      const bool left_of_outgoing = Cross(next - vertex, p - vertex) >= 0.0;
      inside =
          convex ? (left_of_incoming && left_of_outgoing) : (left_of_incoming || left_of_outgoing);
    } else {
      inside = Cross(e.direction, p - e.edge.start) >= 0.0;
    }
  }
  return inside ? best : -best;
}

int DiscClipper::ClearSide(const Vector<2>& p, Curve skip_kind, int skip_index) const {
  // Excess of p over each set (> 0 outside); a clear decision needs every excess to be
  // farther than kClearance from zero.
  bool near = false;
  auto check = [&](double excess) {
    if (excess > kClearance) return true;  // clearly outside
    near = near || excess > -kClearance;
    return false;
  };
  if (skip_kind != Curve::kCircle && check(p.norm() - 1.0)) return -1;
  for (int k = 0; k < static_cast<int>(lines_.size()); ++k) {
    if (skip_kind == Curve::kLine && k == skip_index) continue;
    if (check(lines_[k].normal.dot(p) - lines_[k].offset)) return -1;
  }
  if (use_domain_circle_ && skip_kind != Curve::kDomainCircle &&
      check((p - domain_centre_).norm() - domain_radius_))
    return -1;
  if (!edges_.empty() && skip_kind != Curve::kEdge && check(-PolygonSignedDistance(p))) return -1;
  return near ? 0 : 1;
}

bool DiscClipper::Inside(const Vector<2>& p, Curve skip_kind, int skip_index) const {
  if (skip_kind != Curve::kCircle && p.squaredNorm() > (1.0 + kTolerance) * (1.0 + kTolerance))
    return false;
  for (int k = 0; k < static_cast<int>(lines_.size()); ++k) {
    if (skip_kind == Curve::kLine && k == skip_index) continue;
    if (lines_[k].normal.dot(p) - lines_[k].offset > kTolerance) return false;
  }
  if (use_domain_circle_ && skip_kind != Curve::kDomainCircle &&
      (p - domain_centre_).norm() > domain_radius_ + kTolerance)
    return false;
  if (!edges_.empty() && skip_kind != Curve::kEdge) {
    const double distance = PolygonSignedDistance(p);
    if (distance < -kTolerance) return false;
    if (skip_kind == Curve::kLine && distance <= kTolerance) {
      // The piece lies on a polygon edge. If the domain is on the same side as the
      // half-plane, the edge piece already carries this boundary: do not count it twice.
      // (If it is on the other side, both pieces count and cancel: the region is empty.)
      const Vector<2> probe = p - kProbe * lines_[skip_index].normal;
      if (PolygonSignedDistance(probe) > 0.0) return false;
    }
  }
  return true;
}

double DiscClipper::Area(const DiscClipProblem& problem) {
  // 1. The half-planes that cut the disc. A half-plane that only grazes the disc is
  //    dropped (it would cut a sliver of area < 2e-15); one that leaves only a sliver
  //    empties the region. Coincident half-planes are kept once.
  lines_.clear();
  for (const HalfPlane& half_plane : problem.half_planes) {
    if (half_plane.offset >= 1.0 - kTolerance) continue;
    if (half_plane.offset <= -1.0 + kTolerance) return 0.0;
    bool duplicate = false;
    for (const Line& line : lines_)
      if ((line.normal - half_plane.normal).cwiseAbs().maxCoeff() <= kTolerance &&
          std::abs(line.offset - half_plane.offset) <= kTolerance)
        duplicate = true;
    if (duplicate) continue;
    Line line;
    line.normal = half_plane.normal;
    line.tangent = Vector<2>(-half_plane.normal.y(), half_plane.normal.x());  // domain on the left
    line.offset = half_plane.offset;
    line.half_chord = std::sqrt(1.0 - half_plane.offset * half_plane.offset);
    lines_.push_back(line);
  }

  // 2. The domain circle, unless the disc lies inside it (then it changes nothing).
  use_domain_circle_ = false;
  if (problem.use_domain_circle) {
    const double distance = problem.domain_centre.norm();
    if (distance >= problem.domain_radius + 1.0 - kTolerance) return 0.0;
    if (distance + 1.0 > problem.domain_radius + kTolerance) {
      use_domain_circle_ = true;
      domain_centre_ = problem.domain_centre;
      domain_radius_ = problem.domain_radius;
    }
  }

  // 3. The polygon edges cut to the disc.
  edges_.clear();
  if (problem.use_polygon) {
    for (const PolygonEdge& polygon_edge : problem.polygon_edges) {
      const Vector<2> direction = polygon_edge.end - polygon_edge.start;
      const double a = direction.squaredNorm();
      const double b = polygon_edge.start.dot(direction);
      const double c = polygon_edge.start.squaredNorm() - 1.0;
      const double discriminant = b * b - a * c;
      if (a == 0.0 || discriminant <= 0.0) continue;
      const double root = std::sqrt(discriminant);
      const double u_begin = std::max(0.0, (-b - root) / a);
      const double u_end = std::min(1.0, (-b + root) / a);
      if (u_end > u_begin) edges_.push_back({polygon_edge, direction, u_begin, u_end});
    }
    if (edges_.empty() && !problem.centre_inside_polygon) return 0.0;
  }

  // 4. Split every curve at its crossings with the others.
  const int line_count = static_cast<int>(lines_.size());
  const int edge_count = static_cast<int>(edges_.size());
  circle_splits_.clear();
  domain_splits_.clear();
  if (static_cast<int>(line_splits_.size()) < line_count) line_splits_.resize(line_count);
  if (static_cast<int>(edge_splits_.size()) < edge_count) edge_splits_.resize(edge_count);
  for (int k = 0; k < line_count; ++k) {
    const Line& line = lines_[k];
    line_splits_[k].assign({-line.half_chord, line.half_chord});
    circle_splits_.push_back(Angle(line.offset * line.normal - line.half_chord * line.tangent));
    circle_splits_.push_back(Angle(line.offset * line.normal + line.half_chord * line.tangent));
  }
  for (int e = 0; e < edge_count; ++e) {
    const Edge& edge = edges_[e];
    edge_splits_[e].assign({edge.u_begin, edge.u_end});
    for (double u : {edge.u_begin, edge.u_end}) {
      const Vector<2> point = edge.edge.start + u * edge.direction;
      if (1.0 - point.norm() <= kOnCircle) circle_splits_.push_back(Angle(point));
    }
  }
  for (int k = 0; k < line_count; ++k) {
    const Line& line = lines_[k];
    for (int l = k + 1; l < line_count; ++l) {
      const Line& other = lines_[l];
      const double denominator = other.normal.dot(line.tangent);
      if (std::abs(denominator) < kParallel) continue;
      const double s = (other.offset - line.offset * other.normal.dot(line.normal)) / denominator;
      const Vector<2> point = line.offset * line.normal + s * line.tangent;
      if (point.squaredNorm() > 1.0) continue;
      line_splits_[k].push_back(s);
      line_splits_[l].push_back(other.tangent.dot(point));
    }
    for (int e = 0; e < edge_count; ++e) {
      const Edge& edge = edges_[e];
      const double denominator = line.normal.dot(edge.direction);
      if (std::abs(denominator) < kParallel * edge.direction.norm()) continue;
      const double u = (line.offset - line.normal.dot(edge.edge.start)) / denominator;
      if (u < edge.u_begin || u > edge.u_end) continue;
      const Vector<2> point = edge.edge.start + u * edge.direction;
      line_splits_[k].push_back(line.tangent.dot(point));
      edge_splits_[e].push_back(u);
    }
    if (use_domain_circle_) {
      const Vector<2> foot = line.offset * line.normal - domain_centre_;
      const double half_b = line.tangent.dot(foot);
      const double discriminant =
          half_b * half_b - (foot.squaredNorm() - domain_radius_ * domain_radius_);
      if (discriminant > 0.0) {
        const double root = std::sqrt(discriminant);
        for (double s : {-half_b - root, -half_b + root}) {
          if (std::abs(s) > line.half_chord) continue;
          line_splits_[k].push_back(s);
          domain_splits_.push_back(
              Angle(line.offset * line.normal + s * line.tangent - domain_centre_));
        }
      }
    }
  }
  if (use_domain_circle_) {
    const double distance = domain_centre_.norm();
    if (distance > std::abs(1.0 - domain_radius_) && distance < 1.0 + domain_radius_) {
      // Circle-circle crossings: along the centre line at `along`, off it by +-`across`.
      const double along =
          (1.0 - domain_radius_ * domain_radius_ + distance * distance) / (2.0 * distance);
      const double across_squared = 1.0 - along * along;
      if (across_squared > 0.0) {
        const Vector<2> unit = domain_centre_ / distance;
        const Vector<2> normal(-unit.y(), unit.x());
        for (double sign : {-1.0, 1.0}) {
          const Vector<2> point = along * unit + sign * std::sqrt(across_squared) * normal;
          circle_splits_.push_back(Angle(point));
          domain_splits_.push_back(Angle(point - domain_centre_));
        }
      }
    }
  }

  // 5. Sum the Green's-theorem terms of the pieces on the boundary of the region.
  double twice_area = 0.0;  // accumulate 2 * area to keep the terms simple
  auto circle_pieces = [&](std::vector<double>& splits, const Vector<2>& centre, double radius,
                           Curve kind) {
    auto point_at = [&](double angle) {
      return Vector<2>(centre + radius * Vector<2>(std::cos(angle), std::sin(angle)));
    };
    if (splits.empty()) {
      if (PieceOnBoundary(point_at, 0.0, 2.0 * kPi, kind, 0))
        twice_area += 2.0 * ArcTerm(centre, radius, 0.0, 2.0 * kPi);
      return;
    }
    std::sort(splits.begin(), splits.end());
    for (size_t i = 0; i < splits.size(); ++i) {
      const double begin = splits[i];
      const double end = i + 1 < splits.size() ? splits[i + 1] : splits[0] + 2.0 * kPi;
      if (end > begin && PieceOnBoundary(point_at, begin, end, kind, 0))
        twice_area += kind == Curve::kCircle ? end - begin  // unit circle about the origin
                                             : 2.0 * ArcTerm(centre, radius, begin, end);
    }
  };
  circle_pieces(circle_splits_, Vector<2>::Zero(), 1.0, Curve::kCircle);
  if (use_domain_circle_)
    circle_pieces(domain_splits_, domain_centre_, domain_radius_, Curve::kDomainCircle);
  for (int k = 0; k < line_count; ++k) {
    const Line& line = lines_[k];
    auto point_at = [&](double s) {
      return Vector<2>(line.offset * line.normal + s * line.tangent);
    };
    std::vector<double>& splits = line_splits_[k];
    std::sort(splits.begin(), splits.end());
    for (size_t i = 0; i + 1 < splits.size(); ++i)
      if (splits[i + 1] > splits[i] &&
          PieceOnBoundary(point_at, splits[i], splits[i + 1], Curve::kLine, k))
        twice_area += line.offset * (splits[i + 1] - splits[i]);  // cross(p, q), |n x t| = 1
  }
  for (int e = 0; e < edge_count; ++e) {
    const Edge& edge = edges_[e];
    auto point_at = [&](double u) { return Vector<2>(edge.edge.start + u * edge.direction); };
    std::vector<double>& splits = edge_splits_[e];
    std::sort(splits.begin(), splits.end());
    const double cross = Cross(edge.edge.start, edge.direction);
    for (size_t i = 0; i + 1 < splits.size(); ++i)
      if (splits[i + 1] > splits[i] &&
          PieceOnBoundary(point_at, splits[i], splits[i + 1], Curve::kEdge, e))
        twice_area += cross * (splits[i + 1] - splits[i]);
  }
  // Round-off can leave an empty region at -1e-17 or so; the area is in [0, pi].
  return std::clamp(0.5 * twice_area, 0.0, kPi);
}

}  // namespace specimen
