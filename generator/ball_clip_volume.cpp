#include "generator/ball_clip_volume.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTolerance = kDiscClipTolerance;
// A half-space whose normal is this close to +-z is treated as a bound on z.
constexpr double kHorizontal = 1e-14;
// Each run of cut slabs starts with this many equal sub-slabs (refinement adds more).
constexpr int kInitialSplit = 4;

// Volume of the cap of the unit ball beyond the plane at distance h in [0, 1) from the
// centre: pi (1 - h)^2 (2 + h) / 3.
double CapVolume(double h) { return kPi * (1.0 - h) * (1.0 - h) * (2.0 + h) / 3.0; }

// Volume of the unit ball between heights a and b: the integral of pi (1 - z^2).
double BallSlab(double a, double b) {
  a = std::clamp(a, -1.0, 1.0);
  b = std::clamp(b, -1.0, 1.0);
  return kPi * ((b - a) - (b * b * b - a * a * a) / 3.0);
}

double BallSliceSquared(double z) { return kPi * std::max(0.0, 1.0 - z * z); }

// The line through (z0, f0) with the given slope: a secant of the concave f, extended.
struct Secant {
  double z0, f0, slope;
  double At(double z) const { return f0 + slope * (z - z0); }
};

// Simpson's rule: exact for the quadratics integrated here.
template <class Function>
double Simpson(double a, double b, Function&& g) {
  return (b - a) / 6.0 * (g(a) + 4.0 * g(0.5 * (a + b)) + g(b));
}

// Integral over [a, b] of U^2 with U = max(0, min(ball slice, secants)), the upper
// envelope of f = sqrt(A). Between the points where the minimum switches (secant zeros,
// secant-secant and secant-ball crossings) U^2 is one quadratic, integrated exactly.
double IntegrateUpperSquared(double a, double b, const Secant* first, const Secant* second) {
  double breaks[12];
  int count = 0;
  breaks[count++] = a;
  breaks[count++] = b;
  auto add = [&](double z) {
    if (z > a && z < b) breaks[count++] = z;
  };
  for (const Secant* secant : {first, second}) {
    if (secant == nullptr) continue;
    if (secant->slope != 0.0) add(secant->z0 - secant->f0 / secant->slope);
    // (p + q z)^2 = pi (1 - z^2)  <=>  (q^2 + pi) z^2 + 2 p q z + p^2 - pi = 0
    const double p = secant->f0 - secant->slope * secant->z0, q = secant->slope;
    const double qa = q * q + kPi, qb = 2.0 * p * q, qc = p * p - kPi;
    const double discriminant = qb * qb - 4.0 * qa * qc;
    if (discriminant >= 0.0) {
      const double root = std::sqrt(discriminant);
      add((-qb - root) / (2.0 * qa));
      add((-qb + root) / (2.0 * qa));
    }
  }
  if (first != nullptr && second != nullptr && first->slope != second->slope)
    add((second->At(0.0) - first->At(0.0)) / (first->slope - second->slope));
  for (int k = 1; k < count; ++k)  // insertion sort of at most 9 values
    for (int m = k; m > 0 && breaks[m] < breaks[m - 1]; --m) std::swap(breaks[m], breaks[m - 1]);
  auto upper_squared = [&](double z) {
    double u = std::sqrt(BallSliceSquared(z));
    if (first != nullptr) u = std::min(u, first->At(z));
    if (second != nullptr) u = std::min(u, second->At(z));
    u = std::max(u, 0.0);
    return u * u;
  };
  double sum = 0.0;
  for (int k = 0; k + 1 < count; ++k)
    if (breaks[k + 1] > breaks[k]) sum += Simpson(breaks[k], breaks[k + 1], upper_squared);
  return sum;
}

