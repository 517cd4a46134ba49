// The calibrate-to-material command on bad input: exit status, the message names the
// field, and nothing is written.
#include <gtest/gtest.h>

#include "tests/tools/command_runner.h"
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

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

// A bonded calibration on a 300-disc square with maps on itself (seconds): a target of E 15 GPa,
// UCS 40 MPa, sigma_t 3 MPa at this nu, one round, into out (maps in out/maps) plus `extra`.
Result RunSmallCalibration(const std::string& name, double poisson_ratio, const fs::path& out,
                           const std::string& extra) {
  const std::string material =
      Material(name, "youngs_modulus = 15e9\npoisson_ratio = " + std::to_string(poisson_ratio) +
                         "\nucs = 40e6\ntensile_strength = 3e6\ndensity = 2600\n")
          .string();
  return RunCalibrate(material + " --ucs-domain 'rectangle 0 0 0.01 0.01' --count 300 --sweep-fraction 1 "
                                 "--sweep-levels 3 --rounds 1 --quiet --no-pictures --output " +
                      out.string() + " --maps-dir " + (out.parent_path() / "maps").string() + extra);
}

TEST(CalibrateToMaterialCommand, BadInputExitsWithTwoAndWritesNothing) {
  const fs::path out = fs::temp_directory_path() / "specimen_cal_cli_out";
  fs::remove_all(out);
  const std::string o = " --output " + out.string() + " --maps-dir " + (out / "maps").string();
  const std::string good = Material("good", kGood).string();
  const fs::path typed = fs::temp_directory_path() / "specimen_cal_cli_typed.toml";
  std::ofstream(typed) << "[material]\nname = 42\n" << kGood;
  const fs::path not_array = fs::temp_directory_path() / "specimen_cal_cli_confined.toml";
  std::ofstream(not_array) << "confined = 5\n[material]\n" << kGood;
  fs::create_directories(fs::temp_directory_path() / "specimen_cal_cli_maps");
  const fs::path garbage = fs::temp_directory_path() / "specimen_cal_cli_maps" / "garbage.json";
  std::ofstream(garbage) << "{ not json";
  struct Case {
    std::string arguments;
    int status;
    std::string must_mention;  // empty: the status alone
  };
  const Case cases[] = {
      // Non-physical properties.
      {Material("negative_e", "youngs_modulus = -1\npoisson_ratio = 0.2\nucs = 1e8\n"
                              "tensile_strength = 1e7\ndensity = 2580\n").string() + o,
       2, "youngs_modulus"},
      {Material("nu", "youngs_modulus = 1e10\npoisson_ratio = 0.5\nucs = 1e8\n"
                      "tensile_strength = 1e7\ndensity = 2580\n").string() + o,
       2, "poisson_ratio"},
      {Material("ucs", "youngs_modulus = 1e10\npoisson_ratio = 0.2\nucs = 1e6\n"
                       "tensile_strength = 1e7\ndensity = 2580\n").string() + o,
       2, ""},
      {Material("density", "youngs_modulus = 1e10\npoisson_ratio = 0.2\nucs = 1e8\n"
                           "tensile_strength = 1e7\ndensity = -5\n").string() + o,
       2, "density"},
      // Wrong types in the material file are reported, not replaced.
      {typed.string() + o, 2, "'name' must be a string"},
      {not_array.string() + o, 2, "'confined' must be an array"},
      // Options, named as typed. A value given is applied as given: 0 is rejected, not taken
      // for the default (which would start a real calibration).
      {good + o + " --model magic", 2, "--model"},
      {good + o + " --dimension 4", 2, "--dimension"},
      {good + o + " --max-spectral-radius 1.2", 2, "--max-spectral-radius"},
      {good + o + " --sweep-fraction 0", 2, "--sweep-fraction"},
      {good + o + " --sweep-stiffness-ratio 0.5 0.2", 2, "--sweep-stiffness-ratio = 0.5 0.2: the kt/kn box, allowed"},
      {good + o + " --sweep-stiffness-ratio 0 0.9", 2, "allowed 0 < LO < HI <= 1"},
      {good + o + " --sweep-stiffness-ratio 0.1 1.5", 2, "allowed 0 < LO < HI <= 1"},
      {good + o + " --sweep-stiffness-ratio 0.1", 2, "--sweep-stiffness-ratio"},
      {good + o + " --sweep-stiffness-ratio 0.1 0.9 --model lattice", 2,
       "--sweep-stiffness-ratio is a setting of the bonded calibration"},
      {good + o + " --count 0", 2, "--count"},
      {good + o + " --rate-group 0", 2, "--rate-group"},
      {good + o + " --rounds 0", 2, "--rounds"},
      {good + o + " --bond-range 1.6", 2, "--bond-range"},
      {good + o + " --loading-arc 70", 2, "--loading-arc"},
      {good + o + " --loading-arc -1 --model lattice", 2, "--loading-arc"},
      {good + o + " --loading-arc 10 --bond-range 1.6", 2, "--bond-range"},
      {good + o + " --seed -1", 2, "--seed"},
      {good + o + " --bogus", 2, "--bogus"},
      // Map locations and contents are checked before any specimen is generated.
      {good + o + " --maps /nonexistent/maps.json", 3, "does not exist"},
      {good + o + " --maps " + fs::temp_directory_path().string(), 3, "not a regular file"},
      {good + " --output " + out.string() + " --maps-dir " + good, 3, "not a directory"},
      {good + o + " --maps " + garbage.string(), 2, "not valid JSON"},
      {good + o + " --maps " + garbage.string() + " --sweep-stiffness-ratio 0.05 0.9", 2,
       "--sweep-stiffness-ratio sets the design of maps to build"},
      {good + o + " --maps " + garbage.string() + " --sweep-levels 5", 2, "--sweep-levels sets the design"},
      // Files that do not exist.
      {"/nonexistent/material.toml" + o, 3, ""},
      // An orthotropic target: only the lattice takes it.
      {Material("orthotropic", "youngs_modulus_1 = 5e10\nyoungs_modulus_2 = 2.5e10\npoisson_ratio_12 = 0.25\n"
                               "shear_modulus_12 = 1.2e10\nyoungs_modulus_3 = 5e10\npoisson_ratio_13 = 0.2\n"
                               "poisson_ratio_23 = 0.15\nucs = 1e8\ntensile_strength = 1e7\ndensity = 2600\n")
               .string() + o + " --model rigid",
       2, "needs --model lattice"},
      // TOML syntax is bad input, as on the command line; a name that is no file name too.
      {Material("syntax", "youngs_modulus = 1e10\npoisson_ratio = 0.2 0.3\n").string() + o, 2, "column"},
      {good + o + " --name .hidden", 2, "--name"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.arguments);
    const Result r = RunCalibrate(c.arguments);
    EXPECT_EQ(r.status, c.status) << r.output;
    if (!c.must_mention.empty()) {
      EXPECT_NE(r.output.find(c.must_mention), std::string::npos) << r.output;
    }
    EXPECT_TRUE(!fs::exists(out) || fs::is_empty(out)) << "partial output written";
  }
  fs::remove_all(out);
}

