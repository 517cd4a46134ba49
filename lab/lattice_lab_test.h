#pragma once
// The UCS, biaxial and Brazilian tests on a six-spring lattice specimen (Kacianauskas & Vadluga 2009):
// the lattice of a generated 2D packing (solver/lattice_packing.h: Delaunay triangles of the
// centres plus surface nodes on the domain's sides), central differences with row-sum lumped
// masses at a fraction of the certified critical step (solver/lattice_stability.h), local
// non-viscous damping (LatticeProtocol), and triangle fracture by a tension cut-off and a Mohr-Coulomb limit
// (solver/lattice_fracture.h). The result is a LabTestResult like the bonded tests', so the
// reports, curves and pictures of run-test and the calibrator's measurements apply as they are.
//
//   LatticeMaterial m;
//   m.elasticity = IsotropicPlaneElasticity(30e9, 0.25, PlaneModel::kPlaneStrain);
//   m.density_kg_per_m3 = 2650;
//   m.strength = {8e6, 30e6, 30.0};
//   LabTestResult r = RunLatticeLabTest(packing, m, options);  // options.kind: UCS, biaxial or BTS
//
// The tests (docs/sources.md, "The lattice in the laboratory"):
//  - UCS: a rectangle between two rigid frictionless platens. The surface nodes on the top
//    and bottom sides move with their platen (each at V towards the other; free along x, the
//    bottom node nearest the middle held in x), so the platens are glued in the loading
//    direction only.
//  - Biaxial (kConfinedCompression): the same, with sigma_3 on the side surface nodes (each
//    node's share of its side), raised over one velocity ramp before the platens move. The
//    control is the deviator; peak_stress_pa is sigma_1.
//    Control: the mean platen force over the width. Stress and strain: the area averages of
//    the triangles' (exact for a lattice, which fills the rectangle).
//  - Brazilian: a disc between two rigid jaws with a loading arc 2 alpha (LatticeProtocol,
//    default 30 degrees): each presses the surface nodes within alpha of its pole with a
//    uniform radial pressure (Hondros 1959), and sigma_t is the tensile stress at the disc's
//    centre at the peak, k 2 F / (pi D s), k = (sin 2 alpha - alpha) / sin alpha, F the peak
//    jaw force. With a loading arc 0, flat frictionless platens normal to y touch the surface
//    nodes by a penalty of stiffness E' s per node (compression only), and k = 1. The nodes at
//    the two poles are held in x, and the triangles near the poles stay elastic.
// V = g x sqrt(d22 / rho) (half the axial strain added per wave transit H / c), g the
// loading_rate_group capped for the lattice (LatticeProtocol: the platens' wave stress d22 g a
// small share of the triangles' weaker strength), ramped over velocity_ramp_transits; no
// quasi-static holds (constant speed); check_quasi_static repeats the test at half the rate. The test
// stops once the control has fallen to post_peak_stress_fraction of its peak, or at the
// strain limit (0: 0.02). The isotropic and shear tests are refused (InputError).

#include <string>

#include "generator/packing.h"
#include "lab/lab_test.h"
#include "solver/lattice_fracture.h"

namespace specimen {

struct LatticeMaterial {
  PlaneElasticity elasticity;     // D, per unit thickness (s = 1 m)
  double density_kg_per_m3 = 0.0;  // of the solid: the lattice fills the specimen
  LatticeStrength strength;

  // Names the first invalid field and its range.
  bool IsValid(std::string* error) const;
};

// What the lattice tests add to LabTestOptions.
struct LatticeProtocol {
  // Brazilian: the triangles within this share of the diameter D of either contact point stay
  // elastic, in [0, 0.3]. A platen loads the lattice at a few nodes, where the discrete
  // stress of the triangles around them exceeds any strength long before the centre of the
  // disc splits; the rock under a real platen or ISRM jaw is confined and does not fail
  // there (the test's strength against the zone: docs/sources.md, "The lattice in the
  // laboratory").
  double platen_zone_share = 0.1;
  // Brazilian: the loading arc 2 alpha of each jaw, in degrees, [0, 60]; 0 = flat platens on
  // the nodes they touch. A point load shears the disc next to its contacts at a lower force
  // than it splits the centre unless the shear strength is several times the tensile (Tresca:
  // the largest shear along the loaded diameter is 1 / (4 sin alpha (1 - sin alpha)) times the
  // centre's under Hondros's pressure), which puts a floor under UCS / sigma_t; a wider arc
  // brings the first failure to the centre, as a valid test requires (docs/sources.md, "The
  // loading arc"). At 30 degrees a lattice that fails in tension gives its triangles' sigma_t
  // within 1.5 % (800 to 3,943 discs measured).
  double loading_arc_deg = 30.0;
  // Local damping alpha of the nodes, in [0, 1) (replaces LabTestOptions::local_damping, the
  // bonded tests' 0.7). Damping that holds back every node also holds back the free sides'
  // lateral expansion, and none lets waves break the specimen early (docs/sources.md).
  double local_damping = 0.4;
  // Quasi-static rate. A platen moving at V sends a stress wave of rho c V = d22 g (g the
  // loading-rate group). Where that is not small against the triangles' strength, the wave
  // breaks triangles by itself and the strengths depend on the rate (docs/sources.md, "The
  // lattice in the laboratory": at the bonded tests' group 5e-5 a UCS of a brittle rock came
  // out at 29 % of its quasi-static value). The group used is therefore at most this share
  // of min(sigma_t, c) / d22, in [0, 1]; 0 leaves the group as given (a platen_speed given is
  // never capped). The Brazilian strength
  // follows the rate more closely (it peaks a few wave transits after the first failure) and
  // gets the smaller share; both keep the strength within about 1 % of its half-rate value.
  double compression_wave_share = 0.25;  // UCS and biaxial
  double brazilian_wave_share = 0.03;

  // Names the first invalid field and its range.
  bool IsValid(std::string* error) const;
};

LabTestResult RunLatticeLabTest(const Packing<2>& packing, const LatticeMaterial& material,
                                const LabTestOptions& options, const LatticeProtocol& protocol = {});

}  // namespace specimen
