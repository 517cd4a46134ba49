#include "lab/lab_scene_file.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <toml++/toml.h>

#include "common/error.h"
#include "common/field_names.h"
#include "generator/domain.h"
#include "lab/lab_envelope.h"
#include "lab/lab_specimen.h"
#include "common/format.h"
#include "common/atomic_file.h"

namespace specimen {
namespace {

// Reads the keys of one table, each at most once and with its type checked; Finish()
// rejects the keys nobody asked for.
class TableReader {
 public:
  TableReader(const toml::table* table, std::string where) : table_(table), where_(std::move(where)) {}

  bool Has(const std::string& key) const { return table_ && table_->get(key) != nullptr; }
  // "'key' is missing", naming a present key that looks like a typo of it.
  std::string Missing(const std::string& key) const {
    std::vector<std::string> present;
    if (table_)
      for (const auto& [k, v] : *table_) (void)v, present.emplace_back(k.str());
    return where_ + ": '" + key + "' is missing" + MisspeltKeys(key, present);
  }

  // A number (integers accepted; inf and nan are TOML numbers too: ranges reject nan).
  bool Number(const std::string& key, double* value) {
    const toml::node* node = Get(key);
    if (!node) return false;
    if (const auto v = node->value<double>()) {
      *value = *v;
      return true;
    }
    throw InputError(where_ + ": '" + key + "' must be a number");
  }
  bool Integer(const std::string& key, std::int64_t* value) {
    const toml::node* node = Get(key);
    if (!node) return false;
    if (node->is_integer()) {
      *value = *node->value<std::int64_t>();
      return true;
    }
    throw InputError(where_ + ": '" + key + "' must be an integer");
  }
  bool Boolean(const std::string& key, bool* value) {
    const toml::node* node = Get(key);
    if (!node) return false;
    // is_boolean: toml++'s value<bool>() would also take an integer (7 -> true).
    if (node->is_boolean()) {
      *value = *node->value<bool>();
      return true;
    }
    throw InputError(where_ + ": '" + key + "' must be true or false");
  }
  bool String(const std::string& key, std::string* value) {
    const toml::node* node = Get(key);
    if (!node) return false;
    if (const auto v = node->value<std::string>()) {
      *value = *v;
      return true;
    }
    throw InputError(where_ + ": '" + key + "' must be a string");
  }
  bool Numbers(const std::string& key, std::vector<double>* values) {
    const toml::node* node = Get(key);
    if (!node) return false;
    const toml::array* array = node->as_array();
    if (!array) throw InputError(where_ + ": '" + key + "' must be an array of numbers");
    values->clear();
    for (const toml::node& item : *array) {
      const auto v = item.value<double>();
      if (!v) throw InputError(where_ + ": '" + key + "' must be an array of numbers");
      values->push_back(*v);
    }
    return true;
  }
  void Finish() const {
    if (!table_) return;
    for (const auto& [key, value] : *table_) {
      (void)value;
      if (!read_.count(std::string(key.str())))
        throw InputError(where_ + ": unknown key '" + std::string(key.str()) + "'");
    }
  }
  const std::string& where() const { return where_; }