// Minimum-norm point on the intersection of the planes n_k . y = h_k, k in `active`.
bool MinimumNormOnPlanes(const std::vector<HalfSpace>& half_spaces, const int* active, int count,
                         Vector<3>* point) {
  if (count == 0) {
    point->setZero();
    return true;
  }
  Eigen::Matrix3d gram = Eigen::Matrix3d::Identity();
  Eigen::Vector3d offsets = Eigen::Vector3d::Zero();
  for (int a = 0; a < count; ++a) {
    offsets[a] = half_spaces[active[a]].offset;
    for (int b = 0; b < count; ++b)
      gram(a, b) = half_spaces[active[a]].normal.dot(half_spaces[active[b]].normal);
  }
  if (std::abs(gram.determinant()) < 1e-20) return false;  // parallel planes: no common point
  const Eigen::Vector3d multipliers = gram.partialPivLu().solve(offsets);
  point->setZero();
  for (int a = 0; a < count; ++a) *point += multipliers[a] * half_spaces[active[a]].normal;
  return true;
}

bool MinimumNormRecursive(const std::vector<HalfSpace>& half_spaces, int count, int* active,
                          int active_count, Vector<3>* point) {
  if (!MinimumNormOnPlanes(half_spaces, active, active_count, point)) return false;
  for (int k = 0; k < count; ++k) {
    if (half_spaces[k].normal.dot(*point) <= half_spaces[k].offset + 1e-12) continue;
    if (active_count == 3) return false;  // the point is fixed and violates k: empty
    active[active_count] = k;
    if (!MinimumNormRecursive(half_spaces, k, active, active_count + 1, point)) return false;
  }
  return true;
}

}  // namespace

bool MinimumNormPoint(const std::vector<HalfSpace>& half_spaces, Vector<3>* point) {
  int active[3];
  return MinimumNormRecursive(half_spaces, static_cast<int>(half_spaces.size()), active, 0, point);
}

bool BallClipper::ClosedForm(const BallClipProblem& problem, double* volume) {
  // Empty region: a half-space (or the mantle) leaves at most a sliver of the ball.
  for (const HalfSpace& half_space : problem.half_spaces)
    if (half_space.offset <= -1.0 + kTolerance) {
      *volume = 0.0;
      return true;
    }
  if (problem.use_mantle) {
    const double distance = problem.mantle_centre.norm();
    if (distance >= problem.mantle_radius + 1.0 - kTolerance) {
      *volume = 0.0;
      return true;
    }
    if (distance + 1.0 > problem.mantle_radius + kTolerance) return false;  // the mantle cuts
  }
  // Caps beyond planes at distance h >= 0 are disjoint when their spherical caps are:
  // angle(n_k, n_l) >= alpha_k + alpha_l with cos(alpha) = h (for h >= 0 a point of the
  // solid caps' intersection, pushed out radially, lies in both spherical caps).
  const auto& planes = problem.half_spaces;
  double removed = 0.0;
  for (size_t k = 0; k < planes.size(); ++k) {
    const double h_k = planes[k].offset;
    if (h_k >= 1.0 - kTolerance) continue;
    if (h_k < 0.0) return false;
    const double sine_k = std::sqrt(1.0 - h_k * h_k);
    for (size_t l = k + 1; l < planes.size(); ++l) {
      const double h_l = planes[l].offset;
      if (h_l >= 1.0 - kTolerance) continue;
      if (h_l < 0.0) return false;
      const double cosine_of_sum = h_k * h_l - sine_k * std::sqrt(1.0 - h_l * h_l);
      if (planes[k].normal.dot(planes[l].normal) > cosine_of_sum) return false;
    }
    removed += CapVolume(h_k);
  }
  *volume = 4.0 / 3.0 * kPi - removed;
  return true;
}

double BallClipper::SliceArea(double z) {
  ++evaluations_;
  const double radius_squared = 1.0 - z * z;
  if (radius_squared <= 0.0) return 0.0;
  const double radius = std::sqrt(radius_squared);
  slice_problem_.Clear();
  for (const SlicePlane& plane : planes_) {
    HalfPlane half_plane;
    half_plane.normal = plane.direction;
    half_plane.offset = (plane.offset - plane.normal_z * z) / (plane.length * radius);
    slice_problem_.half_planes.push_back(half_plane);
  }
  if (use_mantle_) {
    slice_problem_.use_domain_circle = true;
    slice_problem_.domain_centre = mantle_centre_ / radius;
    slice_problem_.domain_radius = mantle_radius_ / radius;
  }
  return disc_clipper_.Area(slice_problem_) * radius_squared;
}

