#include "calibrate/target_material.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include "common/error.h"
#include "common/field_names.h"
#include "common/format.h"
#include "lab/lab_measurement.h"

namespace specimen {
namespace {

// A required or optional number under `table`, with the key named in every message.
std::optional<double> ReadNumber(const toml::table& table, const std::string& key,
                                 const std::string& where, bool required) {
  const toml::node* node = table.get(key);
  if (node == nullptr) {
    if (required) {
      std::vector<std::string> present;
      for (const auto& [k, v] : table) (void)v, present.emplace_back(k.str());
      throw InputError(where + ": '" + key + "' is missing" + MisspeltKeys(key, present));
    }
    return std::nullopt;
  }
  if (const auto value = node->value<double>()) return *value;
  throw InputError(where + ": '" + key + "' must be a number");
}

void RejectUnknownKeys(const toml::table& table, const std::set<std::string>& known,
                       const std::string& where) {
  for (const auto& [key, value] : table) {
    (void)value;
    if (!known.count(std::string(key.str())))
      throw InputError(where + ": unknown key '" + std::string(key.str()) + "'");
  }
}

}  // namespace

bool TargetMaterial::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  auto finite = [](double v) { return std::isfinite(v); };
  if (!finite(youngs_modulus_pa) || youngs_modulus_pa <= 0.0)
    return fail("youngs_modulus = " + Number(youngs_modulus_pa) + " Pa is not allowed: it must be > 0");
  if (!finite(poisson_ratio) || poisson_ratio <= -1.0 || poisson_ratio >= 0.5)
    return fail("poisson_ratio = " + Number(poisson_ratio) + " is not allowed: it must be in (-1, 0.5)");
  if (!finite(tensile_strength_pa) || tensile_strength_pa <= 0.0)
    return fail("tensile_strength = " + Number(tensile_strength_pa) + " Pa is not allowed: it must be > 0");
  if (!finite(ucs_pa) || ucs_pa <= tensile_strength_pa)
    return fail("ucs = " + Number(ucs_pa) + " Pa is not allowed: it must be larger than the tensile strength (" +
                Number(tensile_strength_pa) + " Pa)");
  if (!finite(density_kg_per_m3) || density_kg_per_m3 <= 0.0)
    return fail("density = " + Number(density_kg_per_m3) + " kg/m^3 is not allowed: it must be > 0");
  if (friction_angle_deg && (!finite(*friction_angle_deg) || *friction_angle_deg <= 0.0 ||
                             *friction_angle_deg >= 90.0))
    return fail("friction_angle = " + Number(*friction_angle_deg) +
                " degrees is not allowed: it must be in (0, 90)");
  for (size_t i = 0; i < confined.size(); ++i) {
    const auto& c = confined[i];
    const std::string where = "confined[" + std::to_string(i) + "]";
    if (!finite(c.confinement_pa) || c.confinement_pa < 0.0)
      return fail(where + ".confinement = " + Number(c.confinement_pa) + " Pa is not allowed: it must be >= 0");
    if (!finite(c.peak_stress_pa) || c.peak_stress_pa <= c.confinement_pa)
      return fail(where + ".peak_stress = " + Number(c.peak_stress_pa) +
                  " Pa is not allowed: it must be larger than the confinement");
  }
  return true;
}

