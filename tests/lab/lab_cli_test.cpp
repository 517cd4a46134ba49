// The run-test command as a user runs it (tools/run_test.cpp): a scene file in, the report
// and the files out; exit statuses of tools/command_line.h (0 success, 2 bad input, 3 file
// error, 4 a strength test without a peak); nothing written for bad input.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

namespace {

namespace fs = std::filesystem;

struct Result {
  int status = -1;
  std::string output;  // stdout and stderr
};

Result Execute(const std::string& command) {
  Result result;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  char buffer[4096];
  while (fgets(buffer, sizeof(buffer), pipe)) result.output += buffer;
  const int raw = pclose(pipe);
  result.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return result;
}

// Per process: ctest runs the tests of this suite as parallel processes, each of which makes
// its own packing in SetUpTestSuite.
fs::path Scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() /
                       ("specimen_run_test_cli_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

bool MissingOrEmpty(const fs::path& dir) { return !fs::exists(dir) || fs::is_empty(dir); }

std::vector<std::string> Lines(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The integer in column `column` (from 0) of a CSV row.
int Field(const std::string& row, int column) {
  size_t start = 0;
  for (int k = 0; k < column; ++k) start = row.find(',', start) + 1;
  return std::stoi(row.substr(start, row.find(',', start) - start));
}

// The values of the VTU cell array "kind" (ascii, one per line).
std::vector<int> VtuKinds(const fs::path& path) {
  std::vector<int> kinds;
  bool inside = false;
  for (const std::string& line : Lines(path)) {
    if (line.find("Name=\"kind\"") != std::string::npos) {
      inside = true;
    } else if (inside) {
      if (line.find("</DataArray>") != std::string::npos) break;
      kinds.push_back(std::stoi(line));
    }
  }
  return kinds;
}

class RunTestCommand : public testing::Test {
 protected:
  // A 300-disc 10 x 10 mm packing, made once (generate-packing, as a user would).
  static void SetUpTestSuite() {
    const fs::path dir = Scratch("packing");
    const Result r = Execute(std::string(SPECIMEN_BINARY_DIR) +
                             "/tools/generate-packing --domain \"rectangle 0 0 0.01 0.01\" "
                             "--count 300 --no-pictures --quiet --output " +
                             dir.string());
    ASSERT_EQ(r.status, 0) << r.output;
    packing_ = (dir / "packing.packing").string();
  }
  // Removes this process's scratch directories.
  static void TearDownTestSuite() {
    const std::string suffix = "_" + std::to_string(getpid());
    std::vector<fs::path> mine;
    for (const auto& entry : fs::directory_iterator(fs::temp_directory_path())) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("specimen_run_test_cli_", 0) == 0 && name.size() > suffix.size() &&
          name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
        mine.push_back(entry.path());
    }
    for (const fs::path& dir : mine) fs::remove_all(dir);
  }

  // Writes a scene with the packing, a breakable material and `test` lines.
  static fs::path Scene(const fs::path& dir, const std::string& test,
                        const std::string& material_extra = "bond_tensile_strength = 2e3\n"
                                                            "bond_shear_strength = 2e4\n") {
    const fs::path path = dir / "scene.toml";
    std::ofstream(path) << "[specimen]\npacking = \"" << packing_
                        << "\"\n[material]\nnormal_stiffness = 1e10\ntangential_stiffness = "
                           "2.5e9\nfriction_coefficient = 0.5\ndensity = 2000\n"
                        << material_extra << "[test]\n"
                        << test << "[output]\nname = \"t\"\n";
    return path;
  }

  static Result RunTest(const std::string& arguments) {
    return Execute(std::string(SPECIMEN_BINARY_DIR) + "/tools/run-test " + arguments + " --quiet");
  }

  static std::string packing_;
};
std::string RunTestCommand::packing_;

TEST_F(RunTestCommand, UcsWritesTheReportAndFiles) {
  const fs::path dir = Scratch("ucs");
  const fs::path out = dir / "out";
  const Result r = RunTest(Scene(dir, "kind = \"ucs\"\n").string() + " --output " + out.string() +
                           " --no-pictures");
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* text : {"UCS (peak)", "E, nu (plane strain)", "E', nu' (in-plane)", "files:"})
    EXPECT_NE(r.output.find(text), std::string::npos) << text << "\n" << r.output;
  for (const char* file : {"t_curve.csv", "t_bonds.csv", "t_summary.json", "t_peak.vtu", "t_end.vtu"})
    EXPECT_TRUE(fs::exists(out / file)) << file;
  std::ifstream in(out / "t_summary.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["command"], "run-test");
  EXPECT_TRUE(j["result"]["peak_reached"].get<bool>());
  EXPECT_GT(j["result"]["peak_stress_pa"].get<double>(), 0.0);
  EXPECT_TRUE(j["result"]["elastic"]["measured"].get<bool>());
  // Not asked for: the quasi-static check is reported as not run, in the JSON and the report.
  EXPECT_EQ(j["result"]["quasi_static_check"]["status"], "not run");
  EXPECT_TRUE(j["result"]["quasi_static_check"]["passed"].is_null());
  EXPECT_NE(r.output.find("not run: not requested"), std::string::npos) << r.output;

  // 2D: forces, energies per metre of thickness and the stress volume an area, by name.
  const std::vector<std::string> curve = Lines(out / "t_curve.csv");
  ASSERT_GT(curve.size(), 1u);
  for (const char* column : {",control_pa,", ",platen_force_n_per_m,", ",stress_area_m2,",
                             ",kinetic_j_per_m,", ",dissipated_j_per_m"})
    EXPECT_NE(curve[0].find(column), std::string::npos) << column << " in " << curve[0];
  EXPECT_TRUE(j["result"].contains("peak_force_n_per_m"));

  // One code table for the broken bonds: 2 tension, 3 shear, in bonds.csv, cracks.csv and
  // the VTU cell array "kind" (0 particle, 1 intact bond).
  const std::vector<std::string> bonds = Lines(out / "t_bonds.csv");
  ASSERT_GT(bonds.size(), 1u) << "the test breaks bonds";
  EXPECT_EQ(bonds[0], "i,j,kind,time_s,boundary_strain,x_m,y_m,z_m");
  std::vector<int> listed(4, 0);
  for (size_t k = 1; k < bonds.size(); ++k) ++listed.at(Field(bonds[k], 2));
  const std::vector<std::string> cracks = Lines(out / "t_cracks.csv");
  EXPECT_EQ(cracks[0], "x_i_m,y_i_m,x_j_m,y_j_m,kind");
  std::vector<int> drawn(4, 0);
  for (size_t k = 1; k < cracks.size(); ++k) ++drawn.at(Field(cracks[k], 4));
  std::vector<int> cells(4, 0);
  for (int code : VtuKinds(out / "t_end.vtu")) ++cells.at(code);
  EXPECT_EQ(listed[0] + listed[1], 0);
  EXPECT_EQ(drawn[0] + drawn[1], 0);
  EXPECT_EQ(listed[2] + listed[3], j["result"]["broken_bonds"]["listed"].get<int>());
  EXPECT_EQ(drawn[2], j["result"]["broken_bonds"]["tension"].get<int>());
  EXPECT_EQ(drawn[3], j["result"]["broken_bonds"]["shear"].get<int>());
  for (int code : {2, 3}) {
    EXPECT_EQ(cells[code], drawn[code]) << code;
    EXPECT_LE(listed[code], drawn[code]) << code;
  }
  EXPECT_GT(cells[0], 0);
  EXPECT_GT(cells[1], 0);
}

// Bad input: status 2, the message names the problem, no output directory is created.
TEST_F(RunTestCommand, BadInputWritesNothing) {
  const struct {
    const char* test;
    const char* words;
  } cases[] = {
      {"kind = \"biaxial\"\nconfining_stress = -1e6\n", "confining"},
      {"kind = \"ucs\"\nmodulus_window = [0.0, 0.5]\n", "modulus_window"},
      {"kind = \"ucs\"\nmodulus_window = [0.1, 1.2]\n", "modulus_window"},
      {"kind = \"brazilian\"\n", "disc"},
      {"kind = \"ucs\"\nno_such_key = 1\n", "no_such_key"},
      {"kind = \"triaxial\"\n", "triaxial"},
      // The messages name the scene's keys, not the library's fields.
      {"kind = \"ucs\"\nsafety_factor = 1.5\n", "safety_factor = 1.5"},
      {"kind = \"ucs\"\npost_peak_fraction = 2\n", "post_peak_fraction = 2"},
      // An integer is not a boolean.
      {"kind = \"ucs\"\nquasi_static_check = 7\n", "true or false"},
      // The step budget, before the first step: a platen speed a billion steps away, or a
      // budget below what the test needs.
      {"kind = \"ucs\"\nplaten_speed = 1e-12\n", "more than max_steps = 20000000"},
      {"kind = \"ucs\"\nmax_steps = 100\n", "more than max_steps = 100"},
      {"kind = \"ucs\"\nmax_steps = 0\n", "max_steps = 0"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.test);
    const fs::path dir = Scratch("bad");
    const fs::path out = dir / "out";
    const Result r = RunTest(Scene(dir, c.test).string() + " --output " + out.string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find(c.words), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("run-test: error:"), std::string::npos) << r.output;
    EXPECT_TRUE(MissingOrEmpty(out)) << r.output;
  }
  {  // a misspelled required key: the message names the typo too
    const fs::path dir = Scratch("typo");
    std::ofstream(dir / "scene.toml") << "[specimen]\npacking = \"" << packing_
                                      << "\"\n[material]\nnormal_stifness = 1e10\ndensity = 2000\n[test]\n"
                                         "kind = \"ucs\"\n";
    const Result r = RunTest((dir / "scene.toml").string() + " --output " + (dir / "out").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("'normal_stiffness' is missing (the table has 'normal_stifness': misspelled?)"),
              std::string::npos)
        << r.output;
  }
  // Physical ranges, named by the scene's keys: kt for kn (a typo: the time step would follow
  // kt, the platen speed kn), stiffnesses and densities that lose every digit or overflow.
  for (const auto& [material, words] : std::vector<std::pair<std::string, std::string>>{
           {"normal_stiffness = 1e-3\ntangential_stiffness = 2.5e9\ndensity = 2000\n", "kt/kn <= 10"},
           {"normal_stiffness = 1e300\ndensity = 2000\n", "normal_stiffness (kn) = 1e+300 is not allowed"},
           {"normal_stiffness = 1e10\ndensity = 1e-300\n", "density = 1e-300 is not allowed"}}) {
    SCOPED_TRACE(material);
    const fs::path dir = Scratch("ranges");
    std::ofstream(dir / "scene.toml") << "[specimen]\npacking = \"" << packing_ << "\"\n[material]\n" << material
                                      << "[test]\nkind = \"ucs\"\n";
    const Result r = RunTest((dir / "scene.toml").string() + " --output " + (dir / "out").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find(words), std::string::npos) << r.output;
    EXPECT_TRUE(MissingOrEmpty(dir / "out"));
  }
  {  // nu_p without Ep would silently run rigid particles
    const fs::path dir = Scratch("nu_p");
    const Result r = RunTest(Scene(dir, "kind = \"ucs\"\n", "particle_poisson_ratio = 0.3\n").string() +
                             " --output " + (dir / "out").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("particle_youngs_modulus"), std::string::npos) << r.output;
    EXPECT_TRUE(MissingOrEmpty(dir / "out"));
  }
  // Options of the command line: a value given is applied as given, parse errors are bad
  // input (status 2, not CLI11's own codes).
  for (const char* options : {"--threads 0", "--name ''", "--bogus", "--threads two"}) {
    SCOPED_TRACE(options);
    const fs::path dir = Scratch("options");
    const Result r = RunTest(Scene(dir, "kind = \"ucs\"\n").string() + " --output " +
                             (dir / "out").string() + " " + options);
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(MissingOrEmpty(dir / "out"));
  }
  // A domain the packing does not fill (a generated specimen must match its own domain; a
  // packing file whose domain is larger than its particles).
  const fs::path dir = Scratch("unfilled");
  std::ifstream in(packing_);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string from = "rectangle 0 0 0.01", to = "rectangle 0 0 0.03";
  const size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos) << text.substr(0, 400);
  text.replace(at, from.size(), to);
  std::ofstream(dir / "wide.packing") << text;
  std::ofstream(dir / "scene.toml") << "[specimen]\npacking = \"wide.packing\"\n[material]\n"
                                       "normal_stiffness = 1e10\ndensity = 2000\n[test]\n"
                                       "kind = \"ucs\"\n";
  const Result r = RunTest((dir / "scene.toml").string() + " --output " + (dir / "out").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("do not fill"), std::string::npos) << r.output;
  EXPECT_TRUE(MissingOrEmpty(dir / "out"));
}

TEST_F(RunTestCommand, FileErrors) {
  const fs::path dir = Scratch("files");
  // A scene that does not exist.
  Result r = RunTest((dir / "missing.toml").string() + " --output " + (dir / "out").string());
  EXPECT_EQ(r.status, 3) << r.output;
  EXPECT_TRUE(MissingOrEmpty(dir / "out"));
  // An output directory that cannot be created (below a regular file): refused before the run.
  std::ofstream(dir / "file") << "x";
  r = RunTest(Scene(dir, "kind = \"ucs\"\n").string() + " --output " + (dir / "file" / "out").string());
  EXPECT_EQ(r.status, 3) << r.output;
  EXPECT_EQ(r.output.find("UCS (peak)"), std::string::npos) << r.output;  // no test was run
  // A directory given as the scene.
  r = RunTest(dir.string() + " --output " + (dir / "out").string());
  EXPECT_EQ(r.status, 3) << r.output;
  EXPECT_NE(r.output.find("is a directory"), std::string::npos) << r.output;
  // A scene that is not TOML: bad input (2), as the same mistake on a command line, with the line.
  std::ofstream(dir / "broken.toml") << "[test\nkind = ";
  r = RunTest((dir / "broken.toml").string() + " --output " + (dir / "out").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("line 1"), std::string::npos) << r.output;
  EXPECT_TRUE(MissingOrEmpty(dir / "out"));
}

// A strength test that reaches its strain limit without a peak: status 4 and the message,
// with the files written for diagnosis.
TEST_F(RunTestCommand, NoPeakIsAComputationFailure) {
  const fs::path dir = Scratch("nopeak");
  const fs::path out = dir / "out";
  const Result r = RunTest(Scene(dir, "kind = \"ucs\"\nstrain_limit = 5e-4\n", "").string() +
                           " --output " + out.string() + " --no-pictures --no-snapshots");
  EXPECT_EQ(r.status, 4) << r.output;
  EXPECT_NE(r.output.find("without a peak"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(out / "t_summary.json"));
}

}  // namespace

namespace {

// A lattice scene on the suite's packing (model = "lattice", [material] lines given).
fs::path LatticeScene(const fs::path& dir, const std::string& packing, const std::string& material,
                      const std::string& test) {
  const fs::path path = dir / "lattice.toml";
  std::ofstream(path) << "[specimen]\npacking = \"" << packing << "\"\n[material]\nmodel = \"lattice\"\n"
                      << material << "[test]\n" << test << "[output]\nname = \"l\"\n";
  return path;
}

const char* kLatticeMaterial =
    "youngs_modulus = 30e9\npoisson_ratio = 0.25\ntensile_strength = 8e6\ncohesion = 25e6\ndensity = 2650\n";

}  // namespace

// The bonded Brazilian test's jaws: loading_arc out of range, with platen friction, or on a
// specimen that is not a disc: exit 2 naming the cause, nothing written.
TEST_F(RunTestCommand, BondedLoadingArcBadInputWritesNothing) {
  const struct {
    std::string test, words;
  } cases[] = {
      {"kind = \"brazilian\"\nloading_arc = 70\n", "loading_arc"},
      {"kind = \"brazilian\"\nloading_arc = -5\n", "loading_arc"},
      {"kind = \"brazilian\"\nloading_arc = 30\nplaten_friction = 0.3\n", "platen_friction"},
      {"kind = \"ucs\"\nloading_arc = 30\n", "setting of the Brazilian test"},
      {"kind = \"brazilian\"\nloading_arc = 30\n", "disc"},  // the packing is a rectangle
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.test);
    const fs::path dir = Scratch("bonded_arc");
    const Result r = RunTest(Scene(dir, c.test).string() + " --output " + (dir / "out").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find(c.words), std::string::npos) << r.output;
    EXPECT_TRUE(MissingOrEmpty(dir / "out"));
  }
}