void BallClipper::SlabBounds(int i, bool any_positive, double* lower, double* upper) const {
  const double a = z_[i], b = z_[i + 1];
  switch (slab_[i]) {
    case Slab::kFull:
      *lower = *upper = BallSlab(a, b);
      return;
    case Slab::kEmpty:
      *lower = *upper = 0.0;
      return;
    case Slab::kBracketed:
      break;
  }
  const double fa = f_[i], fb = f_[i + 1];
  // Lower envelope: the chord, where both ends are in the support (f > 0); else 0.
  *lower = 0.0;
  if (fa > 0.0 && fb > 0.0) {
    const Secant chord{a, fa, (fb - fa) / (b - a)};
    *lower = Simpson(a, b, [&](double z) { return chord.At(z) * chord.At(z); });
  }
  if (fa == 0.0 && fb == 0.0) {
    // The support is one interval: if it holds a sample elsewhere, it misses this slab.
    *upper = any_positive ? 0.0 : BallSlab(a, b);
    return;
  }
  // Upper envelope: the neighbouring secants (both samples in the support), extended.
  const int n = static_cast<int>(z_.size());
  Secant left{0, 0, 0}, right{0, 0, 0};
  const bool use_left = i >= 1 && f_[i - 1] > 0.0 && fa > 0.0;
  const bool use_right = i + 2 < n && fb > 0.0 && f_[i + 2] > 0.0;
  if (use_left) left = {a, fa, (fa - f_[i - 1]) / (a - z_[i - 1])};
  if (use_right) right = {b, fb, (f_[i + 2] - fb) / (z_[i + 2] - b)};
  *upper = IntegrateUpperSquared(a, b, use_left ? &left : nullptr, use_right ? &right : nullptr);
  *upper = std::max(*upper, *lower);
}

void BallClipper::AddSample(double z) {
  const auto position = std::lower_bound(z_.begin(), z_.end(), z);
  if (position == z_.end() || *position == z || position == z_.begin()) return;
  const int index = static_cast<int>(position - z_.begin());
  const Slab kind = slab_[index - 1];
  z_.insert(z_.begin() + index, z);
  f_.insert(f_.begin() + index, std::sqrt(SliceArea(z)));
  slab_.insert(slab_.begin() + index, kind);
}