TargetMaterial ParseTargetMaterial(const std::string& toml_text, const std::string& source) {
  toml::table root;
  try {
    root = toml::parse(toml_text, source);
  } catch (const toml::parse_error& e) {
    std::ostringstream message;
    message << source << ", line " << e.source().begin.line << ", column " << e.source().begin.column
            << ": " << e.description();
    throw InputError(message.str());  // malformed content, as a bad value on the command line
  }
  RejectUnknownKeys(root, {"material", "confined"}, source);
  const toml::table* table = root["material"].as_table();
  if (table == nullptr) throw InputError(source + ": the [material] table is missing");
  const std::string where = source + " [material]";
  RejectUnknownKeys(*table,
                    {"name", "youngs_modulus", "poisson_ratio", "ucs", "tensile_strength", "density",
                     "friction_angle", "youngs_modulus_1", "youngs_modulus_2", "poisson_ratio_12",
                     "shear_modulus_12", "axis_angle", "youngs_modulus_3", "poisson_ratio_13", "poisson_ratio_23"},
                    where);
  TargetMaterial material;
  if (const toml::node* name = table->get("name"); name != nullptr && !name->is_string())
    throw InputError(where + ": 'name' must be a string");
  material.name = (*table)["name"].value_or(std::string("unnamed material"));
  if (table->contains("youngs_modulus_1")) {
    if (table->contains("youngs_modulus") || table->contains("poisson_ratio"))
      throw InputError(where + ": give either youngs_modulus and poisson_ratio (isotropic) or youngs_modulus_1, "
                       "youngs_modulus_2, poisson_ratio_12, shear_modulus_12 (orthotropic), not both");
    OrthotropicConstants o;
    o.youngs_modulus_1_pa = *ReadNumber(*table, "youngs_modulus_1", where, true);
    o.youngs_modulus_2_pa = *ReadNumber(*table, "youngs_modulus_2", where, true);
    o.poisson_ratio_12 = *ReadNumber(*table, "poisson_ratio_12", where, true);
    o.shear_modulus_12_pa = *ReadNumber(*table, "shear_modulus_12", where, true);
    const double angle_deg = ReadNumber(*table, "axis_angle", where, false).value_or(0.0);
    if (!(std::abs(angle_deg) <= 360.0))
      throw InputError(where + ": axis_angle = " + Number(angle_deg) + " is not allowed: it must be in [-360, 360] degrees");
    o.axis_angle_rad = angle_deg * 3.14159265358979323846 / 180.0;
    // The calibration is plane strain: the out-of-plane constants enter D (no silent default).
    o.youngs_modulus_3_pa = *ReadNumber(*table, "youngs_modulus_3", where, true);
    o.poisson_ratio_13 = *ReadNumber(*table, "poisson_ratio_13", where, true);
    o.poisson_ratio_23 = *ReadNumber(*table, "poisson_ratio_23", where, true);
    std::string invalid;
    if (!o.IsValid(PlaneModel::kPlaneStrain, &invalid)) throw InputError(where + ": " + invalid);
    // The apparent constants along y (header comment).
    const Eigen::Matrix3d compliance = OrthotropicPlaneElasticity(o, PlaneModel::kPlaneStrain).Matrix().inverse();
    PlaneStrainFromInPlane(1.0 / compliance(1, 1), -compliance(0, 1) / compliance(1, 1), &material.youngs_modulus_pa,
                           &material.poisson_ratio);
    material.orthotropic = o;
  } else {
    material.youngs_modulus_pa = *ReadNumber(*table, "youngs_modulus", where, true);
    material.poisson_ratio = *ReadNumber(*table, "poisson_ratio", where, true);
  }
  material.ucs_pa = *ReadNumber(*table, "ucs", where, true);
  material.tensile_strength_pa = *ReadNumber(*table, "tensile_strength", where, true);
  material.density_kg_per_m3 = *ReadNumber(*table, "density", where, true);
  material.friction_angle_deg = ReadNumber(*table, "friction_angle", where, false);
  if (root.contains("confined") && !root["confined"].is_array())
    throw InputError(source + ": 'confined' must be an array of tables [[confined]] with "
                     "confinement and peak_stress");
  if (const toml::array* confined = root["confined"].as_array()) {
    for (size_t i = 0; i < confined->size(); ++i) {
      const toml::table* entry = (*confined)[i].as_table();
      const std::string entry_where = source + " [[confined]] #" + std::to_string(i + 1);
      if (entry == nullptr) throw InputError(entry_where + ": must be a table");
      RejectUnknownKeys(*entry, {"confinement", "peak_stress"}, entry_where);
      material.confined.push_back({*ReadNumber(*entry, "confinement", entry_where, true),
                                   *ReadNumber(*entry, "peak_stress", entry_where, true)});
    }
  }
  std::string error;
  if (!material.IsValid(&error)) throw InputError(source + ": " + error);
  return material;
}

TargetMaterial LoadTargetMaterial(const std::string& path) {
  if (std::filesystem::is_directory(path))
    throw FileError("the material file '" + path + "' is a directory, not a file");
  std::ifstream in(path);
  if (!in) throw FileError("cannot read the material file '" + path + "'");
  std::stringstream text;
  text << in.rdbuf();
  return ParseTargetMaterial(text.str(), path);
}

nlohmann::json TargetMaterialToJson(const TargetMaterial& m) {
  nlohmann::json j;
  j["name"] = m.name;
  j["youngs_modulus_pa"] = m.youngs_modulus_pa;
  j["poisson_ratio"] = m.poisson_ratio;
  j["ucs_pa"] = m.ucs_pa;
  j["tensile_strength_pa"] = m.tensile_strength_pa;
  j["density_kg_per_m3"] = m.density_kg_per_m3;
  if (m.friction_angle_deg) j["friction_angle_deg"] = *m.friction_angle_deg;
  if (m.orthotropic) {
    const OrthotropicConstants& o = *m.orthotropic;
    j["orthotropic"] = {{"youngs_modulus_1_pa", o.youngs_modulus_1_pa}, {"youngs_modulus_2_pa", o.youngs_modulus_2_pa},
                        {"poisson_ratio_12", o.poisson_ratio_12}, {"shear_modulus_12_pa", o.shear_modulus_12_pa},
                        {"axis_angle_deg", o.axis_angle_rad * 180.0 / 3.14159265358979323846},
                        {"youngs_modulus_3_pa", o.youngs_modulus_3_pa}, {"poisson_ratio_13", o.poisson_ratio_13},
                        {"poisson_ratio_23", o.poisson_ratio_23}};
  }
  for (const auto& c : m.confined)
    j["confined"].push_back({{"confinement_pa", c.confinement_pa}, {"peak_stress_pa", c.peak_stress_pa}});
  return j;
}

}  // namespace specimen
