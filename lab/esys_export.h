#pragma once
// The bonded specimen for ESyS-Particle (docs/exports.md, "ESyS-Particle: the bonded
// specimen"): a geometry file (`LSMGeometry 1.2`: the particles and the bonds, each bond
// tagged with its group) and a Python script, run with
// `mpirun -np 2 esysparticle <script> --run at-rest`, that builds the bonds with this
// toolkit's constants (kn, kt, Rn, Rt, mu) and checks that they start at rest.
//
// ESyS-Particle 2.3.5 has no bond whose normal spring is both at rest at the initial distance
// and paired with a shear spring: its rotational bond (RotBondPrms, BrittleBeamPrms) and
// NRotBondPrms measure the normal stretch from ri + rj, so a bond across a gap starts with
// the force kn x gap. Its short bond (NRotShortBondPrms) takes the initial distance d0 as
// rest length. Each bond of the packing is therefore two ESyS bonds on the same pair:
//   normal  NRotShortBondPrms, normalK = kn (not scaled), at rest at d0; it breaks when the
//           stretch exceeds breakDistance x d0, so breakDistance = Rn / (kn d_group): bonds are
//           grouped by d0 (groups at most tension_group_width wide), one tag per group;
//   shear   RotBondPrms with scaling = False, normalK = 0, shearK = kt, torsion and bending 0,
//           shearBrkForce = Rt: at rest at creation, breaks when |Fs| > Rt (its normal term
//           is zero, so ESyS's Mohr-Coulomb criterion reduces to that).
// Contacts made after a bond broke: RotFrictionPrms (kn, kt, mu, scaling = False), excluded
// while either bond of the pair holds.
//
// Not carried over (refused as bad input, naming the field): deformable particles (DDEM),
// bonds with a moment (the combined criterion needs the normal force and the moment in one
// bond), bonds within a range (bond_range > 1), unbreakable bonds. Not reproduced: the two
// halves of a bond break separately; the shear spring acts on (ri + rj) x the rotation of the
// branch, so its stiffness is kt (ri + rj)/d0 (the script's header gives the largest
// deviation); the tension limit is Rn within half a group width.
//
// Masses: ESyS's own. 2D (force2dComputations): discs of unit thickness, m = rho pi r^2 per
// metre, as this toolkit's 2D solver; 3D spheres. KN, KT, RN, RT are per metre in 2D.

#include <array>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "generator/packing.h"
#include "lab/bonded_export.h"
#include "solver/material.h"

namespace specimen {

struct EsysExportOptions {
  // The contact constants (a calibrate-to-material `_parameters.toml`); absent: the script's
  // KN ... DENSITY are None and it stops, naming them, until they are set.
  std::optional<MaterialParameters> material;
  std::string parameters_source;  // named in the script's header
  std::string packing_source;     // likewise
  // The geometry file's name as the script refers to it (relative: to the script's directory).
  std::string geometry_name = "specimen_esys.geo";
  // A listed pair is a bond when |gap| <= this x (ri + rj)/2, in [0, 1] (the solver's rule).
  double bond_gap_tolerance = 0.05;
  // Bonds are grouped by initial length d0, largest / smallest d0 of a group <= 1 + this, in
  // (0, 1]: the tension limit is Rn within this / (2 + this) for every bond.
  double tension_group_width = 0.01;
  // Local damping of the particles' motion and rotation (run-test's default), in [0, 1).
  double local_damping = 0.7;
  // The time step as this fraction of the per-particle bound (Madan (2.16)-(2.18)), in (0, 1].
  double time_step_safety = 0.5;
};

// One group of bonds with the same ESyS tag: its tag, its representative length (the middle
// of its smallest and largest d0) and its bonds (indices into the bond list).
struct EsysBondGroup {
  int tag = 0;
  double length_m = 0.0;
  std::vector<int> bonds;
};

// The groups of `bonds` by initial length: sorted by d0, a group closes before the bond that
// would make largest / smallest exceed 1 + width.
template <int Dim>
std::vector<EsysBondGroup> EsysBondGroups(const Packing<Dim>& packing, const std::vector<std::array<int, 2>>& bonds,
                                          double width);

// The geometry file (LSMGeometry 1.2: particles `x y z r id 0`, connections `i j tag`).
template <int Dim>
void WriteEsysGeometry(const Packing<Dim>& packing, const EsysExportOptions& options, std::ostream& out);

// The script. Both throw InputError for options out of range or a material that cannot be
// carried (above), naming the field.
template <int Dim>
void WriteEsysScript(const Packing<Dim>& packing, const EsysExportOptions& options, std::ostream& out);

// Both files, as one atomic group: an error leaves neither. options.geometry_name is set to
// the geometry file's name.
template <int Dim>
void SaveEsysSpecimen(const Packing<Dim>& packing, EsysExportOptions options, const std::string& script_path,
                      const std::string& geometry_path);

}  // namespace specimen
