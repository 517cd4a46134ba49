#pragma once
// The codes of particles, contacts and bonds in the output files, one table for every file
// (docs/exports.md, "Units and names in the output files"): the VTU cell array "kind" of
// generate-packing and run-test and the "kind" column of run-test's _bonds.csv and
// _cracks.csv. A ParaView threshold and a filter on a CSV file then use the same numbers.

namespace specimen {

enum class ElementKind : int {
  kParticle = 0,          // a VTU vertex cell
  kContact = 1,           // a contact of a packing, or an intact bond
  kBrokenInTension = 2,   // a bond broken by its normal force
  kBrokenInShear = 3,     // a bond broken by its tangential force
};

inline int Code(ElementKind kind) { return static_cast<int>(kind); }

}  // namespace specimen
