#pragma once
// What the bonded exports (lab/yade_export.h, lab/esys_export.h) share: the bonds they
// carry (the listed pairs this toolkit's solver bonds), the check of a parameter set against
// what a rigid-sphere bond of another code can hold, and Python literals for their scripts.

#include <array>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "generator/packing.h"
#include "solver/material.h"

namespace specimen {

// The bonds an export creates: the listed pairs with |gap| <= tolerance x (ri + rj)/2, the
// solver's rule (solver/simulation.cpp, Madan (2.21)).
template <int Dim>
std::vector<std::array<int, 2>> ExportedBonds(const Packing<Dim>& packing, double bond_gap_tolerance);

// Throws InputError, naming `source` and the field, for a set the target's bond cannot
// carry: an invalid set, deformable particles (DDEM), bonds with a moment (`moment_reason`
// says why the target cannot), bonds within a range (bond_range > 1) or unbreakable bonds.
void RequireRigidPairBonds(const MaterialParameters& material, const std::string& source, const std::string& target,
                           const std::string& moment_reason);

// Throws InputError unless the tolerance is in [0, 1] and the packing has particles.
template <int Dim>
void RequireBondedExportable(const Packing<Dim>& packing, double bond_gap_tolerance, const std::string& format);

// A Python literal: the number written exactly, or None.
std::string PythonNumber(const std::optional<double>& value);

// Text safe in a one-line Python comment or string: at most 200 characters, line breaks and
// quotes replaced.
std::string PythonText(const std::string& text);

// The script lines "KN = ..." to "DENSITY = ...": the constants of `material` written exactly,
// or None for each when there is none (the script then stops, naming them).
void WritePythonMaterialConstants(const MaterialParameters* material, std::ostream& out);

// A Python function `report(result, json_path)` that prints the result dictionary as JSON and
// writes it to json_path when given: the end of every bonded export's script.
extern const char* const kPythonReportFunction;

}  // namespace specimen
