#include "generator/union_volume.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "common/error.h"
#include "generator/ball_clip_volume.h"
#include "generator/disc_clip_area.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Below this many particles the work is smaller than starting threads (and idle threads
// spinning on a busy machine).
constexpr int kParallelParticles = 2000;

// Neighbours that overlap each particle, in compressed rows: neighbours[offsets[i] ..
// offsets[i + 1]).
struct Adjacency {
  std::vector<int> offsets;
  std::vector<int> neighbours;
};

Adjacency BuildAdjacency(int particle_count, const std::vector<std::array<int, 2>>& pairs) {
  Adjacency adjacency;
  adjacency.offsets.assign(particle_count + 1, 0);
  for (const auto& pair : pairs) {
    if (pair[0] < 0 || pair[1] < 0 || pair[0] >= particle_count || pair[1] >= particle_count)
      throw InputError("union volume: overlapping pair (" + std::to_string(pair[0]) + ", " +
                       std::to_string(pair[1]) + ") refers to a particle out of range");
    if (pair[0] == pair[1]) continue;
    ++adjacency.offsets[pair[0] + 1];
    ++adjacency.offsets[pair[1] + 1];
  }
  for (int i = 0; i < particle_count; ++i) adjacency.offsets[i + 1] += adjacency.offsets[i];
  adjacency.neighbours.resize(adjacency.offsets.back());
  std::vector<int> fill(adjacency.offsets.begin(), adjacency.offsets.end() - 1);
  for (const auto& pair : pairs) {
    if (pair[0] == pair[1]) continue;
    adjacency.neighbours[fill[pair[0]]++] = pair[1];
    adjacency.neighbours[fill[pair[1]]++] = pair[0];
  }
  return adjacency;
}

enum class PowerCut { kNone, kHalfSpace, kEmpty };

// The power half-space H_ij of particle i against j, in coordinates centred on x_i and
// scaled by r_i (see union_volume.h). Concentric particles: the larger one (or, for equal
// radii, the lower index) keeps the volume; the other is empty.
template <int Dim>
PowerCut PowerHalfSpace(const Packing<Dim>& packing, int i, int j, Vector<Dim>* normal,
                        double* offset) {
  const double radius = packing.radii[i];
  const Vector<Dim> branch = (packing.centres[j] - packing.centres[i]) / radius;
  const double length = branch.norm();
  const double radius_ratio = packing.radii[j] / radius;
  if (length == 0.0) {
    if (radius_ratio > 1.0 || (radius_ratio == 1.0 && j < i)) return PowerCut::kEmpty;
    return PowerCut::kNone;
  }
  *normal = branch / length;
  *offset = (length * length + 1.0 - radius_ratio * radius_ratio) / (2.0 * length);
  return PowerCut::kHalfSpace;
}

double DistanceToSegment(const Vector<2>& a, const Vector<2>& b, const Vector<2>& p) {
  const Vector<2> ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + t * ab - p).norm();
}

bool IsConvex(const std::vector<Vector<2>>& vertices) {  // counter-clockwise vertices
  const size_t n = vertices.size();
  for (size_t k = 0; k < n; ++k) {
    const Vector<2> incoming = vertices[(k + 1) % n] - vertices[k];
    const Vector<2> outgoing = vertices[(k + 2) % n] - vertices[(k + 1) % n];
    if (incoming.x() * outgoing.y() - incoming.y() * outgoing.x() < 0.0) return false;
  }
  return true;
}