ClippedVolume BallClipper::Volume(const BallClipProblem& problem, double tolerance,
                                  int max_slices) {
  ClippedVolume result;
  if (ClosedForm(problem, &result.volume)) return result;
  evaluations_ = 0;

  // 1. Slicing set-up: horizontal half-spaces bound z; the others are lines in each
  //    slice; each plane cuts the slices only over the z-range of its circle on the
  //    sphere, the mantle only where the slice radius exceeds ||c| - R|.
  double z_low = -1.0, z_high = 1.0;
  planes_.clear();
  std::vector<std::array<double, 2>> cut_ranges;
  for (const HalfSpace& half_space : problem.half_spaces) {
    const double h = half_space.offset;
    if (h >= 1.0 - kTolerance) continue;
    const Vector<2> horizontal = half_space.normal.head<2>();
    const double length = horizontal.norm();
    if (length < kHorizontal) {
      if (half_space.normal.z() > 0.0)
        z_high = std::min(z_high, h / half_space.normal.z());
      else
        z_low = std::max(z_low, h / half_space.normal.z());
      continue;
    }
    planes_.push_back({horizontal / length, length, half_space.normal.z(), h});
    const double centre = h * half_space.normal.z();
    const double half_width = std::sqrt(1.0 - h * h) * length;
    cut_ranges.push_back({centre - half_width, centre + half_width});
  }
  use_mantle_ = false;
  if (problem.use_mantle &&
      problem.mantle_centre.norm() + 1.0 > problem.mantle_radius + kTolerance) {
    use_mantle_ = true;
    mantle_centre_ = problem.mantle_centre;
    mantle_radius_ = problem.mantle_radius;
    const double gap = std::abs(mantle_centre_.norm() - mantle_radius_);
    if (gap < 1.0) {
      const double half_width = std::sqrt(1.0 - gap * gap);
      cut_ranges.push_back({-half_width, half_width});
    }
  }
  if (!(z_high > z_low)) return result;

  // 2. Initial samples. Between the range ends, a slab no range cuts is either the full
  //    ball slice or empty throughout (closed form); runs of cut slabs are merged and start
  //    with kInitialSplit equal sub-slabs (the refinement puts further slices where the
  //    bracket is widest, which need not be at the range ends).
  std::vector<double> events = {z_low, z_high};
  for (const auto& range : cut_ranges)
    for (double z : range)
      if (z > z_low && z < z_high) events.push_back(z);
  std::sort(events.begin(), events.end());
  events.erase(std::unique(events.begin(), events.end()), events.end());
  z_.clear();
  f_.clear();
  slab_.clear();
  double run_begin = 0.0;
  bool in_run = false;
  auto end_run = [&](double run_end) {
    for (int part = 0; part < kInitialSplit; ++part) {
      z_.push_back(run_begin + (run_end - run_begin) * part / kInitialSplit);
      slab_.push_back(Slab::kBracketed);
    }
    in_run = false;
  };
  for (size_t e = 0; e + 1 < events.size(); ++e) {
    const double a = events[e], b = events[e + 1], middle = 0.5 * (a + b);
    bool cut = false;
    for (const auto& range : cut_ranges) cut = cut || (range[0] < middle && middle < range[1]);
    if (cut) {
      if (!in_run) run_begin = a;
      in_run = true;
      continue;
    }
    if (in_run) end_run(a);
    bool full = !use_mantle_ || mantle_centre_.norm() < mantle_radius_;
    for (const SlicePlane& plane : planes_) full = full && plane.normal_z * middle <= plane.offset;
    z_.push_back(a);
    slab_.push_back(full ? Slab::kFull : Slab::kEmpty);
  }
  if (in_run) end_run(events.back());
  z_.push_back(events.back());
  f_.resize(z_.size());
  for (size_t k = 0; k < z_.size(); ++k) f_[k] = std::sqrt(SliceArea(z_[k]));

  // 3. No slice meets the region: prove it empty (its polyhedral hull misses the ball),
  //    or find it from the hull's point nearest to the centre.
  auto any_positive = [&] {
    return std::any_of(f_.begin(), f_.end(), [](double f) { return f > 0.0; });
  };
  if (!any_positive()) {
    std::vector<HalfSpace> hull = problem.half_spaces;
    if (use_mantle_ && mantle_centre_.norm() > 1e-12) {
      // The tangent plane of the mantle facing the ball bounds the domain.
      const Vector<2> outward = -mantle_centre_.normalized();
      HalfSpace tangent;
      tangent.normal = Vector<3>(outward.x(), outward.y(), 0.0);
      tangent.offset = mantle_radius_ + mantle_centre_.dot(outward);
      hull.push_back(tangent);
    }
    Vector<3> nearest;
    if (!MinimumNormPoint(hull, &nearest) || nearest.squaredNorm() >= 1.0 - 1e-12) {
      result.slices = evaluations_;
      return result;  // empty
    }
    for (double offset : {0.0, -1e-3, 1e-3, -1e-2, 1e-2, -1e-1, 1e-1})
      AddSample(std::clamp(nearest.z() + offset, z_low, z_high));
    if (!any_positive()) {
      // The convex region lies within one slab between samples: bound it by the largest.
      double largest = 0.0;
      for (size_t k = 0; k + 1 < z_.size(); ++k)
        largest = std::max(largest, BallSlab(z_[k], z_[k + 1]));
      result.volume = result.error_bound = 0.5 * largest;
      result.slices = evaluations_;
      return result;
    }
  }

  // 4. Bracket and refine: bisect the slabs whose gap is above the mean until the
  //    half-width of the bracket is within the tolerance or the budget is spent. A slab's
  //    bounds depend on the samples next to it (i - 1 .. i + 2): only slabs near a new
  //    sample are bounded again.
  std::vector<double> lower(slab_.size()), upper(slab_.size());
  for (int i = 0; i < static_cast<int>(slab_.size()); ++i)
    SlabBounds(i, true, &lower[i], &upper[i]);
  std::vector<double> new_z, new_f, new_lower, new_upper;
  std::vector<Slab> new_slab;
  std::vector<char> fresh;
  double lower_total = 0.0, upper_total = 0.0;
  for (;;) {
    lower_total = upper_total = 0.0;
    int bracketed = 0;
    for (size_t i = 0; i < slab_.size(); ++i) {
      lower_total += lower[i];
      upper_total += upper[i];
      if (slab_[i] == Slab::kBracketed) ++bracketed;
    }
    const double gap_total = upper_total - lower_total;
    if (gap_total <= 2.0 * tolerance || evaluations_ >= max_slices || bracketed == 0) break;
    // Split the slabs with a gap above the mean (less a hair, so that equal gaps all
    // qualify despite rounding), largest first, within the budget.
    double threshold = 0.999 * gap_total / bracketed;
    const int budget = max_slices - evaluations_;
    int selected = 0;
    for (size_t i = 0; i < slab_.size(); ++i) selected += upper[i] - lower[i] >= threshold ? 1 : 0;
    if (selected > budget) {
      std::vector<double> gaps(slab_.size());
      for (size_t i = 0; i < slab_.size(); ++i) gaps[i] = upper[i] - lower[i];
      std::nth_element(gaps.begin(), gaps.begin() + (budget - 1), gaps.end(),
                       std::greater<double>());
      threshold = gaps[budget - 1];
    }
    new_z.clear();
    new_f.clear();
    new_slab.clear();
    new_lower.clear();
    new_upper.clear();
    fresh.clear();
    int added = 0;
    for (size_t i = 0; i < slab_.size(); ++i) {
      new_z.push_back(z_[i]);
      new_f.push_back(f_[i]);
      fresh.push_back(0);
      new_slab.push_back(slab_[i]);
      new_lower.push_back(lower[i]);
      new_upper.push_back(upper[i]);
      const double gap = upper[i] - lower[i];
      const double middle = 0.5 * (z_[i] + z_[i + 1]);
      if (slab_[i] == Slab::kBracketed && gap >= threshold && gap > 0.0 && added < budget &&
          middle > z_[i] && middle < z_[i + 1]) {
        new_z.push_back(middle);
        new_f.push_back(std::sqrt(SliceArea(middle)));
        fresh.push_back(1);
        new_slab.push_back(slab_[i]);
        new_lower.push_back(0.0);
        new_upper.push_back(0.0);
        ++added;
      }
    }
    new_z.push_back(z_.back());
    new_f.push_back(f_.back());
    fresh.push_back(0);
    if (added == 0) break;  // the slabs cannot be split further (round-off)
    z_.swap(new_z);
    f_.swap(new_f);
    slab_.swap(new_slab);
    lower.swap(new_lower);
    upper.swap(new_upper);
    const int samples = static_cast<int>(z_.size());
    for (int i = 0; i + 1 < samples; ++i) {
      bool near_fresh = false;
      for (int k = std::max(0, i - 1); k <= std::min(samples - 1, i + 2); ++k)
        near_fresh = near_fresh || fresh[k];
      if (near_fresh) SlabBounds(i, true, &lower[i], &upper[i]);
    }
  }
  result.volume = 0.5 * (lower_total + upper_total);
  result.error_bound = 0.5 * (upper_total - lower_total);
  result.slices = evaluations_;
  return result;
}

}  // namespace specimen
