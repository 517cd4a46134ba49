#pragma once
// What the bonded export tests share: one parameter set and small generated specimens.

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <limits>
#include <string>

#include "common/error.h"
#include "generator/generate.h"
#include "lab/bonded_export.h"
#include "solver/material.h"

namespace specimen {

// kn 2e6 N/m, kt 5e5 N/m, Rn 5 N, Rt 50 N, mu 0.5, 2650 kg/m^3: bonds that hold at rest.
inline MaterialParameters ExportTestMaterial() {
  MaterialParameters m;
  m.normal_stiffness_n_per_m = 2e6;
  m.tangential_stiffness_n_per_m = 5e5;
  m.bond_tensile_strength_n = 5.0;
  m.bond_shear_strength_n = 50.0;
  m.friction_coefficient = 0.5;
  m.density_kg_per_m3 = 2650.0;
  return m;
}

// A packing of `count` particles in `domain`, seed 3, one thread.
template <int Dim>
Packing<Dim> ExportTestPacking(const Domain<Dim>& domain, int count) {
  GeneratorOptions options = DefaultGeneratorOptions<Dim>();
  options.particle_count = count;
  options.seed = 3;
  options.num_threads = 1;
  return GeneratePacking<Dim>(domain, options, nullptr);
}

// Checks that `save` (an export that writes its file(s) from a set named "p.toml") refuses,
// naming the field, what a rigid pair bond cannot carry: DDEM, moments, a bond range, an
// unbreakable bond, and an invalid set (naming the file).
inline void ExpectRigidPairRefusals(const std::function<void(const MaterialParameters&)>& save) {
  auto refusal = [&](const MaterialParameters& material) {
    try {
      save(material);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  MaterialParameters ddem = ExportTestMaterial();
  ddem.particle_youngs_modulus_pa = 2e11;
  ddem.particle_poisson_ratio = 0.2;
  EXPECT_NE(refusal(ddem).find("particle_youngs_modulus"), std::string::npos);
  MaterialParameters moments = ExportTestMaterial();
  moments.bond_radius_ratio = 0.5;
  EXPECT_NE(refusal(moments).find("bond_radius_ratio = 0.5"), std::string::npos);
  MaterialParameters ranged = ExportTestMaterial();
  ranged.bond_range = 1.2;
  EXPECT_NE(refusal(ranged).find("bond_range = 1.2"), std::string::npos);
  MaterialParameters unbreakable = ExportTestMaterial();
  unbreakable.bond_tensile_strength_n = std::numeric_limits<double>::infinity();
  EXPECT_NE(refusal(unbreakable).find("unbreakable"), std::string::npos);
  MaterialParameters bad = ExportTestMaterial();
  bad.normal_stiffness_n_per_m = -1.0;
  EXPECT_NE(refusal(bad).find("p.toml"), std::string::npos);
}

// Runs `command` (a script's at-rest check in the target code) with `--steps N --json
// json_path` appended, its output going to json_path + ".log", and returns the JSON it wrote
// (null, with a failure naming the command and its log, when it did not).
inline nlohmann::json RunAtRestCheck(const std::string& command, int steps, const std::string& json_path) {
  const std::string full = command + " --steps " + std::to_string(steps) + " --json '" + json_path + "' > '" +
                           json_path + ".log' 2>&1";
  const int status = std::system(full.c_str());
  std::ifstream log(json_path + ".log");
  std::stringstream text;
  text << log.rdbuf();
  EXPECT_EQ(status, 0) << full << "\n" << text.str();
  std::ifstream in(json_path);
  if (!in) return nlohmann::json();
  return nlohmann::json::parse(in);
}

// The at-rest criterion of every bonded export: all the solver's bonds made, the largest bond
// force at step 1 and after `steps` below 1e-9 kn r_mean, and none broken.
template <int Dim>
void ExpectBondsAtRest(const nlohmann::json& result, const Packing<Dim>& packing, int steps) {
  ASSERT_TRUE(result.is_object());
  const double scale = ExportTestMaterial().normal_stiffness_n_per_m * VolumeMeanRadius<Dim>(packing.radii);
  EXPECT_EQ(result["bonds"].get<int>(), static_cast<int>(ExportedBonds(packing, 0.05).size()));
  EXPECT_GT(result["bonds"].get<int>(), packing.size());
  EXPECT_LT(result["largest_bond_force_step_1_n"].get<double>(), 1e-9 * scale);
  EXPECT_LT(result["largest_bond_force_end_n"].get<double>(), 1e-9 * scale);
  EXPECT_EQ(result["broken_bonds"].get<int>(), 0);
  EXPECT_EQ(result["steps"].get<int>(), steps);
}

}  // namespace specimen
