#include "stability/stability_parameters.h"

#include <toml++/toml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "common/error.h"
#include "common/format.h"

namespace specimen {

namespace {

void RejectUnknownKeys(const toml::table& table, const std::set<std::string>& known,
                       const std::string& where) {
  for (const auto& [key, value] : table) {
    (void)value;
    if (!known.count(std::string(key.str())))
      throw InputError(where + ": unknown key '" + std::string(key.str()) + "'");
  }
}

std::optional<double> ReadNumber(const toml::table& table, const std::string& key,
                                 const std::string& where) {
  const toml::node* node = table.get(key);
  if (node == nullptr) return std::nullopt;
  if (const auto value = node->value<double>()) return *value;
  throw InputError(where + ": '" + key + "' must be a number");
}

std::optional<std::string> ReadString(const toml::table& table, const std::string& key,
                                      const std::string& where) {
  const toml::node* node = table.get(key);
  if (node == nullptr) return std::nullopt;
  if (const auto value = node->value<std::string>()) return *value;
  throw InputError(where + ": '" + key + "' must be a string");
}

template <typename T>
void Prefer(std::optional<T>& out, const std::optional<T>& preferred,
            const std::optional<T>& fallback) {
  out = preferred ? preferred : fallback;
}

// A value in a range, or an InputError naming it.
void Require(bool ok, const std::string& field, double value, const std::string& range) {
  if (!ok) throw InputError(field + " = " + Number(value) + " is not allowed: it must be " + range);
}

}  // namespace

StabilityParameters ParseStabilityParameters(const std::string& text, const std::string& source) {
  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    std::ostringstream message;
    message << source << ", line " << e.source().begin.line << ", column "
            << e.source().begin.column << ": " << e.description();
    throw InputError(message.str());  // malformed content, as a bad value on the command line
  }
  RejectUnknownKeys(root, {"material", "time_step", "stability", "walls"}, source);
  StabilityParameters p;
  auto table = [&](const char* name) -> const toml::table* {
    const toml::node* node = root.get(name);
    if (node == nullptr) return nullptr;
    if (const toml::table* t = node->as_table()) return t;
    throw InputError(source + ": '" + name + "' must be a table");
  };
  if (const toml::table* m = table("material")) {
    const std::string where = source + " [material]";
    RejectUnknownKeys(
        *m,
        {"normal_stiffness", "tangential_stiffness", "density", "particle_youngs_modulus",
         "particle_poisson_ratio", "plane_model", "translational_damping", "rotational_damping",
         "normal_dashpot_ratio", "tangential_dashpot_ratio", "mass_scaling",
         "bond_radius_ratio", "bond_range",
         // A run-test [material] table (calibrate-to-material's _parameters.toml) may be given
         // as it is: the strengths and friction do not enter the linear stability limit, and
         // are checked as numbers only.
         "bond_tensile_strength", "bond_shear_strength", "friction_coefficient"},
        where);
    for (const char* ignored : {"bond_tensile_strength", "bond_shear_strength", "friction_coefficient"})
      ReadNumber(*m, ignored, where);
    p.normal_stiffness_n_per_m = ReadNumber(*m, "normal_stiffness", where);
    p.tangential_stiffness_n_per_m = ReadNumber(*m, "tangential_stiffness", where);
    p.density_kg_per_m3 = ReadNumber(*m, "density", where);
    p.particle_youngs_modulus_pa = ReadNumber(*m, "particle_youngs_modulus", where);
    p.particle_poisson_ratio = ReadNumber(*m, "particle_poisson_ratio", where);
    p.plane_model = ReadString(*m, "plane_model", where);
    p.translational_damping = ReadNumber(*m, "translational_damping", where);
    p.rotational_damping = ReadNumber(*m, "rotational_damping", where);
    p.normal_dashpot_ratio = ReadNumber(*m, "normal_dashpot_ratio", where);
    p.tangential_dashpot_ratio = ReadNumber(*m, "tangential_dashpot_ratio", where);
    p.mass_scaling_budget = ReadNumber(*m, "mass_scaling", where);
    p.bond_radius_ratio = ReadNumber(*m, "bond_radius_ratio", where);
    p.bond_range = ReadNumber(*m, "bond_range", where);
  }
  if (const toml::table* t = table("time_step")) {
    const std::string where = source + " [time_step]";
    RejectUnknownKeys(*t, {"time_step", "safety_factor"}, where);
    p.time_step_s = ReadNumber(*t, "time_step", where);
    p.safety_factor = ReadNumber(*t, "safety_factor", where);
  }
  if (const toml::table* t = table("stability")) {
    const std::string where = source + " [stability]";
    RejectUnknownKeys(*t, {"max_spectral_radius", "time_step_margin"}, where);
    p.max_spectral_radius = ReadNumber(*t, "max_spectral_radius", where);
    p.time_step_margin = ReadNumber(*t, "time_step_margin", where);
  }
  if (const toml::table* w = table("walls")) {
    const std::string where = source + " [walls]";
    RejectUnknownKeys(*w, {"sides", "normal_stiffness", "tangential_stiffness", "friction"}, where);
    if (const toml::node* node = w->get("sides")) {
      const toml::array* sides = node->as_array();
      if (sides == nullptr) throw InputError(where + ": 'sides' must be an array of strings");
      std::vector<std::string> list;
      for (const toml::node& side : *sides) {
        const auto name = side.value<std::string>();
        if (!name) throw InputError(where + ": 'sides' must be an array of strings");
        list.push_back(*name);
      }
      p.wall_sides = list;
    }
    p.wall_normal_stiffness_n_per_m = ReadNumber(*w, "normal_stiffness", where);
    p.wall_tangential_stiffness_n_per_m = ReadNumber(*w, "tangential_stiffness", where);
    p.wall_friction = ReadNumber(*w, "friction", where);
  }
  return p;
}