// A target out of reach is not an error: the command calibrates what is reachable, the
// report names what was given up and the intervals, and the exit status is 4. A small
// specimen with maps on itself (a few seconds); nu 0.45 is beyond any rigid-particle packing.
TEST(CalibrateToMaterialCommand, UnreachableTargetExitsWithFourAndSaysWhatWasGivenUp) {
  const fs::path dir = fs::temp_directory_path() / "specimen_cal_cli_unreachable", out = dir / "out";
  fs::remove_all(dir);
  const Result r = RunSmallCalibration("high_nu", 0.45, out, " --model rigid");
  EXPECT_EQ(r.status, 4) << r.output;
  EXPECT_NE(r.output.find("given up: nu"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("nu reach on this specimen (measured)"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(out / "calibration_report.json"));
  EXPECT_TRUE(fs::exists(out / "calibration_reach.csv"));
  fs::remove_all(dir);
}

// --model auto obtains both models' maps when the rigid reach does not hold the target; the
// calibration's runs go into the chosen model's file only, and the other file keeps its own
// model (written over with the chosen maps, its sweep would be lost). A target of nu 0.01,
// below any packing's, is nearer the rigid reach: rigid particles are chosen.
TEST(CalibrateToMaterialCommand, AutomaticChoiceWritesOnlyTheChosenModelsMapFile) {
  const fs::path dir = fs::temp_directory_path() / ("specimen_cal_cli_auto_" + std::to_string(getpid()));
  const fs::path out = dir / "out";
  fs::remove_all(dir);
  // (with a box of kt/kn of its own, which both models' designs take)
  const Result r = RunSmallCalibration("low_nu", 0.01, out, " --threads 2 --sweep-stiffness-ratio 0.2 0.95");
  ASSERT_EQ(r.status, 4) << r.output;
  std::ifstream report_file(out / "calibration_report.json");
  const nlohmann::json report = nlohmann::json::parse(report_file);
  EXPECT_EQ(report.at("model").at("used").get<std::string>(), "rigid") << r.output;
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir / "maps")) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() != ".json") continue;
    ++files;
    std::ifstream in(e.path());
    const nlohmann::json maps = nlohmann::json::parse(in);
    const bool ddem_file = name.rfind("maps_2d_ddem_", 0) == 0;
    EXPECT_EQ(maps.at("model").get<std::string>(), ddem_file ? "deformable" : "rigid") << name;
    const nlohmann::json& stiffness_axis = maps.at("design").at("axes").at(0);
    EXPECT_EQ(stiffness_axis.at("ratio").get<std::string>(), "kt/kn") << name;
    EXPECT_DOUBLE_EQ(stiffness_axis.at("lower").get<double>(), 0.2) << name;
    EXPECT_DOUBLE_EQ(stiffness_axis.at("upper").get<double>(), 0.95) << name;
  }
  EXPECT_EQ(files, 2) << "both models' maps stored";
  fs::remove_all(dir);
}

