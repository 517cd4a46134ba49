#pragma once
// The Packing: what generate-packing produces and every later stage consumes. A value
// type: the domain, the particle centres and radii, and the contact list (the pairs that
// become bonds downstream). Conventions (docs/solver.md, "Conventions"): gap
// g = |xj - xi| - ri - rj, negative = overlap.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "generator/domain.h"

namespace specimen {

template <int Dim>
struct Packing {
  Domain<Dim> domain;
  std::vector<Vector<Dim>> centres;
  std::vector<double> radii;
  // Particle pairs (i < j, sorted) in contact: |gap| <= contact_tolerance * mean radius.
  std::vector<std::array<int, 2>> contacts;
  // The tolerance used to build `contacts`, relative to the volume-based mean radius.
  double contact_tolerance = 0.0;
  // Provenance, written into the packing file.
  std::string created_by;  // program and version
  std::uint64_t seed = 0;

  explicit Packing(const Domain<Dim>& d) : domain(d) {}

  int size() const { return static_cast<int>(radii.size()); }
  double Gap(int i, int j) const { return (centres[j] - centres[i]).norm() - radii[i] - radii[j]; }
};

// Gap of particles i and j given as arrays (the stages that work on bare centres and radii).
template <int Dim>
inline double PairGap(const std::vector<Vector<Dim>>& centres, const std::vector<double>& radii,
                      int i, int j) {
  return (centres[i] - centres[j]).norm() - radii[i] - radii[j];
}

// Removes the particles flagged in `remove`, keeping the order of the others; `marks`
// (per-particle flags) are compacted alongside. Returns the number removed.
template <int Dim>
int RemoveFlaggedParticles(const std::vector<char>& remove, std::vector<Vector<Dim>>& centres,
                           std::vector<double>& radii, std::vector<char>* marks = nullptr);

// Volume-based mean radius (Labra 3.12): (sum r^D / N)^(1/D).
template <int Dim>
double VolumeMeanRadius(const std::vector<double>& radii);

// Volume of a particle: pi r^2 (2D, per unit thickness) or 4/3 pi r^3.
template <int Dim>
double ParticleVolume(double radius);

// Nominal porosity (Labra 3.13): 1 - sum of particle volumes / domain volume (overlaps
// counted twice).
template <int Dim>
double NominalPorosity(const Domain<Dim>& domain, const std::vector<double>& radii);

// Rebuilds packing.contacts as every pair with |gap| <= tolerance * mean radius among
// the candidate pairs (any pair list, e.g. triangulation edges), sorted and unique.
template <int Dim>
void SetContactsFromCandidates(Packing<Dim>& packing,
                               const std::vector<std::array<int, 2>>& candidates,
                               double tolerance);

}  // namespace specimen