StabilityParameters LoadStabilityParameters(const std::string& path) {
  if (std::filesystem::is_directory(path))
    throw FileError("the parameter file '" + path + "' is a directory, not a file");
  std::ifstream in(path);
  if (!in) throw FileError("cannot read the parameter file '" + path + "'");
  std::stringstream text;
  text << in.rdbuf();
  return ParseStabilityParameters(text.str(), path);
}

StabilityParameters MergeStabilityParameters(const StabilityParameters& a,
                                             const StabilityParameters& b) {
  StabilityParameters p;
  Prefer(p.normal_stiffness_n_per_m, a.normal_stiffness_n_per_m, b.normal_stiffness_n_per_m);
  Prefer(p.tangential_stiffness_n_per_m, a.tangential_stiffness_n_per_m,
         b.tangential_stiffness_n_per_m);
  Prefer(p.density_kg_per_m3, a.density_kg_per_m3, b.density_kg_per_m3);
  Prefer(p.particle_youngs_modulus_pa, a.particle_youngs_modulus_pa, b.particle_youngs_modulus_pa);
  Prefer(p.particle_poisson_ratio, a.particle_poisson_ratio, b.particle_poisson_ratio);
  Prefer(p.plane_model, a.plane_model, b.plane_model);
  Prefer(p.translational_damping, a.translational_damping, b.translational_damping);
  Prefer(p.rotational_damping, a.rotational_damping, b.rotational_damping);
  Prefer(p.normal_dashpot_ratio, a.normal_dashpot_ratio, b.normal_dashpot_ratio);
  Prefer(p.tangential_dashpot_ratio, a.tangential_dashpot_ratio, b.tangential_dashpot_ratio);
  Prefer(p.mass_scaling_budget, a.mass_scaling_budget, b.mass_scaling_budget);
  Prefer(p.bond_radius_ratio, a.bond_radius_ratio, b.bond_radius_ratio);
  Prefer(p.bond_range, a.bond_range, b.bond_range);
  Prefer(p.time_step_s, a.time_step_s, b.time_step_s);
  Prefer(p.safety_factor, a.safety_factor, b.safety_factor);
  Prefer(p.max_spectral_radius, a.max_spectral_radius, b.max_spectral_radius);
  Prefer(p.time_step_margin, a.time_step_margin, b.time_step_margin);
  Prefer(p.wall_sides, a.wall_sides, b.wall_sides);
  Prefer(p.wall_normal_stiffness_n_per_m, a.wall_normal_stiffness_n_per_m,
         b.wall_normal_stiffness_n_per_m);
  Prefer(p.wall_tangential_stiffness_n_per_m, a.wall_tangential_stiffness_n_per_m,
         b.wall_tangential_stiffness_n_per_m);
  Prefer(p.wall_friction, a.wall_friction, b.wall_friction);
  return p;
}

