#pragma once
// Volume (area in 2D, per unit thickness) of the union of the particles clipped to the
// domain: the solid fraction behind the overlap-corrected porosity.
//
// Power-diagram decomposition. The power cells P_i = {x : |x - x_i|^2 - r_i^2 <=
// |x - x_j|^2 - r_j^2 for all j} tile space, and a point of the union lies in the particle
// of its own cell (its power w.r.t. that particle is the smallest, hence <= 0). So the
// union is the disjoint union of B_i ∩ P_i. The power bisector of two particles that do
// not overlap separates them (a point of the bisector inside B_i would have power < 0 for
// both, i.e. lie in B_i ∩ B_j), so B_i ∩ P_i only depends on the neighbours j that overlap
// i: B_i ∩ P_i = B_i ∩ (∩_{j overlapping i} H_ij) with the half-space
//   H_ij = {y : n . y <= h},  n = (x_j - x_i)/L,  h = (L^2 + r_i^2 - r_j^2) / (2 L),
// L = |x_j - x_i| (y measured from x_i). Hence
//   |union ∩ domain| = sum_i |B_i ∩ (∩_j H_ij) ∩ domain|,
// a particle with no overlapping neighbour and inside the domain contributing its full
// volume. 2D pieces are exact (disc_clip_area.h); 3D pieces are exact when their cut caps
// are disjoint and bracketed with a guaranteed bound otherwise (ball_clip_volume.h).
// Identical particles (same centre and radius) are resolved by index: the lower one keeps
// the shared volume.

#include <array>
#include <vector>

#include "generator/packing.h"

namespace specimen {

struct ClippedUnion {
  double volume = 0.0;       // |union of the particles ∩ domain|
  double error_bound = 0.0;  // |true volume - volume| <= error_bound (2D: 0, exact up to round-off)
  int cut_particles = 0;     // particles cut by an overlapping neighbour or the boundary
  int sliced_particles = 0;  // 3D: cut particles without a closed form (bracketed by slices)
};

// `overlapping_pairs`: every pair i < j with a negative gap (OverlappingPairs()); pairs
// that do not overlap are harmless, missing ones are not. 3D: `target_error` is the
// absolute volume allowed for the sum of the error bounds, spread evenly over the sliced
// particles; `max_slices_per_sphere` caps the slice evaluations of one sphere (the bound
// reported is the one reached).
template <int Dim>
ClippedUnion ClippedUnionOfParticles(const Packing<Dim>& packing,
                                     const std::vector<std::array<int, 2>>& overlapping_pairs,
                                     double target_error, int max_slices_per_sphere);

}  // namespace specimen
