#pragma once
// The jaws of a Brazilian test with a loading arc 2 alpha: each presses the surface particles
// within alpha of its pole with a uniform radial pressure (Hondros 1959), a conforming jaw of
// the solver (solver/walls.h). Under a point load the largest shear along the loaded diameter
// lies next to the contacts, so a disc whose shear strength is not several times its tensile
// strength is sheared there before it splits from the centre; over an arc the centre's
// tensile stress, k 2 F / (pi D t), governs (docs/sources.md, "The loading arc").
//
//   const auto jaws = BrazilianJawArcs<2>(packing, 30.0);   // bottom, top
//   wall.jaw_particles = jaws[1].particles; ...
//   sigma_t = HondrosFactor(30.0) * 2 F / (pi D t);          // k = 0.920

#include <array>
#include <vector>

#include "generator/packing.h"
#include "solver/vector_algebra.h"

namespace specimen {

template <int Dim>
struct JawArc {
  std::vector<int> particles;          // indices into the packing
  std::vector<double> weights;         // the force shares, sum 1
  std::vector<Vector<Dim>> inward;     // unit, from the particle towards the disc's axis
};

// The surface particles (within 5 % of their radius of the disc's circle, or the cylinder's
// mantle) whose centres lie within alpha = loading_arc_deg / 2 of the poles on the y axis:
// [0] the bottom jaw's, [1] the top jaw's. 2D: each particle's share is half the angle to its
// neighbours on the surface, clipped to the arc; 3D: its cross-section pi r^2 (the particles tile the mantle's
// strip); then corrected to the nearest shares whose forces balance (no net lateral force;
// in 3D, no moment about the centre). InputError if the domain is not a disc or cylinder, loading_arc_deg is outside
// (0, 60], or an arc holds no surface particle.
template <int Dim>
std::array<JawArc<Dim>, 2> BrazilianJawArcs(const Packing<Dim>& packing, double loading_arc_deg);

// Hondros's factor k = (sin 2 alpha - alpha) / sin alpha of the centre's tensile stress
// k 2 F / (pi D t) under a uniform radial pressure over the arc 2 alpha with resultant F;
// 1 for a point load (loading_arc_deg = 0).
double HondrosFactor(double loading_arc_deg);

}  // namespace specimen
