#pragma once
// The bonded specimen as a Yade script (docs/exports.md, "Yade: the bonded specimen"): a
// Python file, run with `yade -x <file> --run at-rest|ucs`, that builds the spheres, every
// bond of the packing with this toolkit's constants (kn, kt, Rn, Rt, mu per contact) and its
// initial gap as the zero-force distance, and the two platens of a UCS test.
//
// Yade's law is Law2_ScGeom6D_CohFrictPhys_CohesionMoment on CohFrictPhys interactions made
// by hand (utils.createInteraction) and then set: kn, ks = kt, normalAdhesion = Rn,
// shearAdhesion = Rt (forces, as here), tangensOfFrictionAngle = mu, fragile,
// cohesionDisablesFriction (the shear limit is Rt alone, Labra (2.35)) and
// unp = the initial penetration depth, so that Fn = kn (penetrationDepth - unp) is zero at
// the packing's gap (the stress-free bonds of docs/solver.md, "Bonds and the contact law").
// The bonds are the listed pairs the solver bonds: |gap| <= bond_gap_tolerance (ri + rj)/2.
//
// Not carried over (refused as bad input, the message says why): deformable particles
// (DDEM: Ep, nu_p; Yade's spheres are rigid) and bonds with a moment (bond_radius_ratio > 0:
// CohFrictPhys has bending and twisting stiffnesses, but its moment limits are checked apart
// from the force, not on the combined peripheral stress of Potyondy & Cundall).
//
// 2D: the discs become spheres at z = 0 kept in the plane (blockedDOFs "zXY") with the
// masses and inertia of discs of unit thickness, m = rho pi r^2 x 1 m, J = m r^2 / 2; the
// stiffnesses and strengths are the per-metre values, so the forces are this toolkit's.

#include <iosfwd>
#include <optional>
#include <string>

#include "generator/packing.h"
#include "lab/bonded_export.h"  // ExportedBonds: the bonds the script creates
#include "lab/lab_test.h"
#include "solver/material.h"

namespace specimen {

struct YadeExportOptions {
  // The contact constants (a calibrate-to-material `_parameters.toml`); absent: the script's
  // KN, KT, RN, RT, MU, DENSITY are None and it stops, naming them, until they are set.
  std::optional<MaterialParameters> material;
  std::string parameters_source;  // named in the script's header
  std::string packing_source;     // likewise
  // A listed pair is a bond when |gap| <= this x (ri + rj)/2, in [0, 1]: the solver's rule
  // and default (solver/scene.h ContactDetectionOptions).
  double bond_gap_tolerance = 0.05;
  // The UCS drive and measurement of run-test (lab/lab_test.h): loading_rate_group,
  // velocity_ramp_transits, platen_stiffness_ratio, local_damping, sample_interval_steps,
  // linear_portion_low, post_peak_stress_fraction. The others do not enter the script.
  LabTestOptions ucs;
  // Yade's time step as this fraction of the per-particle bound (Madan (2.16)-(2.18)), in
  // (0, 1]: the bound is not a bound on an irregular packing (docs/solver.md).
  double time_step_safety = 0.5;
};

// Writes the script. Throws InputError for a packing that cannot be exported (indices out
// of range), options out of range, or a material Yade's law cannot carry (DDEM, moments).
template <int Dim>
void WriteYadeScript(const Packing<Dim>& packing, const YadeExportOptions& options, std::ostream& out);

// The same, written to `path` atomically (temporary file + rename): an error leaves no file.
template <int Dim>
void SaveYadeScript(const Packing<Dim>& packing, const YadeExportOptions& options, const std::string& path);

}  // namespace specimen
