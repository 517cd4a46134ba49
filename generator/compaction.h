#pragma once
// Compaction stage of the generator: force-biased growth of all radii by one common
// factor until the packing jams (r_max / r_min is kept).
//
// The least-squares rounds leave a packing that is already jammed for its radii (3D,
// 30k spheres: porosity 36.7 %, nc 6.5, and a growth of 0.1 % leaves overlaps no
// relaxation removes). Growing it in place gives nothing; it has to be rearranged. This is
// the force-biased algorithm (Mościński, Bargieł, Rycerz & Jacobs 1989) with the
// Jodrey-Tory schedule: an outer scale of the radii starts above what fits (1 +
// initial_growth) and contracts towards the inner scale (the largest factor at which nothing
// overlaps at the current centres) by `contraction` of their distance per sweep. Every
// sweep pushes each overlapping pair apart along its line of centres by its overlap (raised
// to `exponent`, normalised by the largest overlap of the previous sweep), the smaller
// particle moving most (shares in inverse proportion to the radii), and pushes protruding
// particles back inside (Gauss-Seidel order). The two scales meet at a jammed packing,
// which is returned at the inner scale: nothing overlaps or protrudes. A run that meets
// the inner scale without real contraction was not jammed and inflates again. If the
// result is looser than the input, the input is kept.
//
// Measured on the 3D output of the rounds: porosity 36.7 -> 35.3 %, but nc 6.5 -> 5.4 (a
// jammed frictionless packing is isostatic, nc ~6 less its rattlers); the generator
// therefore lets a least-squares round follow that closes the near-contacts (generate.h).

#include <vector>

#include "generator/domain.h"

namespace specimen {

struct CompactionOptions {
  // Length scale of the tolerances below (the mean radius).
  double length_scale = 1.0;
  // Displacement of a pair ~ overlap * (overlap / largest overlap)^(exponent - 1):
  // 1 = proportional to the overlap (Mościński et al.); larger values work on the worst
  // overlaps first. In [0.5, 4].
  double exponent = 1.0;
  // The outer scale starts at 1 + initial_growth (relative to the input radii).
  double initial_growth = 0.08;
  // Share of the distance between outer and inner scale the outer one contracts by per
  // sweep: slower contraction, denser packing, more sweeps.
  double contraction = 0.001;
  // The schedule ends when outer and inner scale agree to this relative tolerance.
  double tolerance = 1e-4;
  // Sweep budget of the schedule (bounds the run time).
  int max_sweeps = 4000;
  // Verlet skin of the candidate pairs, relative to length_scale.
  double skin = 1.0;
};

struct CompactionSummary {
  double growth_factor = 1.0;  // common radius factor reached (before the projection)
  bool kept_input = false;     // the schedule ended looser than the input: input kept
  int sweeps = 0;              // relaxation sweeps over all pairs
  int neighbour_rebuilds = 0;
  double seconds = 0.0;
};

// Compacts the packing in place (centres and radii); the result has no overlap and no
// protrusion (up to round-off, which the generator's final projection removes).
template <int Dim>
CompactionSummary CompactPacking(const Domain<Dim>& domain, const CompactionOptions& options,
                                 std::vector<Vector<Dim>>& x, std::vector<double>& r);

}  // namespace specimen
