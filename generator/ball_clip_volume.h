#pragma once
// Volume of a ball clipped by half-spaces and, optionally, by the mantle of a z-axis
// cylinder, with a guaranteed error bound. The 3D building block of the overlap-corrected
// porosity (union_volume.h): a sphere cut by its power cell and the domain.
//
// Closed form where it exists: an uncut ball, or caps cut off by planes that do not
// reach the centre and do not meet each other inside the ball (4/3 pi - sum of caps).
//
// Otherwise the region K = ball ∩ half-spaces ∩ cylinder is convex, and it is sliced
// along z: each slice is a disc clipped by lines and a circle, whose area A(z) is exact
// (disc_clip_area.h). By Brunn's concavity principle, f(z) = sqrt(A(z)) is concave on
// the z-support of a convex body. Between two samples in the support f lies above the
// chord, and beyond a pair of samples it lies below the extension of their secant (and
// always below the slice of the ball, sqrt(pi (1 - z^2))). Integrating the squares of
// these lower and upper envelopes gives a rigorous bracket [V_lower, V_upper] of the
// volume; slices are added where the bracket is widest until its half-width is within
// the tolerance. Slabs that no plane and no mantle cuts are integrated in closed form.
// The value returned is the midpoint of the bracket, the error bound its half-width.
// No assumption is made about where the ball centre lies, so deeply overlapped spheres
// (centre outside their own cell) need no special case; a region that no slice meets is
// proven empty (minimum-norm point of the half-spaces outside the ball) or, failing that,
// bounded conservatively.

#include <vector>

#include "generator/disc_clip_area.h"
#include "generator/domain.h"

namespace specimen {

// The half-space {y : normal . y <= offset}; normal has unit length.
struct HalfSpace {
  Vector<3> normal = Vector<3>::Zero();
  double offset = 0.0;
};

// unit ball ∩ half-spaces ∩ {|y_xy - mantle_centre| <= mantle_radius}, in coordinates
// centred on the ball and scaled so that it has radius 1.
struct BallClipProblem {
  std::vector<HalfSpace> half_spaces;
  bool use_mantle = false;
  Vector<2> mantle_centre = Vector<2>::Zero();
  double mantle_radius = 0.0;

  void Clear() {
    half_spaces.clear();
    use_mantle = false;
  }
};

struct ClippedVolume {
  double volume = 0.0;       // in units of the cubed radius (4/3 pi for an uncut ball)
  double error_bound = 0.0;  // |true volume - volume| <= error_bound (0: closed form)
  int slices = 0;            // slice areas evaluated (0: closed form)
};

class BallClipper {
 public:
  // The closed form, when it applies (see the file comment); false if slicing is needed.
  static bool ClosedForm(const BallClipProblem& problem, double* volume);

  // The volume, by the closed form or by slices until error_bound <= tolerance (in units of
  // the cubed radius) or max_slices slice areas have been evaluated.
  ClippedVolume Volume(const BallClipProblem& problem, double tolerance, int max_slices);

 private:
  struct SlicePlane {  // a half-space seen in the slice at height z: direction . y <= (offset -
                       // normal_z z) / length
    Vector<2> direction;
    double length, normal_z, offset;
  };
  enum class Slab { kBracketed, kFull, kEmpty };

  double SliceArea(double z);
  // Lower and upper bounds of the volume between samples i and i + 1 (bracketed slab).
  void SlabBounds(int i, bool any_positive, double* lower, double* upper) const;
  // Adds a slice at z (kept sorted; the slab it falls in is split and keeps its kind).
  void AddSample(double z);

  std::vector<SlicePlane> planes_;
  bool use_mantle_ = false;
  Vector<2> mantle_centre_ = Vector<2>::Zero();
  double mantle_radius_ = 0.0;
  DiscClipper disc_clipper_;
  DiscClipProblem slice_problem_;
  // Samples z_[k], f_[k] = sqrt(A(z_[k])), ascending in z; slab_[k] is the kind of the
  // slab between samples k and k + 1.
  std::vector<double> z_, f_;
  std::vector<Slab> slab_;
  int evaluations_ = 0;
};

// The point of {y : n_k . y <= h_k for all k} nearest to the origin. Returns false when the
// half-spaces have no common point. Seidel's incremental algorithm for LP-type problems:
// a half-space violated by the optimum of the previous ones is active at the new optimum.
bool MinimumNormPoint(const std::vector<HalfSpace>& half_spaces, Vector<3>* point);

}  // namespace specimen
