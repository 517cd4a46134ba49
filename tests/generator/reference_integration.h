#pragma once
// Independent reference integrals for the metrics tests: areas and volumes by iterated
// one-dimensional integration (Gauss-Legendre between all the points where the integrand
// is not smooth, with a cosine substitution that removes the square-root behaviour at
// those points). Nothing here shares code with the Green's-theorem clipping or the
// slice brackets under test.

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <utility>
#include <vector>

namespace specimen::reference {

constexpr double kPi = 3.14159265358979323846;

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on the Legendre recurrence).
inline const std::vector<std::array<double, 2>>& GaussLegendre() {
  static const std::vector<std::array<double, 2>> rule = [] {
    const int n = 40;
    std::vector<std::array<double, 2>> nodes;
    for (int i = 0; i < n; ++i) {
      double x = std::cos(kPi * (i + 0.75) / (n + 0.5)), derivative = 0.0;
      for (int iteration = 0; iteration < 100; ++iteration) {
        double p0 = 1.0, p1 = x;
        for (int k = 2; k <= n; ++k) {
          const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        derivative = n * (x * p1 - p0) / (x * x - 1.0);
        const double step = p1 / derivative;
        x -= step;
        if (std::abs(step) < 1e-16) break;
      }
      nodes.push_back({x, 2.0 / ((1.0 - x * x) * derivative * derivative)});
    }
    return nodes;
  }();
  return rule;
}

// Integral of g over [a, b] with x = a + (b - a)(1 - cos t)/2, t in [0, pi]: smooth in t
// when g behaves like sqrt or (.)^(3/2) at the ends.
inline double Integrate(double a, double b, const std::function<double(double)>& g) {
  if (!(b > a)) return 0.0;
  double sum = 0.0;
  for (const auto& [node, weight] : GaussLegendre()) {
    const double t = 0.5 * kPi * (node + 1.0);
    sum += weight * g(a + 0.5 * (b - a) * (1.0 - std::cos(t))) * 0.5 * (b - a) * std::sin(t);
  }
  return 0.5 * kPi * sum;
}

// Integral over [lower, upper] split at every break point inside.
inline double IntegratePiecewise(std::vector<double> breaks, double lower, double upper,
                                 const std::function<double(double)>& g) {
  breaks.push_back(lower);
  breaks.push_back(upper);
  std::sort(breaks.begin(), breaks.end());
  double sum = 0.0;
  for (size_t k = 0; k + 1 < breaks.size(); ++k) {
    const double a = std::max(breaks[k], lower), b = std::min(breaks[k + 1], upper);
    sum += Integrate(a, b, g);
  }
  return sum;
}

struct Circle {
  double x, y, r;
};

// x of the points where two circles cross.
inline void AddCircleCrossings(const Circle& a, const Circle& b, std::vector<double>* breaks) {
  const double dx = b.x - a.x, dy = b.y - a.y, d = std::hypot(dx, dy);
  if (d == 0.0 || d >= a.r + b.r || d <= std::abs(a.r - b.r)) return;
  const double along = (d * d + a.r * a.r - b.r * b.r) / (2.0 * d);
  const double across = std::sqrt(std::max(0.0, a.r * a.r - along * along));
  breaks->push_back(a.x + along * dx / d - across * dy / d);
  breaks->push_back(a.x + along * dx / d + across * dy / d);
}

// x where a circle crosses the horizontal line y = level.
inline void AddLevelCrossings(const Circle& c, double level, std::vector<double>* breaks) {
  const double s = c.r * c.r - (level - c.y) * (level - c.y);
  if (s <= 0.0) return;
  breaks->push_back(c.x - std::sqrt(s));
  breaks->push_back(c.x + std::sqrt(s));
}

// Area of (union of discs) ∩ domain, where the domain's column at x is the interval
// column(x) (empty when first > second). `breaks`: the x where the column's ends are not
// smooth or cross a circle, beyond those of the discs themselves.
inline double UnionArea(const std::vector<Circle>& discs,
                        const std::function<std::pair<double, double>(double)>& column,
                        std::vector<double> breaks, double x_lower, double x_upper) {
  for (size_t i = 0; i < discs.size(); ++i) {
    breaks.push_back(discs[i].x - discs[i].r);
    breaks.push_back(discs[i].x + discs[i].r);
    for (size_t j = i + 1; j < discs.size(); ++j) AddCircleCrossings(discs[i], discs[j], &breaks);
  }
  return IntegratePiecewise(breaks, x_lower, x_upper, [&](double x) {
    const auto [low, high] = column(x);
    std::vector<std::pair<double, double>> intervals;
    for (const Circle& c : discs) {
      const double s = c.r * c.r - (x - c.x) * (x - c.x);
      if (s <= 0.0) continue;
      const double a = std::max(c.y - std::sqrt(s), low), b = std::min(c.y + std::sqrt(s), high);
      if (b > a) intervals.push_back({a, b});
    }
    std::sort(intervals.begin(), intervals.end());
    double length = 0.0, reach = -1e300;
    for (const auto& [a, b] : intervals) {
      if (b <= reach) continue;
      length += b - std::max(a, reach);
      reach = b;
    }
    return length;
  });
}

// Area of the disc of radius rho at the origin ∩ {a x + b y <= c} for each (a, b, c).
inline double ClippedDiscArea(double rho, const std::vector<std::array<double, 3>>& lines) {
  std::vector<double> breaks;
  for (size_t k = 0; k < lines.size(); ++k) {
    const auto& [a, b, c] = lines[k];
    const double norm = std::hypot(a, b), distance = c / norm;
    if (std::abs(distance) < rho) {  // crossings with the circle
      const double half = std::sqrt(rho * rho - distance * distance);
      const double foot_x = a / norm * distance;
      breaks.push_back(foot_x - half * b / norm);
      breaks.push_back(foot_x + half * b / norm);
    }
    if (std::abs(b) < 1e-15 * norm) breaks.push_back(c / a);
    for (size_t l = k + 1; l < lines.size(); ++l) {
      const auto& [a2, b2, c2] = lines[l];
      const double det = a * b2 - a2 * b;
      if (std::abs(det) > 1e-15) breaks.push_back((c * b2 - c2 * b) / det);
    }
  }
  return IntegratePiecewise(breaks, -rho, rho, [&](double x) {
    const double s = std::sqrt(std::max(0.0, rho * rho - x * x));
    double low = -s, high = s;
    for (const auto& [a, b, c] : lines) {
      if (std::abs(b) < 1e-15 * std::hypot(a, b)) {
        if (a * x > c) return 0.0;
      } else if (b > 0.0) {
        high = std::min(high, (c - a * x) / b);
      } else {
        low = std::max(low, (c - a * x) / b);
      }
    }
    return std::max(0.0, high - low);
  });
}

// Volume of the unit ball ∩ {n . y <= h} for each (n, h), by slices along z with every
// event where the slice area is not smooth: tangency of a plane to the slice circle, the
// crossing of two planes' line with the sphere, the vertex of three planes.
inline double ClippedBallVolume(const std::vector<std::pair<Eigen::Vector3d, double>>& planes) {
  double z_low = -1.0, z_high = 1.0;
  std::vector<double> events;
  std::vector<std::pair<Eigen::Vector3d, double>> sloped;
  for (const auto& [n, h] : planes) {
    const double horizontal = std::hypot(n.x(), n.y());
    if (horizontal < 1e-14) {
      if (n.z() > 0)
        z_high = std::min(z_high, h / n.z());
      else
        z_low = std::max(z_low, h / n.z());
      continue;
    }
    sloped.push_back({n, h});
    if (std::abs(h) < 1.0) {
      events.push_back(h * n.z() - std::sqrt(1.0 - h * h) * horizontal);
      events.push_back(h * n.z() + std::sqrt(1.0 - h * h) * horizontal);
    }
  }
  for (size_t k = 0; k < sloped.size(); ++k)
    for (size_t l = k + 1; l < sloped.size(); ++l) {
      const Eigen::Vector3d direction = sloped[k].first.cross(sloped[l].first);
      if (direction.norm() < 1e-12) continue;
      Eigen::Matrix3d m;
      m.row(0) = sloped[k].first;
      m.row(1) = sloped[l].first;
      m.row(2) = direction;
      const Eigen::Vector3d point =
          m.fullPivLu().solve(Eigen::Vector3d(sloped[k].second, sloped[l].second, 0.0));
      // |point + t d| = 1
      const double qa = direction.squaredNorm(), qb = point.dot(direction),
                   qc = point.squaredNorm() - 1.0, disc = qb * qb - qa * qc;
      if (disc > 0)
        for (double sign : {-1.0, 1.0})
          events.push_back((point + (-qb + sign * std::sqrt(disc)) / qa * direction).z());
      for (size_t j = l + 1; j < sloped.size(); ++j) {
        Eigen::Matrix3d three;
        three.row(0) = sloped[k].first;
        three.row(1) = sloped[l].first;
        three.row(2) = sloped[j].first;
        if (std::abs(three.determinant()) < 1e-12) continue;
        const Eigen::Vector3d vertex = three.fullPivLu().solve(
            Eigen::Vector3d(sloped[k].second, sloped[l].second, sloped[j].second));
        if (vertex.norm() < 1.0) events.push_back(vertex.z());
      }
    }
  if (!(z_high > z_low)) return 0.0;
  return IntegratePiecewise(events, z_low, z_high, [&](double z) {
    const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
    std::vector<std::array<double, 3>> lines;
    for (const auto& [n, h] : sloped) lines.push_back({n.x(), n.y(), h - n.z() * z});
    return rho > 0.0 ? ClippedDiscArea(rho, lines) : 0.0;
  });
}

// Area common to two circles (radii a, b, centres d apart).
inline double LensArea(double a, double b, double d) {
  if (d >= a + b) return 0.0;
  if (d <= std::abs(a - b)) return kPi * std::min(a, b) * std::min(a, b);
  return a * a * std::acos((d * d + a * a - b * b) / (2 * d * a)) +
         b * b * std::acos((d * d + b * b - a * a) / (2 * d * b)) -
         0.5 * std::sqrt((-d + a + b) * (d + a - b) * (d - a + b) * (d + a + b));
}

// Volume of a union of balls (centre, radius), by slices along z: each slice is a union of
// discs (UnionArea), with events at the poles, where two slice circles touch (the z-extent
// of two spheres' intersection circle) and at the points common to three spheres.
inline double UnionOfBallsVolume(const std::vector<std::pair<Eigen::Vector3d, double>>& balls) {
  std::vector<double> events;
  double z_low = 1e300, z_high = -1e300;
  for (const auto& [c, r] : balls) {  // a slice disc appears with a kink in its area
    z_low = std::min(z_low, c.z() - r);
    z_high = std::max(z_high, c.z() + r);
    events.push_back(c.z() - r);
    events.push_back(c.z() + r);
  }
  // The radical plane of spheres a and b: 2 (c_b - c_a) . p = r_a^2 - r_b^2 + |c_b|^2 - |c_a|^2.
  auto radical = [&](size_t a, size_t b) {
    const auto& [ca, ra] = balls[a];
    const auto& [cb, rb] = balls[b];
    return std::pair<Eigen::Vector3d, double>(
        2.0 * (cb - ca), ra * ra - rb * rb + cb.squaredNorm() - ca.squaredNorm());
  };
  for (size_t a = 0; a < balls.size(); ++a)
    for (size_t b = a + 1; b < balls.size(); ++b) {
      const auto& [ca, ra] = balls[a];
      const auto& [cb, rb] = balls[b];
      const double d = (cb - ca).norm();
      if (d >= ra + rb || d <= std::abs(ra - rb)) continue;
      const Eigen::Vector3d u = (cb - ca) / d;
      const double along = (d * d + ra * ra - rb * rb) / (2.0 * d);
      const double rho = std::sqrt(ra * ra - along * along);
      const double centre_z = ca.z() + along * u.z();
      events.push_back(centre_z - rho * std::sqrt(std::max(0.0, 1.0 - u.z() * u.z())));
      events.push_back(centre_z + rho * std::sqrt(std::max(0.0, 1.0 - u.z() * u.z())));
      for (size_t k = b + 1; k < balls.size(); ++k) {
        const auto [n1, h1] = radical(a, b);
        const auto [n2, h2] = radical(a, k);
        const Eigen::Vector3d direction = n1.cross(n2);
        if (direction.norm() < 1e-12) continue;
        Eigen::Matrix3d m;
        m.row(0) = n1;
        m.row(1) = n2;
        m.row(2) = direction;
        const Eigen::Vector3d point = m.fullPivLu().solve(Eigen::Vector3d(h1, h2, 0.0)) - ca;
        const double qa = direction.squaredNorm(), qb = point.dot(direction),
                     qc = point.squaredNorm() - ra * ra, disc = qb * qb - qa * qc;
        if (disc > 0)
          for (double sign : {-1.0, 1.0})
            events.push_back(ca.z() +
                             (point + (-qb + sign * std::sqrt(disc)) / qa * direction).z());
      }
    }
  return IntegratePiecewise(events, z_low, z_high, [&](double z) {
    std::vector<Circle> slice;
    double x_low = 1e300, x_high = -1e300;
    for (const auto& [c, r] : balls) {
      const double s = r * r - (z - c.z()) * (z - c.z());
      if (s <= 0.0) continue;
      slice.push_back({c.x(), c.y(), std::sqrt(s)});
      x_low = std::min(x_low, c.x() - std::sqrt(s));
      x_high = std::max(x_high, c.x() + std::sqrt(s));
    }
    if (slice.empty()) return 0.0;
    return UnionArea(
        slice, [](double) { return std::pair<double, double>(-1e300, 1e300); }, {}, x_low, x_high);
  });
}

}  // namespace specimen::reference