 private:
  const toml::node* Get(const std::string& key) {
    read_.insert(key);
    return table_ ? table_->get(key) : nullptr;
  }
  const toml::table* table_;
  std::string where_;
  std::set<std::string> read_;
};

// The fields of MaterialParameters and LabTestOptions as the scene keys that set them, for
// the messages of their validation.
const FieldNames kMaterialKeys = {
    {"normal_stiffness_n_per_m", "normal_stiffness"},
    {"tangential_stiffness_n_per_m", "tangential_stiffness"},
    {"bond_tensile_strength_n", "bond_tensile_strength"},
    {"bond_shear_strength_n", "bond_shear_strength"},
    {"density_kg_per_m3", "density"},
    {"particle_youngs_modulus_pa", "particle_youngs_modulus"},
};
const FieldNames kTestKeys = {
    {"platen_speed_m_per_s", "platen_speed"},
    {"post_peak_stress_fraction", "post_peak_fraction"},
    {"modulus_window_low", "modulus_window[0]"},
    {"modulus_window_high", "modulus_window[1]"},
    {"sample_interval_steps", "sample_interval"},
    {"num_threads", "threads"},
    {"confining_stress_pa", "confining_stress"},
    {"mass_scaling_budget", "mass_scaling"},
    {"time_step_safety_factor", "safety_factor"},
    {"loading_arc_deg", "loading_arc"},
};

}  // namespace

FieldNames SceneKeyNames() {
  FieldNames names = kMaterialKeys;
  names.insert(names.end(), kTestKeys.begin(), kTestKeys.end());
  return names;
}

namespace {

int DimensionOfDomain(const std::string& text) {
  std::istringstream in(text);
  std::string shape;
  in >> shape;
  if (shape == "rectangle" || shape == "disc" || shape == "polygon") return 2;
  if (shape == "box" || shape == "cylinder") return 3;
  throw InputError("[specimen] domain: unknown domain '" + shape +
                   "'; use rectangle, disc, polygon (2D) or box, cylinder (3D)");
}

void ReadSpecimen(const toml::table* table, const std::string& source, LabScene* scene) {
  TableReader t(table, source + " [specimen]");
  if (!table) throw InputError(source + ": the [specimen] table is missing");
  const bool has_packing = t.String("packing", &scene->packing_path);
  const bool has_domain = t.String("domain", &scene->domain);
  if (has_packing == has_domain)
    throw InputError(t.where() + ": give exactly one of 'packing' (a packing file) and 'domain' "
                                 "(generate the specimen)");
  std::int64_t count = 0, seed = 1;
  const bool has_count = t.Integer("count", &count);
  const bool has_radius = t.Number("mean_radius", &scene->mean_radius_m);
  t.Integer("seed", &seed);
  t.Boolean("scale_density", &scene->test.scale_density);
  t.Finish();
  if (has_packing) {
    if (has_count || has_radius || table->get("seed"))
      throw InputError(t.where() + ": 'count', 'mean_radius' and 'seed' only go with 'domain'");
    std::filesystem::path path(scene->packing_path);
    if (path.is_relative())
      path = std::filesystem::path(source).parent_path() / path;
    scene->packing_path = path.lexically_normal().string();
    return;
  }
  if (has_count == has_radius)
    throw InputError(t.where() + ": with 'domain' give exactly one of 'count' and 'mean_radius'");
  if (has_count && (count < 1 || count > std::numeric_limits<int>::max()))
    throw InputError(t.where() + ": count = " + std::to_string(count) +
                     " is not allowed: it must be >= 1");
  if (has_radius && !(scene->mean_radius_m > 0.0 && std::isfinite(scene->mean_radius_m)))
    throw InputError(t.where() + ": mean_radius must be a finite length > 0 [m]");
  if (seed < 0) throw InputError(t.where() + ": seed must be >= 0");
  scene->particle_count = static_cast<int>(count);
  scene->seed = static_cast<std::uint64_t>(seed);
  scene->dimension = DimensionOfDomain(scene->domain);
  try {
    if (scene->dimension == 2)
      CheckSpecimenShape<2>(Domain<2>::Parse(scene->domain), scene->test.kind);
    else
      CheckSpecimenShape<3>(Domain<3>::Parse(scene->domain), scene->test.kind);
  } catch (const InputError& e) {
    throw InputError(t.where() + ": " + e.what());
  }
}

constexpr double kDegree = 3.14159265358979323846 / 180.0;

// [material] of a lattice scene (model = "lattice"): isotropic E, nu or orthotropic constants,
// the plane model, the fracture strengths and the density.
void ReadLatticeMaterial(TableReader& t, LatticeMaterial* m) {
  auto required = [&](const std::string& key, double* value) {
    if (!t.Number(key, value)) throw InputError(t.Missing(key) + " (model = \"lattice\")");
  };
  PlaneModel plane = PlaneModel::kPlaneStrain;
  std::string plane_name;
  if (t.String("plane_model", &plane_name)) {
    if (plane_name == "plane_strain")
      plane = PlaneModel::kPlaneStrain;
    else if (plane_name == "plane_stress")
      plane = PlaneModel::kPlaneStress;
    else
      throw InputError(t.where() + ": plane_model = '" + plane_name +
                       "' is not allowed: use plane_strain or plane_stress");
  }
  double e = 0.0, nu = 0.0;
  const bool isotropic = t.Number("youngs_modulus", &e);
  const bool has_nu = t.Number("poisson_ratio", &nu);
  OrthotropicConstants o;
  double angle_deg = 0.0;
  const bool orthotropic = t.Number("youngs_modulus_1", &o.youngs_modulus_1_pa);
  if (isotropic == orthotropic)
    throw InputError(t.where() + ": give either youngs_modulus and poisson_ratio (isotropic) or youngs_modulus_1, "
                     "youngs_modulus_2, poisson_ratio_12, shear_modulus_12 (orthotropic)");
  if (isotropic) {
    if (!has_nu) throw InputError(t.where() + ": 'poisson_ratio' is missing (model = \"lattice\")");
    try {
      m->elasticity = IsotropicPlaneElasticity(e, nu, plane);
    } catch (const InputError& error) {
      throw InputError(t.where() + ": " + error.what());
    }
  } else {
    if (has_nu) throw InputError(t.where() + ": 'poisson_ratio' is for an isotropic lattice: use poisson_ratio_12");
    required("youngs_modulus_2", &o.youngs_modulus_2_pa);
    required("poisson_ratio_12", &o.poisson_ratio_12);
    required("shear_modulus_12", &o.shear_modulus_12_pa);
    t.Number("axis_angle", &angle_deg);
    t.Number("youngs_modulus_3", &o.youngs_modulus_3_pa);
    t.Number("poisson_ratio_13", &o.poisson_ratio_13);
    t.Number("poisson_ratio_23", &o.poisson_ratio_23);
    if (!(std::abs(angle_deg) <= 360.0))
      throw InputError(t.where() + ": axis_angle = " + Number(angle_deg) + ": must be in [-360, 360] degrees");
    o.axis_angle_rad = angle_deg * kDegree;
    std::string error;
    if (!o.IsValid(plane, &error)) throw InputError(t.where() + ": " + error);
    m->elasticity = OrthotropicPlaneElasticity(o, plane);
  }
  required("tensile_strength", &m->strength.tensile_strength_pa);
  required("cohesion", &m->strength.cohesion_pa);
  t.Number("friction_angle", &m->strength.friction_angle_deg);
  required("density", &m->density_kg_per_m3);
  t.Finish();
  std::string error;
  if (!m->IsValid(&error)) throw InputError(t.where() + ": " + error);
}

void ReadMaterial(const toml::table* table, const std::string& source, LabScene* scene) {
  if (!table) throw InputError(source + ": the [material] table is missing");
  TableReader t(table, source + " [material]");
  std::string model = "bonded";
  t.String("model", &model);
  if (model == "lattice") {
    scene->lattice = true;
    ReadLatticeMaterial(t, &scene->lattice_material);
    return;
  }
  if (model != "bonded")
    throw InputError(t.where() + ": model = '" + model + "' is not allowed: use bonded (the default) or lattice");
  MaterialParameters* m = &scene->material;
  auto required = [&](const std::string& key, double* value) {
    if (!t.Number(key, value)) throw InputError(t.Missing(key));
  };
  required("normal_stiffness", &m->normal_stiffness_n_per_m);
  t.Number("tangential_stiffness", &m->tangential_stiffness_n_per_m);
  t.Number("bond_tensile_strength", &m->bond_tensile_strength_n);
  t.Number("bond_shear_strength", &m->bond_shear_strength_n);
  t.Number("friction_coefficient", &m->friction_coefficient);
  t.Number("bond_radius_ratio", &m->bond_radius_ratio);
  t.Number("bond_range", &m->bond_range);
  required("density", &m->density_kg_per_m3);
  double modulus = 0.0;
  if (t.Number("particle_youngs_modulus", &modulus)) m->particle_youngs_modulus_pa = modulus;
  // nu_p alone would silently run rigid particles: the user meant DDEM and forgot Ep.
  if (t.Number("particle_poisson_ratio", &m->particle_poisson_ratio) &&
      !m->particle_youngs_modulus_pa)
    throw InputError(t.where() + ": 'particle_poisson_ratio' is given without "
                     "'particle_youngs_modulus': give both for deformable particles (DDEM), "
                     "neither for rigid ones");
  std::string plane;
  if (t.String("plane_model", &plane)) {
    scene->plane_model_given = true;
    if (plane == "plane_strain")
      m->plane_model = PlaneModel::kPlaneStrain;
    else if (plane == "plane_stress")
      m->plane_model = PlaneModel::kPlaneStress;
    else
      throw InputError(t.where() + ": plane_model = '" + plane +
                       "' is not allowed: use plane_strain or plane_stress");
  }
  t.Finish();
  std::string error;
  if (!m->IsValid(&error)) throw InputError(t.where() + ": " + InUserTerms(error, kMaterialKeys));
}

void ReadTest(const toml::table* table, const std::string& source, LabScene* scene) {
  if (!table) throw InputError(source + ": the [test] table is missing");
  TableReader t(table, source + " [test]");
  LabTestOptions& o = scene->test;
  std::string kind;
  if (!t.String("kind", &kind)) throw InputError(t.Missing("kind"));
  if (!ParseLabTestKind(kind, &o.kind))
    throw InputError(t.where() + ": kind = '" + kind +
                     "' is not allowed: use ucs, brazilian, biaxial, isotropic or shear");
  t.Number("loading_rate_group", &o.loading_rate_group);
  t.Number("platen_speed", &o.platen_speed_m_per_s);
  t.Number("velocity_ramp_transits", &o.velocity_ramp_transits);
  t.Number("pause_kinetic_energy_ratio", &o.pause_kinetic_energy_ratio);
  t.Number("max_pause_transits", &o.max_pause_transits);
  t.Boolean("pause_on_breakage", &o.pause_on_breakage);
  t.Number("pause_ramp_transits", &o.pause_ramp_transits);
  t.Number("post_peak_fraction", &o.post_peak_stress_fraction);
  t.Number("strain_limit", &o.strain_limit);
  std::vector<double> window;
  if (t.Numbers("modulus_window", &window)) {
    if (window.size() != 2)
      throw InputError(t.where() + ": modulus_window must hold two numbers [low, high]");
    o.modulus_window_low = window[0];
    o.modulus_window_high = window[1];
  }
  std::int64_t interval = o.sample_interval_steps, threads = o.num_threads;
  t.Integer("sample_interval", &interval);
  t.Integer("threads", &threads);
  if (interval < 1 || interval > 1000000)
    throw InputError(t.where() + ": sample_interval = " + std::to_string(interval) +
                     " is not allowed: it must be in [1, 1000000]");
  if (threads < 1 || threads > 1024)
    throw InputError(t.where() + ": threads = " + std::to_string(threads) +
                     " is not allowed: it must be in [1, 1024]");
  std::int64_t max_steps = o.max_steps;
  t.Integer("max_steps", &max_steps);
  if (max_steps < 1 || max_steps > 1000000000000)
    throw InputError(t.where() + ": max_steps = " + std::to_string(max_steps) +
                     " is not allowed: it must be in [1, 1e12]");
  o.max_steps = static_cast<long>(max_steps);
  o.sample_interval_steps = static_cast<int>(interval);
  o.num_threads = static_cast<int>(threads);
  t.Number("strain_boundary_margin", &o.strain_boundary_margin);
  t.Number("linear_portion_low", &o.linear_portion_low);
  const bool one = t.Number("confining_stress", &o.confining_stress_pa);
  const bool many = t.Numbers("confining_stresses", &scene->confining_stresses_pa);
  t.Number("servo_gain_fraction", &o.servo_gain_fraction);
  t.Number("servo_integral_transits", &o.servo_integral_transits);
  t.Number("consolidation_tolerance", &o.consolidation_tolerance);
  t.Number("platen_stiffness_ratio", &o.platen_stiffness_ratio);
  t.Number("platen_friction", &o.platen_friction);
  scene->platen_zone_given = t.Number("platen_zone", &scene->lattice_protocol.platen_zone_share);
  scene->loading_arc_given = t.Number("loading_arc", &scene->lattice_protocol.loading_arc_deg);
  // The lattice's cap on the rate (LatticeProtocol), for the scene's one test.
  double wave_share = 0.0;
  scene->wave_share_given = t.Number("wave_share", &wave_share);
  if (scene->wave_share_given) {
    if (!(wave_share >= 0.0 && wave_share <= 1.0))
      throw InputError(t.where() + ": wave_share = " + Number(wave_share) +
                       " is not allowed: it must be in [0, 1] (0: the loading-rate group as given)");
    scene->lattice_protocol.compression_wave_share = scene->lattice_protocol.brazilian_wave_share = wave_share;
  }
  // A lattice scene keeps LatticeProtocol's own default unless the key is given.
  if (t.Number("local_damping", &o.local_damping)) scene->lattice_protocol.local_damping = o.local_damping;
  t.Number("dashpot_ratio", &o.dashpot_ratio);
  t.Number("mass_scaling", &o.mass_scaling_budget);
  t.Number("safety_factor", &o.time_step_safety_factor);
  t.Boolean("quasi_static_check", &o.check_quasi_static);
  t.Number("quasi_static_tolerance", &o.quasi_static_tolerance);
  t.Finish();
  if ((one || many) && o.kind != LabTestKind::kConfinedCompression)
    throw InputError(t.where() + ": 'confining_stress(es)' only go with kind = 'biaxial'");
  if (one && many)
    throw InputError(t.where() + ": give 'confining_stress' (one test) or 'confining_stresses' "
                                 "(an envelope), not both");
  if (many) {
    try {
      CheckConfinements(scene->confining_stresses_pa);
    } catch (const InputError& e) {
      throw InputError(t.where() + ": " + e.what());
    }
  }
  std::string error;
  if (!o.IsValid(&error)) throw InputError(t.where() + ": " + InUserTerms(error, kTestKeys));
}

void ReadOutput(const toml::table* table, const std::string& source, LabOutputOptions* output) {
  TableReader t(table, source + " [output]");
  t.String("name", &output->name);
  t.Boolean("pictures", &output->pictures);
  t.Boolean("snapshots", &output->snapshots);
  t.Finish();
  if (std::string rule; !IsValidOutputName(output->name, &rule))
    throw InputError(t.where() + ": name = '" + output->name + "' is not allowed: " + rule);
}

// The text of a TOML input, or a FileError naming what it is (`kind`).
std::string ReadTomlFile(const std::string& path, const std::string& kind) {
  if (std::filesystem::is_directory(path))
    throw FileError("the " + kind + " '" + path + "' is a directory, not a file");
  std::ifstream in(path);
  if (!in) throw FileError("cannot read the " + kind + " '" + path + "'");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

toml::table ParseToml(const std::string& toml_text, const std::string& source) {
  try {
    return toml::parse(toml_text, source);
  } catch (const toml::parse_error& e) {
    std::ostringstream message;
    message << source << ", line " << e.source().begin.line << ", column "
            << e.source().begin.column << ": " << e.description();
    throw InputError(message.str());  // malformed content, as a bad value on the command line
  }
}

}  // namespace

LabScene ParseLabScene(const std::string& toml_text, const std::string& source) {
  toml::table root = ParseToml(toml_text, source);
  for (const auto& [key, value] : root) {
    (void)value;
    const std::string name(key.str());
    if (name != "specimen" && name != "material" && name != "test" && name != "output")
      throw InputError(source + ": unknown table or key '" + name +
                       "' (the scene has [specimen], [material], [test], [output])");
  }
  LabScene scene;
  scene.source = source;
  scene.output.name = std::filesystem::path(source).stem().string();
  ReadTest(root["test"].as_table(), source, &scene);  // first: the shape check needs the kind
  ReadSpecimen(root["specimen"].as_table(), source, &scene);
  ReadMaterial(root["material"].as_table(), source, &scene);
  ReadOutput(root["output"].as_table(), source, &scene.output);
  if (scene.plane_model_given && scene.dimension == 3)
    throw InputError(source + " [material]: plane_model is a 2D setting; the specimen is 3D");
  if (scene.lattice) {
    if (scene.test.kind != LabTestKind::kUniaxialCompression && scene.test.kind != LabTestKind::kBrazilian &&
        scene.test.kind != LabTestKind::kConfinedCompression)
      throw InputError(source + " [test]: kind = '" + LabTestKindName(scene.test.kind) +
                       "': the lattice model runs the ucs, biaxial and brazilian tests");
    if (scene.dimension == 3) throw InputError(source + ": the lattice model is 2D; the specimen is 3D");
    if (scene.test.scale_density)
      throw InputError(source + " [specimen]: scale_density is for bonded particles; a lattice fills the specimen "
                       "and takes the solid's density as it is");
    // Settings of the bonded tests that the lattice tests do not use: refused, not ignored.
    static const std::set<std::string> bonded_only = {
        "pause_kinetic_energy_ratio", "max_pause_transits", "pause_on_breakage", "pause_ramp_transits",
        "strain_boundary_margin", "confining_stresses", "servo_gain_fraction",
        "servo_integral_transits", "consolidation_tolerance", "platen_stiffness_ratio", "platen_friction",
        "dashpot_ratio", "mass_scaling"};
    if (const toml::table* test = root["test"].as_table())
      for (const auto& [key, value] : *test) {
        (void)value;
        if (bonded_only.count(std::string(key.str())))
          throw InputError(source + " [test]: '" + std::string(key.str()) +
                           "' is a setting of the bonded tests; the lattice model does not use it");
      }
    if (scene.test.kind != LabTestKind::kBrazilian && (scene.platen_zone_given || scene.loading_arc_given))
      throw InputError(source + " [test]: '" + (scene.platen_zone_given ? "platen_zone" : "loading_arc") +
                       "' is a setting of the Brazilian test; kind = '" + LabTestKindName(scene.test.kind) + "'");
    // The lattice's keys, checked here so that a bad one is named before the specimen is made.
    std::string error;
    if (!scene.lattice_protocol.IsValid(&error)) throw InputError(source + " [test]: " + error);
  } else if (scene.platen_zone_given || scene.wave_share_given) {
    throw InputError(source + " [test]: '" + (scene.platen_zone_given ? "platen_zone" : "wave_share") +
                     "' is for model = \"lattice\" ([material])");
  } else if (scene.loading_arc_given) {
    // Bonded particles: the jaws of the Brazilian test (LabTestOptions::loading_arc_deg).
    if (scene.test.kind != LabTestKind::kBrazilian)
      throw InputError(source + " [test]: 'loading_arc' is a setting of the Brazilian test; kind = '" +
                       LabTestKindName(scene.test.kind) + "'");
    scene.test.loading_arc_deg = scene.lattice_protocol.loading_arc_deg;
    std::string error;
    if (!scene.test.IsValid(&error)) throw InputError(source + " [test]: " + InUserTerms(error, kTestKeys));
  }
  return scene;
}

LabScene LoadLabScene(const std::string& path) {
  return ParseLabScene(ReadTomlFile(path, "scene file"), path);
}

MaterialParameters ParseMaterialFile(const std::string& toml_text, const std::string& source) {
  const toml::table root = ParseToml(toml_text, source);
  for (const auto& [key, value] : root) {
    (void)value;
    if (key.str() != "material")
      throw InputError(source + ": unknown table or key '" + std::string(key.str()) +
                       "' (a parameter file has the [material] table only)");
  }
  LabScene scene;
  ReadMaterial(root["material"].as_table(), source, &scene);
  if (scene.lattice)
    throw InputError(source + " [material]: model = \"lattice\" is not allowed here: the parameters of bonded "
                     "particles are needed");
  return scene.material;
}

MaterialParameters LoadMaterialFile(const std::string& path) {
  return ParseMaterialFile(ReadTomlFile(path, "parameter file"), path);
}

}  // namespace specimen
