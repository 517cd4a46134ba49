#pragma once
// The material a calibration aims at, read from a TOML file (SI units):
//
//   [material]
//   name = "Labra 2012, Table 4.7"
//   youngs_modulus = 18.691e9     # E [Pa], > 0
//   poisson_ratio = 0.20          # nu, in (-1, 0.5)
//   ucs = 127.83e6                # uniaxial compressive strength [Pa], > tensile strength
//   tensile_strength = 12.30e6    # Brazilian (BTS) tensile strength [Pa], > 0
//   density = 2580.0              # [kg/m^3], > 0
//   friction_angle = 35.0         # optional, internal friction angle [degrees], in (0, 90)
//
//   [[confined]]                  # optional, any number: peak stress at a confinement
//   confinement = 5.0e6           # lateral stress [Pa], >= 0
//   peak_stress = 160.0e6         # axial peak stress [Pa], > confinement
//
// Every error names the file, the key and the allowed range.

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "solver/six_spring_lattice.h"

namespace specimen {

struct ConfinedStrength {
  double confinement_pa = 0.0;
  double peak_stress_pa = 0.0;
};

struct TargetMaterial {
  std::string name;
  double youngs_modulus_pa = 0.0;
  double poisson_ratio = 0.0;
  double ucs_pa = 0.0;
  double tensile_strength_pa = 0.0;
  double density_kg_per_m3 = 0.0;
  std::optional<double> friction_angle_deg;
  std::vector<ConfinedStrength> confined;
  // An orthotropic rock (keys youngs_modulus_1, youngs_modulus_2, poisson_ratio_12,
  // shear_modulus_12, youngs_modulus_3, poisson_ratio_13, poisson_ratio_23 and the optional
  // axis_angle [deg] of axis 1 from x), for the lattice model only. youngs_modulus_pa and
  // poisson_ratio are then the isotropic pair with its in-plane response along the loading
  // axis y of the UCS: E' = 1 / S_22 and nu' = -S_12 / S_22 (S = D^-1, plane strain) are
  // E / (1 - nu^2) and nu / (1 - nu), the same reduction the UCS's linear portion is read with.
  std::optional<OrthotropicConstants> orthotropic;

  // UCS over tensile strength: the contact law of this toolkit reaches at most about 10
  // (Labra sections 4.3.3-4.3.4); a larger ratio is reported, not silently ignored.
  double StrengthRatio() const { return ucs_pa / tensile_strength_pa; }
  // Names the first invalid field, its value and the allowed range.
  bool IsValid(std::string* error) const;
};

// Parses TOML text; `source` names it in messages. Throws InputError (bad values, missing
// keys, unknown keys, TOML syntax with line and column) or FileError (unreadable file).
TargetMaterial ParseTargetMaterial(const std::string& toml_text, const std::string& source);
TargetMaterial LoadTargetMaterial(const std::string& path);

nlohmann::json TargetMaterialToJson(const TargetMaterial& material);

}  // namespace specimen