// --sweep-stiffness-ratio sets the maps' box of kt/kn, and so the nu the reach measures at its
// ends: below the default box's 0.15 rigid discs reach a higher nu (nu falls with kt/kn).
TEST(CalibrateToMaterialCommand, AWiderStiffnessBoxWidensTheReachOfNu) {
  const fs::path dir = fs::temp_directory_path() / ("specimen_cal_cli_box_" + std::to_string(getpid()));
  fs::remove_all(dir);
  auto top_of_nu_reach = [&](const std::string& box, const std::string& name) {
    const Result r = RunSmallCalibration("box", 0.45, dir / name, " --model rigid" + box);
    EXPECT_EQ(r.status, 4) << r.output;
    const std::string tag = "nu reach on this specimen (measured): ";
    const size_t at = r.output.find(tag);
    if (at == std::string::npos) {
      ADD_FAILURE() << r.output;
      return 0.0;
    }
    const size_t to = r.output.find(" to ", at);
    return std::stod(r.output.substr(to + 4));
  };
  const double default_top = top_of_nu_reach("", "default");
  const double wide_top = top_of_nu_reach(" --sweep-stiffness-ratio 0.02 0.9", "wide");
  EXPECT_GT(wide_top, default_top + 0.02) << "default box " << default_top << ", kt/kn from 0.02 " << wide_top;
  int map_files = 0;  // the box is part of the maps' key: two map files
  for (const auto& e : fs::directory_iterator(dir / "maps")) map_files += e.path().extension() == ".json";
  EXPECT_EQ(map_files, 2);
  fs::remove_all(dir);
}

}  // namespace

