#pragma once
// The scene file of `run-test`: one lab test as TOML (toml++) - the specimen (a packing file,
// or a domain the generator fills), the material parameters, the test and its options, and
// the outputs. Every key is checked (unknown keys, types, ranges, the test's shape against
// the domain) before any work; messages name the file, the table and the key.
//
//   [specimen]
//   packing = "ucs_2d.packing"        # a generate-packing file, relative to this file; or
//   domain = "rectangle 0 0 0.05 0.05"  # generate the specimen: domain, and count or
//   count = 5000                        #   mean_radius [m], seed (generator defaults otherwise)
//   seed = 1
//   scale_density = true              # rho' = rho / (1 - e) (Labra Tables 4.8, 4.11)
//
//   [material]                        # SI units; 2D per unit thickness (docs/solver.md)
//   normal_stiffness = 14.392e9       # kn [N/m]
//   tangential_stiffness = 2.868e9    # kt [N/m]
//   bond_tensile_strength = 4962.3    # Rn [N]; inf (or omitted) = unbreakable
//   bond_shear_strength = 49623       # Rt [N]; inf (or omitted) = unbreakable
//   friction_coefficient = 0.8        # mu
//   density = 2580                    # rho [kg/m^3], before the scaling
//   particle_youngs_modulus = 2e11    # Ep [Pa]: deformable particles (DDEM); omitted = rigid
//   particle_poisson_ratio = 0.25     # nu_p
//   plane_model = "plane_strain"      # 2D DDEM: plane_strain | plane_stress
//
//   # or the six-spring lattice (2D; ucs and brazilian):
//   # model = "lattice"
//   # youngs_modulus = 30e9, poisson_ratio = 0.25  (or youngs_modulus_1, youngs_modulus_2,
//   #   poisson_ratio_12, shear_modulus_12, axis_angle [deg]; plane strain also
//   #   youngs_modulus_3, poisson_ratio_13, poisson_ratio_23)
//   # tensile_strength = 8e6, cohesion = 25e6, friction_angle = 30 [deg], density = 2650
//   # plane_model = "plane_strain"
//
//   [test]
//   kind = "ucs"                      # ucs | brazilian | biaxial | isotropic | shear
//   loading_rate_group = 5e-5         # V / sqrt(kn/rho) (3D: V / sqrt(kn/(rho r_mean)))
//   platen_speed = 0                  # V [m/s], > 0 overrides the group
//   post_peak_fraction = 0.5          # stop when the stress falls to this fraction of the peak
//   strain_limit = 0                  # 0 = automatic (0.02 strength tests, 0.001 others)
//   modulus_window = [0.01, 0.5]      # secant window, fractions of the peak
//   confining_stress = 5e6            # biaxial: one test at sigma_3 [Pa]; or
//   confining_stresses = [1e6, 5e6, 10e6]  # biaxial: the envelope and Mohr-Coulomb fit
//   quasi_static_check = true         # repeat at half the rate, flag > 1 % changes
//   ... and every other LabTestOptions field under its name without the unit suffix:
//   velocity_ramp_transits, pause_kinetic_energy_ratio, max_pause_transits, sample_interval,
//   strain_boundary_margin, linear_portion_low, servo_gain_fraction, servo_integral_transits,
//   consolidation_tolerance, platen_stiffness_ratio, platen_friction, local_damping,
//   dashpot_ratio, mass_scaling (mass_scaling_budget), quasi_static_tolerance, threads;
//   Brazilian: loading_arc (the jaws' arc 2 alpha in degrees; bonded particles:
//   LabTestOptions::loading_arc_deg, default 0 = flat platens; lattice:
//   LatticeProtocol::loading_arc_deg, default 30); lattice Brazilian: platen_zone
//   (LatticeProtocol::platen_zone_share)
//   lattice: wave_share (the cap on the rate, LatticeProtocol::compression_wave_share or
//   brazilian_wave_share by the kind; 0 = the loading-rate group as given)
//
//   [output]
//   name = "ucs_2d"                   # file name prefix (default: the scene file's name)
//   pictures = true
//   snapshots = true                  # VTU at the peak and at the end

#include <cstdint>
#include <string>
#include <vector>

#include "common/field_names.h"
#include "lab/lab_outputs.h"
#include "lab/lab_test.h"
#include "lab/lattice_lab_test.h"
#include "solver/material.h"

namespace specimen {

struct LabScene {
  std::string source;  // the scene file (for messages)
  // [specimen]: exactly one of packing_path and domain.
  std::string packing_path;  // resolved against the scene file's directory
  std::string domain;        // Domain text, generated with count or mean_radius
  int particle_count = 0;
  double mean_radius_m = 0.0;
  std::uint64_t seed = 1;
  int dimension = 0;  // from the domain, or 0 until the packing's header is read
  MaterialParameters material;  // model = "bonded" (the default)
  // model = "lattice": the six-spring lattice of the packing (lab/lattice_lab_test.h).
  bool lattice = false;
  LatticeMaterial lattice_material;
  LatticeProtocol lattice_protocol;
  bool platen_zone_given = false;
  bool wave_share_given = false;
  bool loading_arc_given = false;
  bool plane_model_given = false;  // a 2D setting: refused with a 3D specimen
  LabTestOptions test;
  std::vector<double> confining_stresses_pa;  // biaxial envelope when not empty
  LabOutputOptions output;
};

// Parses and checks a scene. `source` is the file path: relative packing paths are resolved
// against its directory, and it names the scene in messages. Throws InputError for TOML syntax
// errors (with line and column, status 2 as a bad option value) and anything out of range or
// unknown.
LabScene ParseLabScene(const std::string& toml_text, const std::string& source);

// Reads and parses `path`; FileError if it cannot be read.
LabScene LoadLabScene(const std::string& path);

// A parameter file: a TOML file whose only table is a bonded [material] table, checked as a
// scene's (calibrate-to-material's `_parameters.toml`). Throws InputError naming the file,
// the key and its range; FileError if it cannot be read.
MaterialParameters ParseMaterialFile(const std::string& toml_text, const std::string& source);
MaterialParameters LoadMaterialFile(const std::string& path);

// The library's field names of MaterialParameters and LabTestOptions as the scene keys that
// set them, for InUserTerms (common/field_names.h): the messages of a run name the keys.
FieldNames SceneKeyNames();

}  // namespace specimen