// 2D: the clipped disc of particle i as a DiscClipProblem; false if it is empty.
bool BuildDiscProblem(const Packing<2>& packing, const Adjacency& adjacency, bool convex_polygon,
                      int i, DiscClipProblem* problem, bool* cut) {
  problem->Clear();
  *cut = false;
  const double radius = packing.radii[i];
  const Vector<2>& centre = packing.centres[i];
  for (int k = adjacency.offsets[i]; k < adjacency.offsets[i + 1]; ++k) {
    HalfPlane half_plane;
    switch (PowerHalfSpace<2>(packing, i, adjacency.neighbours[k], &half_plane.normal,
                              &half_plane.offset)) {
      case PowerCut::kEmpty:
        return false;
      case PowerCut::kNone:
        break;
      case PowerCut::kHalfSpace:
        problem->half_planes.push_back(half_plane);
        break;
    }
  }
  const Domain<2>& domain = packing.domain;
  if (domain.shape() == DomainShape::kDisc) {
    const double distance = (domain.CircleCentre() - centre).norm();
    if (distance >= domain.CircleRadius() + radius) return false;
    if (distance + radius > domain.CircleRadius()) {
      problem->use_domain_circle = true;
      problem->domain_centre = (domain.CircleCentre() - centre) / radius;
      problem->domain_radius = domain.CircleRadius() / radius;
    }
  } else {
    const double signed_distance = domain.SignedDistance(centre);
    if (signed_distance <= -radius) return false;
    if (signed_distance < radius) {
      const auto& vertices = domain.PolygonVertices();
      const size_t n = vertices.size();
      if (convex_polygon) {
        // A convex domain is the intersection of its edges' inner half-planes.
        for (size_t k = 0; k < n; ++k) {
          const Vector<2>& a = vertices[k];
          const Vector<2>& b = vertices[(k + 1) % n];
          HalfPlane half_plane;
          half_plane.normal = Vector<2>(b.y() - a.y(), a.x() - b.x()).normalized();  // outward
          half_plane.offset = half_plane.normal.dot(a - centre) / radius;
          if (half_plane.offset < 1.0) problem->half_planes.push_back(half_plane);
        }
      } else {
        problem->use_polygon = true;
        problem->centre_inside_polygon = signed_distance >= 0.0;
        auto local = [&](const Vector<2>& v) { return Vector<2>((v - centre) / radius); };
        for (size_t k = 0; k < n; ++k) {
          const Vector<2>& a = vertices[k];
          const Vector<2>& b = vertices[(k + 1) % n];
          if (DistanceToSegment(a, b, centre) >= radius) continue;
          PolygonEdge edge;
          edge.before = local(vertices[(k + n - 1) % n]);
          edge.start = local(a);
          edge.end = local(b);
          edge.after = local(vertices[(k + 2) % n]);
          problem->polygon_edges.push_back(edge);
        }
      }
    }
  }
  *cut = !problem->half_planes.empty() || problem->use_polygon || problem->use_domain_circle;
  return true;
}

// 3D: the clipped ball of particle i as a BallClipProblem; false if it is empty.
bool BuildBallProblem(const Packing<3>& packing, const Adjacency& adjacency, int i,
                      BallClipProblem* problem, bool* cut) {
  problem->Clear();
  *cut = false;
  const double radius = packing.radii[i];
  const Vector<3>& centre = packing.centres[i];
  for (int k = adjacency.offsets[i]; k < adjacency.offsets[i + 1]; ++k) {
    HalfSpace half_space;
    switch (PowerHalfSpace<3>(packing, i, adjacency.neighbours[k], &half_space.normal,
                              &half_space.offset)) {
      case PowerCut::kEmpty:
        return false;
      case PowerCut::kNone:
        break;
      case PowerCut::kHalfSpace:
        problem->half_spaces.push_back(half_space);
        break;
    }
  }
  const Domain<3>& domain = packing.domain;
  auto add_face = [&](int axis, double side, double offset) {
    if (offset >= 1.0) return;  // the face does not reach the ball
    HalfSpace half_space;
    half_space.normal = Vector<3>::Zero();
    half_space.normal[axis] = side;
    half_space.offset = offset;
    problem->half_spaces.push_back(half_space);
  };
  const Vector<3> lower = domain.Lower(), upper = domain.Upper();
  if (domain.shape() == DomainShape::kBox) {
    for (int axis = 0; axis < 3; ++axis) {
      add_face(axis, -1.0, (centre[axis] - lower[axis]) / radius);
      add_face(axis, 1.0, (upper[axis] - centre[axis]) / radius);
    }
  } else {
    add_face(2, -1.0, (centre.z() - domain.ZMin()) / radius);
    add_face(2, 1.0, (domain.ZMax() - centre.z()) / radius);
    const Vector<2> axis_offset = domain.CircleCentre() - centre.head<2>();
    const double distance = axis_offset.norm();
    if (distance >= domain.CircleRadius() + radius) return false;
    if (distance + radius > domain.CircleRadius()) {
      problem->use_mantle = true;
      problem->mantle_centre = axis_offset / radius;
      problem->mantle_radius = domain.CircleRadius() / radius;
    }
  }
  *cut = !problem->half_spaces.empty() || problem->use_mantle;
  return true;
}

}  // namespace