namespace {

// --model lattice: the files of the calibration; the strength map's row measured into the
// maps folder and reused by the next run; bonded-only settings refused.
TEST(CalibrateToMaterialCommand, LatticeModelWritesItsParametersAndScenes) {
  const fs::path out = fs::temp_directory_path() / ("specimen_cal_cli_lattice_" + std::to_string(getpid()));
  fs::remove_all(out);
  const std::string material =
      Material("lattice", "youngs_modulus = 30e9\npoisson_ratio = 0.25\nucs = 90e6\ntensile_strength = 6e6\n"
                          "density = 2600\n").string();
  const fs::path maps = out / "maps";
  const Result r = RunCalibrate(material + " --model lattice --count 500 --rounds 3 --rate-group 4e-5 --output " +
                                out.string() + " --name l --maps-dir " + maps.string());
  ASSERT_TRUE(r.status == 0 || r.status == 4) << r.output;
  EXPECT_NE(r.output.find("rows nu 0.25 measured now"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("before round 1"), std::string::npos) << r.output;
  int map_files = 0;
  for (const auto& e : fs::directory_iterator(maps))
    map_files += e.path().filename().string().rfind("maps_2d_lattice_", 0) == 0;
  EXPECT_EQ(map_files, 1);
  const Result again = RunCalibrate(material + " --model lattice --count 500 --rounds 1 --rate-group 4e-5 --output " +
                                    (out / "again").string() + " --maps-dir " + maps.string());
  EXPECT_TRUE(again.status == 0 || again.status == 4) << again.output;
  EXPECT_NE(again.output.find("(built by"), std::string::npos) << again.output;
  for (const char* file : {"l_report.txt", "l_report.json", "l_parameters.toml", "l_ucs.packing", "l_bts.packing",
                           "l_ucs_scene.toml", "l_bts_scene.toml"})
    EXPECT_TRUE(fs::exists(out / file)) << file << "\n" << r.output;
  std::ifstream in(out / "l_parameters.toml");
  const std::string parameters((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(parameters.find("model = \"lattice\""), std::string::npos) << parameters;
  // The scenes repeat the rounds' rate: the group given.
  std::ifstream bts_scene(out / "l_bts_scene.toml");
  const std::string bts((std::istreambuf_iterator<char>(bts_scene)), std::istreambuf_iterator<char>());
  EXPECT_NE(bts.find("loading_rate_group = 4"), std::string::npos) << bts;
  // The scenes run as they are.
  const Result scene = specimen::testing::RunProgram(
      "run-test", (out / "l_ucs_scene.toml").string() + " --output " + (out / "run").string() + " --no-pictures");
  EXPECT_TRUE(scene.status == 0) << scene.output;
  fs::remove_all(out);
  for (const char* bonded : {" --threads 2", " --nu-p 0.3", " --dimension 3", " --lattice-map some"}) {
    SCOPED_TRACE(bonded);
    const fs::path bad = fs::temp_directory_path() / "specimen_cal_cli_lattice_bad";
    fs::remove_all(bad);
    const Result b = RunCalibrate(material + " --model lattice --output " + bad.string() + bonded);
    EXPECT_EQ(b.status, 2) << b.output;
    EXPECT_FALSE(fs::exists(bad) && !fs::is_empty(bad));
  }
}

}  // namespace

namespace {

// A Brazilian "disc" that is a rectangle is refused before any work: status 2, nothing in the
// output or maps folders (no sweep journal).
TEST(CalibrateToMaterialCommand, AWrongSpecimenShapeIsRefusedBeforeTheSweep) {
  const fs::path dir = fs::temp_directory_path() / ("specimen_cal_cli_shape_" + std::to_string(getpid()));
  fs::remove_all(dir);
  const Result g = specimen::testing::RunProgram(
      "generate-packing", "--domain \"rectangle 0 0 0.01 0.01\" --count 200 --no-pictures --output " + dir.string());
  ASSERT_EQ(g.status, 0) << g.output;
  const std::string packing = (dir / "packing.packing").string();
  for (const char* model : {"rigid", "lattice"}) {
    SCOPED_TRACE(model);
    const fs::path out = dir / "out", maps = dir / "maps";
    const Result r = RunCalibrate(Material("shape", kGood).string() + " --model " + model + " --packing " + packing +
                                  " --bts-packing " + packing + " --output " + out.string() +
                                  (std::string(model) == "rigid" ? " --maps-dir " + maps.string() : ""));
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("disc"), std::string::npos) << r.output;
    EXPECT_TRUE(!fs::exists(out) || fs::is_empty(out));
    EXPECT_TRUE(!fs::exists(maps) || fs::is_empty(maps));
  }
  fs::remove_all(dir);
}

}  // namespace
