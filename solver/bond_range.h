#pragma once
// The pairs a specimen's bonds are made from: the packing's contact list and, with an
// interaction range gamma > 1 (MaterialParameters::bond_range), every other pair whose
// centres lie within gamma (ri + rj). Near neighbours are then bonded at their initial
// distance, stress-free like every bond here (their initial gap is the bond's zero-force gap),
// as Yade's JCFpm bonds them within its interactionDetectionFactor; the strength ratio
// sigma_c / sigma_t of bonded spheres grows with the bonded coordination number (Scholtes and
// Donze 2013). Once broken, such a pair acts only when its particles touch.
//
// The Simulation bonds these pairs and the stability network counts their springs: both
// take them from this one list, so the certified time step sees every bond.
//
//   std::vector<std::array<int, 2>> pairs = BondCandidatePairs(packing, material.bond_range);

#include <array>
#include <vector>

#include "generator/packing.h"

namespace specimen {

// The packing's contact pairs (indices validated by the caller) with i < j, and with
// bond_range > 1 every pair whose centre distance is at most bond_range (ri + rj); sorted by
// (i, j), without duplicates. bond_range >= 1.
template <int Dim>
std::vector<std::array<int, 2>> BondCandidatePairs(const Packing<Dim>& packing, double bond_range);

// Whether a pair at `distance` with radii ri, rj lies within the interaction range (always
// false for bond_range <= 1: the packing's list alone decides).
inline bool WithinBondRange(double distance, double ri, double rj, double bond_range) {
  return bond_range > 1.0 && distance <= bond_range * (ri + rj);
}

}  // namespace specimen
