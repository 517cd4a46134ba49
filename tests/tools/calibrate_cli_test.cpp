// The calibrate-to-material command on bad input: exit status, the message names the
// field, and nothing is written.
#include <gtest/gtest.h>

#include "tests/tools/command_runner.h"
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;

using Result = specimen::testing::CommandResult;

Result RunCalibrate(const std::string& arguments) {
  return specimen::testing::RunProgram("calibrate-to-material", arguments);
}

fs::path Material(const std::string& name, const std::string& body) {
  const fs::path path = fs::temp_directory_path() / ("specimen_cal_cli_" + name + ".toml");
  std::ofstream(path) << "[material]\nname = \"" << name << "\"\n" << body;
  return path;
}

const char* kGood = "youngs_modulus = 18.7e9\npoisson_ratio = 0.2\nucs = 127.8e6\ntensile_strength = 12.3e6\n"
                    "density = 2580\n";

TEST(CalibrateToMaterialCommand, BadInputExitsWithTwoAndWritesNothing) {
  const fs::path out = fs::temp_directory_path() / "specimen_cal_cli_out";
  fs::remove_all(out);
  const std::string o = " --output " + out.string() + " --maps-dir " + (out / "maps").string();
  Result r = RunCalibrate(Material("negative_e", "youngs_modulus = -1\npoisson_ratio = 0.2\nucs = 1e8\n"
                                        "tensile_strength = 1e7\ndensity = 2580\n").string() + o);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("youngs_modulus"), std::string::npos) << r.output;
  r = RunCalibrate(Material("nu", "youngs_modulus = 1e10\npoisson_ratio = 0.5\nucs = 1e8\n"
                         "tensile_strength = 1e7\ndensity = 2580\n").string() + o);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("poisson_ratio"), std::string::npos) << r.output;
  r = RunCalibrate(Material("ucs", "youngs_modulus = 1e10\npoisson_ratio = 0.2\nucs = 1e6\n"
                          "tensile_strength = 1e7\ndensity = 2580\n").string() + o);
  EXPECT_EQ(r.status, 2) << r.output;
  r = RunCalibrate(Material("density", "youngs_modulus = 1e10\npoisson_ratio = 0.2\nucs = 1e8\n"
                              "tensile_strength = 1e7\ndensity = -5\n").string() + o);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("density"), std::string::npos) << r.output;
  const std::string good = Material("good", kGood).string();
  r = RunCalibrate(good + o + " --model magic");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--model"), std::string::npos) << r.output;
  r = RunCalibrate(good + o + " --dimension 4");
  EXPECT_EQ(r.status, 2) << r.output;
  r = RunCalibrate(good + o + " --max-spectral-radius 1.2");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("max_spectral_radius"), std::string::npos) << r.output;
  r = RunCalibrate(good + o + " --sweep-fraction 0");
  EXPECT_EQ(r.status, 2) << r.output;
  // Unreadable maps: a garbage file (after the specimens are generated; small ones).
  fs::create_directories(fs::temp_directory_path() / "specimen_cal_cli_maps");
  const fs::path garbage = fs::temp_directory_path() / "specimen_cal_cli_maps" / "garbage.json";
  std::ofstream(garbage) << "{ not json";
  r = RunCalibrate(good + o + " --ucs-domain 'rectangle 0 0 0.01 0.01' --count 200 --maps " + garbage.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("not valid JSON"), std::string::npos) << r.output;
  EXPECT_TRUE(!fs::exists(out) || fs::is_empty(out) ||
              (fs::directory_iterator(out) == fs::directory_iterator()))
      << "partial output written";
  // Files that do not exist.
  r = RunCalibrate("/nonexistent/material.toml" + o);
  EXPECT_EQ(r.status, 3) << r.output;
  fs::remove_all(out);
}

}  // namespace