template <int Dim>
SceneOptions<Dim> StabilitySceneOf(const StabilityParameters& p, const Packing<Dim>& packing) {
  if (!p.normal_stiffness_n_per_m)
    throw InputError("kn is missing: give --kn or [material] normal_stiffness (N/m, > 0)");
  if (!p.density_kg_per_m3)
    throw InputError("the density is missing: give --density or [material] density (kg/m^3, > 0)");
  SceneOptions<Dim> scene;
  MaterialParameters& m = scene.material;
  m.normal_stiffness_n_per_m = *p.normal_stiffness_n_per_m;
  m.tangential_stiffness_n_per_m = p.tangential_stiffness_n_per_m.value_or(0.0);
  m.density_kg_per_m3 = *p.density_kg_per_m3;
  m.particle_youngs_modulus_pa = p.particle_youngs_modulus_pa;
  m.particle_poisson_ratio = p.particle_poisson_ratio.value_or(0.0);
  const std::string plane = p.plane_model.value_or("strain");
  if (plane == "strain" || plane == "plane strain" || plane == "plane_strain") {
    m.plane_model = PlaneModel::kPlaneStrain;
  } else if (plane == "stress" || plane == "plane stress" || plane == "plane_stress") {
    m.plane_model = PlaneModel::kPlaneStress;
  } else {
    throw InputError("plane_model = '" + plane +
                     "' is not allowed: it must be plane_strain or plane_stress (or strain, stress)");
  }
  m.translational_damping = p.translational_damping.value_or(0.0);
  m.rotational_damping = p.rotational_damping.value_or(m.translational_damping);
  m.normal_dashpot_ratio = p.normal_dashpot_ratio.value_or(0.0);
  m.tangential_dashpot_ratio = p.tangential_dashpot_ratio.value_or(m.normal_dashpot_ratio);
  m.mass_scaling_budget = p.mass_scaling_budget.value_or(0.0);
  m.bond_radius_ratio = p.bond_radius_ratio.value_or(0.0);
  m.bond_range = p.bond_range.value_or(1.0);
  std::string error;
  if (!m.IsValid(&error)) throw InputError(error);
  if (p.time_step_s)
    Require(*p.time_step_s > 0.0 && std::isfinite(*p.time_step_s), "proposed_time_step_s", *p.time_step_s,
            "finite and > 0 [s]");
  scene.time_step.time_step_s = p.time_step_s.value_or(0.0);

  // Walls on the particles' bounding box; their values named as given, before the walls'
  // own check (whose messages name a wall's fields).
  if (p.wall_normal_stiffness_n_per_m)
    Require(*p.wall_normal_stiffness_n_per_m > 0.0 && std::isfinite(*p.wall_normal_stiffness_n_per_m),
            "wall_normal_stiffness", *p.wall_normal_stiffness_n_per_m, "finite and > 0 [N/m]");
  if (p.wall_tangential_stiffness_n_per_m)
    Require(*p.wall_tangential_stiffness_n_per_m >= 0.0 && std::isfinite(*p.wall_tangential_stiffness_n_per_m),
            "wall_tangential_stiffness", *p.wall_tangential_stiffness_n_per_m, "finite and >= 0 [N/m]");
  if (p.wall_friction)
    Require(*p.wall_friction >= 0.0 && std::isfinite(*p.wall_friction), "wall_friction", *p.wall_friction,
            "finite and >= 0");
  if (p.wall_sides && !p.wall_sides->empty()) {
    Vector<Dim> lower = packing.centres.front(), upper = lower;
    for (int q = 0; q < packing.size(); ++q)
      for (int a = 0; a < Dim; ++a) {
        lower[a] = std::min(lower[a], packing.centres[q][a] - packing.radii[q]);
        upper[a] = std::max(upper[a], packing.centres[q][a] + packing.radii[q]);
      }
    const std::vector<std::string> names =
        Dim == 2 ? std::vector<std::string>{"left", "right", "bottom", "top"}
                 : std::vector<std::string>{"left", "right", "bottom", "top", "back", "front"};
    std::set<std::string> seen;
    for (const std::string& side : *p.wall_sides) {
      int index = -1;
      for (size_t k = 0; k < names.size(); ++k)
        if (side == names[k]) index = static_cast<int>(k);
      if (index < 0) {
        std::string list;
        for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
        throw InputError("walls: side '" + side + "' is not allowed: use " + list);
      }
      if (!seen.insert(side).second) throw InputError("walls: side '" + side + "' given twice");
      const int axis = index / 2;
      const bool high = index % 2 == 1;
      WallOptions<Dim> w;
      w.name = side;
      w.normal[axis] = high ? -1.0 : 1.0;
      w.point[axis] = high ? upper[axis] : lower[axis];
      w.normal_stiffness_n_per_m =
          p.wall_normal_stiffness_n_per_m.value_or(m.normal_stiffness_n_per_m);
      w.tangential_stiffness_n_per_m = p.wall_tangential_stiffness_n_per_m.value_or(0.0);
      w.friction_coefficient = p.wall_friction.value_or(0.0);
      if (!w.IsValid(&error)) throw InputError(error);
      scene.walls.push_back(w);
    }
  }
  if (!scene.IsValid(&error)) throw InputError(error);
  return scene;
}

StabilityOptions StabilityOptionsOf(const StabilityParameters& p) {
  StabilityOptions options;
  if (p.safety_factor) options.safety_factor = *p.safety_factor;
  if (p.max_spectral_radius) options.max_spectral_radius = *p.max_spectral_radius;
  if (p.time_step_margin) options.time_step_margin = *p.time_step_margin;
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  return options;
}

template SceneOptions<2> StabilitySceneOf<2>(const StabilityParameters&, const Packing<2>&);
template SceneOptions<3> StabilitySceneOf<3>(const StabilityParameters&, const Packing<3>&);

}  // namespace specimen