TEST_F(RunTestCommand, LatticeUcsWritesTheReportAndFiles) {
  const fs::path dir = Scratch("lattice");
  const fs::path out = dir / "out";
  const Result r = RunTest(LatticeScene(dir, packing_, kLatticeMaterial, "kind = \"ucs\"\n").string() +
                           " --output " + out.string() + " --no-pictures");
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* file : {"l_curve.csv", "l_summary.json", "l_peak.vtu", "l_end.vtu"})
    EXPECT_TRUE(fs::exists(out / file)) << file;
  std::ifstream in(out / "l_summary.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_TRUE(j["result"]["peak_reached"].get<bool>());
  // E and nu are inputs of the lattice (300 discs: a few per cent of dynamics).
  EXPECT_NEAR(j["result"]["linear_elastic"]["youngs_modulus_pa"].get<double>() / 30e9, 1.0, 0.03);
  EXPECT_NEAR(j["result"]["linear_elastic"]["poisson_ratio"].get<double>(), 0.25, 0.01);
}

TEST_F(RunTestCommand, LatticeBadInputWritesNothing) {
  const struct {
    std::string material, test, words;
  } cases[] = {
      {kLatticeMaterial, "kind = \"isotropic\"\n", "ucs, biaxial and brazilian"},
      {kLatticeMaterial, "kind = \"biaxial\"\nconfining_stresses = [1e6, 2e6]\n", "confining_stresses"},
      {kLatticeMaterial, "kind = \"ucs\"\npause_on_breakage = false\n", "pause_on_breakage"},
      {kLatticeMaterial, "kind = \"ucs\"\nplaten_zone = 0.1\n", "setting of the Brazilian test"},
      {kLatticeMaterial, "kind = \"ucs\"\nloading_arc = 20\n", "loading_arc"},
      {kLatticeMaterial, "kind = \"brazilian\"\nwave_share = 1.5\n", "wave_share"},
      {kLatticeMaterial, "kind = \"brazilian\"\nloading_arc = 90\n", "loading_arc"},
      {kLatticeMaterial, "kind = \"brazilian\"\nplaten_zone = 0.5\n", "platen_zone"},
      {"youngs_modulus = 30e9\npoisson_ratio = 0.25\ntensile_strength = 8e6\ndensity = 2650\n", "kind = \"ucs\"\n",
       "cohesion"},
      {"youngs_modulus = 30e9\npoisson_ratio = 0.6\ntensile_strength = 8e6\ncohesion = 25e6\ndensity = 2650\n",
       "kind = \"ucs\"\n", "poisson_ratio"},
      {std::string(kLatticeMaterial) + "normal_stiffness = 1e10\n", "kind = \"ucs\"\n", "normal_stiffness"},
      {std::string(kLatticeMaterial) + "youngs_modulus_1 = 1e10\n", "kind = \"ucs\"\n", "either"},
      {kLatticeMaterial, "kind = \"ucs\"\nmax_steps = 10\n", "more than max_steps = 10"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.test + c.material);
    const fs::path dir = Scratch("lattice_bad");
    const Result r =
        RunTest(LatticeScene(dir, packing_, c.material, c.test).string() + " --output " + (dir / "out").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find(c.words), std::string::npos) << r.output;
    EXPECT_TRUE(MissingOrEmpty(dir / "out"));
  }
  // platen_zone and wave_share belong to the lattice: refused with bonded particles; so is
  // loading_arc outside a Brazilian test.
  for (const std::string key : {"platen_zone", "wave_share", "loading_arc"}) {
    const fs::path dir = Scratch("lattice_zone");
    const Result r = RunTest(Scene(dir, "kind = \"ucs\"\n" + key + " = 0.1\n").string() + " --output " +
                             (dir / "out").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find(key), std::string::npos) << r.output;
  }
}
