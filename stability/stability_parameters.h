#pragma once
// The parameter set of the stability-limit command: a TOML file and/or command-line values
// (the command line wins), turned into the SceneOptions and StabilityOptions of the analysis.
// Every field is optional in the file; kn and the density must come from one of the two.
//
//   [material]
//   normal_stiffness = 7e10          # kn [N/m], > 0
//   tangential_stiffness = 0.0       # kt [N/m], >= 0
//   density = 2000.0                 # particle density [kg/m^3], > 0
//   particle_youngs_modulus = 2e11   # Ep [Pa], > 0; absent: rigid particles (plain DEM)
//   particle_poisson_ratio = 0.35    # nu_p, in (-1, 0.5)
//   plane_model = "strain"           # 2D DDEM particles: "strain" or "stress"
//   translational_damping = 0.0      # local damping alpha_t, in [0, 1)
//   rotational_damping = 0.0         # alpha_r, in [0, 1)
//   normal_dashpot_ratio = 0.0       # xi_n >= 0
//   tangential_dashpot_ratio = 0.0   # xi_t >= 0
//   mass_scaling = 0.01              # inertia scaling budget, in [0, 0.05] (particles.h)
//   bond_radius_ratio = 0.0          # lambda in [0, 1]: bonds with a moment (bond_moment.h)
//   bond_range = 1.0                 # gamma in [1, 1.5]: bonds within gamma (ri + rj) (bond_range.h)
//
//   [time_step]
//   time_step = 2.5e-8               # the proposed step to judge [s], > 0
//   safety_factor = 0.9              # recommended = this x critical, in (0, 1]
//
//   [stability]
//   max_spectral_radius = 0.95       # rho(B) above this is marginal, in (0, 1]
//   time_step_margin = 0.05          # a step within this fraction of dt_cr is marginal
//
//   [walls]                          # fixed rigid planes on the packing's bounding box
//   sides = ["bottom", "top"]        # left, right, bottom, top (2D); back, front (3D, z)
//   normal_stiffness = 7e11          # k_wall [N/m], > 0; default kn
//   tangential_stiffness = 0.0       # kt_wall [N/m], >= 0
//   friction = 0.0                   # mu_wall >= 0 (with kt_wall > 0)
//
// Unknown tables or keys are errors naming the file and the key.

#include <optional>
#include <string>
#include <vector>

#include "generator/packing.h"
#include "solver/scene.h"
#include "stability/stability_analysis.h"

namespace specimen {

struct StabilityParameters {
  std::optional<double> normal_stiffness_n_per_m, tangential_stiffness_n_per_m;
  std::optional<double> density_kg_per_m3;
  std::optional<double> particle_youngs_modulus_pa, particle_poisson_ratio;
  std::optional<std::string> plane_model;  // "strain" | "stress"
  std::optional<double> translational_damping, rotational_damping;
  std::optional<double> normal_dashpot_ratio, tangential_dashpot_ratio;
  std::optional<double> mass_scaling_budget;
  std::optional<double> bond_radius_ratio;
  std::optional<double> bond_range;
  std::optional<double> time_step_s, safety_factor;
  std::optional<double> max_spectral_radius, time_step_margin;
  std::optional<std::vector<std::string>> wall_sides;
  std::optional<double> wall_normal_stiffness_n_per_m, wall_tangential_stiffness_n_per_m;
  std::optional<double> wall_friction;
};

// Parses the TOML text; `source` names it in messages. Throws InputError for TOML syntax
// (line and column), unknown keys and values of the wrong type.
StabilityParameters ParseStabilityParameters(const std::string& toml_text,
                                             const std::string& source);
StabilityParameters LoadStabilityParameters(const std::string& path);

// `preferred` where set, else `fallback` (command line over file).
StabilityParameters MergeStabilityParameters(const StabilityParameters& preferred,
                                             const StabilityParameters& fallback);

// The scene (material, walls on the packing's bounding box: the extent of the particles)
// and the analysis options of a parameter set. Throws InputError naming the field, its value
// and the allowed range, before any work.
template <int Dim>
SceneOptions<Dim> StabilitySceneOf(const StabilityParameters& parameters,
                                   const Packing<Dim>& packing);
StabilityOptions StabilityOptionsOf(const StabilityParameters& parameters);

}  // namespace specimen