template <int Dim>
ClippedUnion ClippedUnionOfParticles(const Packing<Dim>& packing,
                                     const std::vector<std::array<int, 2>>& overlapping_pairs,
                                     double target_error, int max_slices_per_sphere) {
  const int count = packing.size();
  if (static_cast<int>(packing.centres.size()) != count)
    throw InputError("union volume: " + std::to_string(packing.centres.size()) + " centres but " +
                     std::to_string(count) + " radii");
  const Adjacency adjacency = BuildAdjacency(count, overlapping_pairs);
  // Per-particle results, summed in index order afterwards: the total does not depend on
  // the number of threads.
  std::vector<double> volume(count, 0.0), error(count, 0.0);
  std::vector<char> cut(count, 0), sliced(count, 0);

  if constexpr (Dim == 2) {
    const bool convex_polygon = packing.domain.shape() == DomainShape::kRectangle ||
                                (packing.domain.shape() == DomainShape::kPolygon &&
                                 IsConvex(packing.domain.PolygonVertices()));
#pragma omp parallel if (count > kParallelParticles)
    {
      DiscClipper clipper;
      DiscClipProblem problem;
#pragma omp for schedule(dynamic, 256)
      for (int i = 0; i < count; ++i) {
        const double radius = packing.radii[i];
        bool is_cut = false;
        if (!(radius > 0.0)) continue;
        if (!BuildDiscProblem(packing, adjacency, convex_polygon, i, &problem, &is_cut)) {
          cut[i] = 1;  // hidden by a neighbour or outside the domain
          continue;
        }
        cut[i] = is_cut ? 1 : 0;
        volume[i] = (is_cut ? clipper.Area(problem) : kPi) * radius * radius;
      }
    }
  } else {
    // Phase 1: closed forms; phase 2: slices, with the error budget shared among the
    // particles that need them.
#pragma omp parallel if (count > kParallelParticles)
    {
      BallClipProblem problem;
#pragma omp for schedule(dynamic, 256)
      for (int i = 0; i < count; ++i) {
        const double radius = packing.radii[i];
        bool is_cut = false;
        if (!(radius > 0.0)) continue;
        if (!BuildBallProblem(packing, adjacency, i, &problem, &is_cut)) {
          cut[i] = 1;  // hidden by a neighbour or outside the domain
          continue;
        }
        cut[i] = is_cut ? 1 : 0;
        double unit_volume = 4.0 / 3.0 * kPi;
        if (is_cut && !BallClipper::ClosedForm(problem, &unit_volume)) {
          sliced[i] = 1;
          continue;
        }
        volume[i] = unit_volume * radius * radius * radius;
      }
    }
    std::vector<int> to_slice;
    for (int i = 0; i < count; ++i)
      if (sliced[i]) to_slice.push_back(i);
    // With second-order brackets a sphere needs ~ sqrt(r^3 / tolerance) slices; the total
    // is smallest for tolerances in proportion to r (Lagrange): share the budget so.
    double radius_sum = 0.0;
    for (int i : to_slice) radius_sum += packing.radii[i];
    const int slice_count = static_cast<int>(to_slice.size());
#pragma omp parallel if (slice_count > 8)
    {
      BallClipper clipper;
      BallClipProblem problem;
#pragma omp for schedule(dynamic, 16)
      for (int k = 0; k < slice_count; ++k) {
        const int i = to_slice[k];
        const double radius = packing.radii[i];
        const double cube = radius * radius * radius;
        bool is_cut = false;
        BuildBallProblem(packing, adjacency, i, &problem, &is_cut);
        const double share = target_error * radius / radius_sum;
        // Below ~1e-12 of the ball the bracket only measures round-off.
        const double tolerance = std::max(share / cube, 1e-12);
        const ClippedVolume piece = clipper.Volume(problem, tolerance, max_slices_per_sphere);
        volume[i] = piece.volume * cube;
        error[i] = piece.error_bound * cube;
      }
    }
  }

  ClippedUnion result;
  for (int i = 0; i < count; ++i) {
    result.volume += volume[i];
    result.error_bound += error[i];
    result.cut_particles += cut[i];
    result.sliced_particles += sliced[i];
  }
  return result;
}

template ClippedUnion ClippedUnionOfParticles<2>(const Packing<2>&,
                                                 const std::vector<std::array<int, 2>>&, double,
                                                 int);
template ClippedUnion ClippedUnionOfParticles<3>(const Packing<3>&,
                                                 const std::vector<std::array<int, 2>>&, double,
                                                 int);

}  // namespace specimen
