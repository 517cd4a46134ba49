// The stability-limit command as a user runs it: the sample runs of its header comment, the
// JSON keys, the files, the exit statuses and the messages for bad input (no file written).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

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

Result StabilityLimit(const std::string& arguments) {
  return Execute(std::string(SPECIMEN_BINARY_DIR) + "/tools/stability-limit " + arguments +
                 " --quiet");
}

// Per process: ctest runs the tests of this suite as parallel processes.
fs::path FreshDirectory(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("specimen_stability_cli_" + name + "_" +
                                                    std::to_string(getpid()));
  fs::remove_all(dir);
  return dir;
}

bool EmptyOrMissing(const fs::path& dir) { return !fs::exists(dir) || fs::is_empty(dir); }

nlohmann::json ReadJson(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// A small generated packing, made once for the suite (generate-packing, as a user would).
class StabilityLimitCommand : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    const fs::path dir = FreshDirectory("packing");
    const Result r = Execute(std::string(SPECIMEN_BINARY_DIR) +
                             "/tools/generate-packing --domain \"rectangle 0 0 0.01 0.01\" "
                             "--count 300 --no-pictures --quiet --output " +
                             dir.string());
    ASSERT_EQ(r.status, 0) << r.output;
    packing_ = (dir / "packing.packing").string();
  }
  static std::string packing_;
};
std::string StabilityLimitCommand::packing_;

TEST_F(StabilityLimitCommand, FirstSampleRunWritesTheReportAndJson) {
  const fs::path dir = FreshDirectory("first");
  const Result r = StabilityLimit("--packing " + packing_ + " --kn 7e10 --density 2000 --output " +
                                  dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* text : {"per-particle bound", "2/omega_max, certified (DEM)",
                           "admissible kn/(Ep l)", "Verdict for the recommended time step"})
    EXPECT_NE(r.output.find(text), std::string::npos) << text << "\n" << r.output;
  const nlohmann::json j = ReadJson(dir / "packing_stability.json");
  EXPECT_EQ(j["command"], "stability-limit");
  {  // the printed report is also a file
    std::ifstream text(dir / "packing_stability.txt");
    const std::string report((std::istreambuf_iterator<char>(text)), std::istreambuf_iterator<char>());
    EXPECT_NE(report.find("Verdict for the recommended time step"), std::string::npos) << report;
  }
  const nlohmann::json& a = j["analysis"];
  for (const char* key : {"scene", "time_step", "ddem_convergence", "verdict", "sweep", "warnings"})
    EXPECT_TRUE(a.contains(key)) << key;
  for (const char* key : {"per_particle_bound_s", "gershgorin_bound_s", "dem_critical_time_step_s",
                          "critical_time_step_s", "recommended_time_step_s", "dem_eigenvalue"})
    EXPECT_TRUE(a["time_step"].contains(key)) << key;
  for (const char* key : {"unit_spectral_radius_pa", "admissible_kn_over_ep",
                          "recommended_kn_over_ep", "smallest_youngs_modulus_pa", "lattice_limits"})
    EXPECT_TRUE(a["ddem_convergence"].contains(key)) << key;
  EXPECT_EQ(a["verdict"]["verdict"], "stable");
  // Units in the names; the 2D stiffness is per metre of thickness.
  EXPECT_EQ(a["scene"]["normal_stiffness_n_per_m_per_m"].get<double>(), 7e10);
  EXPECT_FALSE(a["scene"].contains("normal_stiffness_n_per_m"));
  EXPECT_TRUE(a.contains("wall_time_s"));
  // The recommended step is 0.9 of the certified one, which is at most the Ritz estimate.
  const double critical = a["time_step"]["critical_time_step_s"];
  EXPECT_NEAR(a["time_step"]["recommended_time_step_s"].get<double>(), 0.9 * critical,
              1e-12 * critical);
  EXPECT_LE(critical, a["time_step"]["dem_time_step_ritz_s"].get<double>());
  EXPECT_TRUE(a["ddem_convergence"]["spectral_radius"].is_null());  // rigid particles
}

// Bonds with a moment add rotational springs: with kt = 0 they bring the rotations in and
// can only lower the critical step (Weyl: every link adds a positive semi-definite term).
TEST_F(StabilityLimitCommand, BondMomentsEnterTheNetwork) {
  auto critical = [&](const std::string& extra, const std::string& name) {
    const fs::path dir = FreshDirectory(name);
    const Result r = StabilityLimit("--packing " + packing_ + " --kn 7e10 --density 2000 " + extra +
                                    " --output " + dir.string());
    EXPECT_EQ(r.status, 0) << r.output;
    const nlohmann::json a = ReadJson(dir / "packing_stability.json")["analysis"];
    return std::make_pair(a["time_step"]["critical_time_step_s"].get<double>(), r.output);
  };
  const auto [without, plain] = critical("", "no_moment");
  const auto [with, report] = critical("--bond-radius-ratio 1", "moment");
  EXPECT_NE(report.find("bonds carry moments: radius ratio 1"), std::string::npos) << report;
  EXPECT_EQ(plain.find("bonds carry moments"), std::string::npos);
  EXPECT_LE(with, without);
  const Result bad = StabilityLimit("--packing " + packing_ +
                                    " --kn 7e10 --density 2000 --bond-radius-ratio 1.5");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.output.find("--bond-radius-ratio"), std::string::npos) << bad.output;
}

TEST_F(StabilityLimitCommand, SecondSampleRunJudgesADdemStep) {
  const fs::path dir = FreshDirectory("second");
  const Result r = StabilityLimit("--packing " + packing_ +
                                  " --kn 7e10 --kt 3.5e10 --density 2000 --Ep 2e11 --nu-p 0.35 "
                                  "--dt 2.5e-8 --damping 0.1 --output " +
                                  dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json a = ReadJson(dir / "packing_stability.json")["analysis"];
  EXPECT_TRUE(a["time_step"]["ddem_available"].get<bool>());
  EXPECT_NEAR(a["ddem_convergence"]["kn_over_ep"].get<double>(), 0.35, 1e-12);
  EXPECT_EQ(a["verdict"]["time_step_s"].get<double>(), 2.5e-8);
  EXPECT_TRUE(a["verdict"]["time_step_proposed"].get<bool>());
  EXPECT_TRUE(a["time_step"]["flutter_possible"].get<bool>());  // kt > 0 with DDEM
  EXPECT_NE(r.output.find("Verdict for the proposed time step 2.5e-08 s"), std::string::npos)
      << r.output;
}

TEST_F(StabilityLimitCommand, ThirdSampleRunReadsAParameterFileAndSweeps) {
  const fs::path dir = FreshDirectory("third");
  fs::create_directories(dir);
  const fs::path toml = dir / "params.toml";
  std::ofstream(toml) << "[material]\nnormal_stiffness = 7e10\ndensity = 2000.0\n"
                         "particle_youngs_modulus = 2e11\nparticle_poisson_ratio = 0.25\n"
                         "[stability]\nmax_spectral_radius = 0.9\n";
  const fs::path out = dir / "out";
  const Result r =
      StabilityLimit("--packing " + packing_ + " --parameters " + toml.string() +
                     " --sweep nu_p --sweep-values 0,0.25,0.45 --output " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(out / "packing_sweep_nu_p.csv"));
  // The plot next to the CSV (gnuplot, a setup.sh package).
  EXPECT_TRUE(fs::exists(out / "packing_sweep_nu_p.png")) << r.output;
  EXPECT_GT(fs::file_size(out / "packing_sweep_nu_p.png"), 1000u);
  EXPECT_NE(r.output.find("largest: kn/(Ep l)"), std::string::npos) << r.output;
  const nlohmann::json a = ReadJson(out / "packing_stability.json")["analysis"];
  EXPECT_EQ(a["sweep"].size(), 3u);
  // The largest admissible value of the sweep and its nu_p.
  double largest = 0.0;
  for (const auto& row : a["sweep"])
    largest = std::max(largest, row["admissible_kn_over_ep"].get<double>());
  EXPECT_EQ(a["sweep_largest"]["admissible_kn_over_ep"].get<double>(),
            largest);
  EXPECT_EQ(a["ddem_convergence"]["max_spectral_radius"].get<double>(), 0.9);
  EXPECT_EQ(a["scene"]["particle_poisson_ratio"].get<double>(), 0.25);
  // The sweep row at nu_p = 0.25 is the analysis' own limit.
  EXPECT_NEAR(a["sweep"][1]["admissible_kn_over_ep"].get<double>(),
              a["ddem_convergence"]["admissible_kn_over_ep"].get<double>(), 1e-12);
  // An option overrides the file.
  const Result over = StabilityLimit("--packing " + packing_ + " --parameters " + toml.string() +
                                     " --nu-p 0.3 --output " + out.string());
  ASSERT_EQ(over.status, 0) << over.output;
  EXPECT_EQ(ReadJson(out / "packing_stability.json")["analysis"]["scene"]["particle_poisson_ratio"]
                .get<double>(),
            0.3);
}

// The [material] table calibrate-to-material writes (_parameters.toml) is read as it is: its
// strengths and friction do not enter the limit, and its plane_model spelling is accepted.
TEST_F(StabilityLimitCommand, ReadsTheCalibratorsParameterFile) {
  const fs::path dir = FreshDirectory("calibrated");
  fs::create_directories(dir);
  const fs::path toml = dir / "calibration_parameters.toml";
  std::ofstream(toml) << "[material]\nnormal_stiffness = 7e10\ntangential_stiffness = 1.4e10\n"
                         "bond_tensile_strength = 2.2e4\nbond_shear_strength = 1.2e5\n"
                         "friction_coefficient = 0.8\ndensity = 2650\nplane_model = \"plane_strain\"\n";
  const Result r = StabilityLimit("--packing " + packing_ + " --parameters " + toml.string() + " --output " +
                                  (dir / "out").string());
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json a = ReadJson(dir / "out" / "packing_stability.json")["analysis"];
  EXPECT_GT(a["time_step"]["critical_time_step_s"].get<double>(), 0.0);
  // A strength that is not a number is still an error naming the key.
  std::ofstream(toml) << "[material]\nnormal_stiffness = 7e10\ndensity = 2650\nbond_tensile_strength = \"x\"\n";
  const Result bad = StabilityLimit("--packing " + packing_ + " --parameters " + toml.string() + " --output " +
                                    (dir / "bad").string());
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_NE(bad.output.find("bond_tensile_strength"), std::string::npos) << bad.output;
}

TEST_F(StabilityLimitCommand, FourthSampleRunWithWalls) {
  const fs::path dir = FreshDirectory("fourth");
  const Result r = StabilityLimit("--packing " + packing_ +
                                  " --kn 7e10 --density 2000 --walls bottom,top "
                                  "--wall-stiffness 7e11 --damping 0.1 --output " +
                                  dir.string() + " --name ucs");
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json a = ReadJson(dir / "ucs_stability.json")["analysis"];
  EXPECT_GT(a["scene"]["wall_links"].get<int>(), 0);
  // Stiff walls lower the limit below that of the free packing.
  const Result free =
      StabilityLimit("--packing " + packing_ + " --kn 7e10 --density 2000 --damping 0.1 --output " +
                     dir.string() + " --name free");
  ASSERT_EQ(free.status, 0) << free.output;
  const nlohmann::json b = ReadJson(dir / "free_stability.json")["analysis"];
  EXPECT_LT(a["time_step"]["critical_time_step_s"].get<double>(),
            b["time_step"]["critical_time_step_s"].get<double>());
}

TEST_F(StabilityLimitCommand, BadInputExitsWithTwoAndWritesNothing) {
  const fs::path bad_toml = fs::temp_directory_path() / "specimen_stability_bad.toml";
  std::ofstream(bad_toml) << "[material]\nnormal_stiffness = 7e10\nstiffness = 3\n";
  const fs::path bad_value_toml = fs::temp_directory_path() / "specimen_stability_bad_value.toml";
  std::ofstream(bad_value_toml) << "[material]\nnormal_stiffness = 7e10\ndensity = 2000\n"
                                   "[time_step]\nsafety_factor = 1.5\n";
  struct Case {
    std::string arguments;
    std::string must_mention;
  };
  const Case cases[] = {
      {"--density 2000", "kn is missing"},
      {"--kn 7e10", "density is missing"},
      // The messages name the options and file keys, not the library's fields.
      {"--kn -7e10 --density 2000", "kn (--kn, [material] normal_stiffness) = -7e+10"},
      {"--kn 7e10 --density 2000 --Ep 2e11 --nu-p 0.6",
       "nu_p (--nu-p, [material] particle_poisson_ratio) = 0.6"},
      {"--kn 7e10 --density 2000 --plane cylinder", "plane_model = 'cylinder'"},
      {"--kn 7e10 --density 2000 --dt -1", "the proposed time step (--dt, [time_step] time_step) = -1"},
      {"--kn 7e10 --density 2000 --walls bottom --wall-kt 1e9 --wall-friction -1",
       "the wall friction (--wall-friction, [walls] friction) = -1"},
      {"--kn 7e10 --density 2000 --safety 1.5", "(--safety, [time_step] safety_factor) = 1.5"},
      // A bad value given is rejected, never replaced by the default.
      {"--kn 7e10 --density 2000 --margin -5", "--margin"},
      {"--kn 7e10 --density 2000 --failure-probability -1", "--failure-probability"},
      {"--kn 7e10 --density 2000 --tolerance -1", "--tolerance"},
      // Settings that would be ignored are reported.
      {"--kn 7e10 --density 2000 --sweep-values 0.1,0.2", "without --sweep"},
      {"--kn 7e10 --density 2000 --wall-kt 1e9", "no wall"},
      {"--kn 7e10 --density 2000 --nu-p 0.3", "without Ep"},
      // Command-line parse errors are bad input too.
      {"--kn 7e10 --density 2000 --bogus", "--bogus"},
      {"--kn abc --density 2000", "--kn"},
      {"--kn 7e10 --density 2000 --walls bottom,diagonal", "side 'diagonal'"},
      {"--kn 7e10 --density 2000 --sweep E", "--sweep 'E'"},
      {"--kn 7e10 --density 2000 --sweep nu_p --sweep-values 0.2,0.7", "sweep nu_p = 0.7"},
      {"--parameters " + bad_toml.string() + " --density 2000", "unknown key 'stiffness'"},
      // Physical ranges: a stiffness or density that would lose every digit or overflow.
      {"--kn 1e-300 --density 2000", "kn (--kn, [material] normal_stiffness) = 1e-300 is not allowed"},
      {"--kn 1e300 --density 2000", "kn (--kn, [material] normal_stiffness) = 1e+300 is not allowed"},
      {"--kn 7e10 --density 1e-300", "density (--density, [material] density) = 1e-300"},
      {"--kn 1e-3 --kt 2.5e9 --density 2000", "kt/kn <= 10"},
      // One number grammar: decimals only, as in the packing files and the domains.
      {"--kn 0x10 --density 2000", "'0x10' is not a finite decimal number"},
      {"--kn inf --density 2000", "'inf' is not a finite decimal number"},
      // Values as given, not in fixed point.
      {"--kn 7e10 --density 2000 --dt -1e-9", "= -1e-09"},
      // Output names: no hidden files, no "..", no name too long for the file system.
      {"--kn 7e10 --density 2000 --name ..", "--name '..' is not allowed"},
      {"--kn 7e10 --density 2000 --name .hidden", "not starting with '.'"},
      {"--kn 7e10 --density 2000 --name " + std::string(300, 'a'), "at most 200 bytes"},
      // A bad value in the file is reported even when an option overrides it.
      {"--parameters " + bad_value_toml.string() + " --safety 0.9",
       bad_value_toml.string() + ": safety_factor (--safety, [time_step] safety_factor) = 1.5"},
  };
  for (const Case& c : cases) {
    const fs::path dir = FreshDirectory("bad");
    const Result r =
        StabilityLimit("--packing " + packing_ + " " + c.arguments + " --output " + dir.string());
    EXPECT_EQ(r.status, 2) << c.arguments << "\n" << r.output;
    EXPECT_NE(r.output.find(c.must_mention), std::string::npos) << c.arguments << "\n" << r.output;
    EXPECT_TRUE(EmptyOrMissing(dir)) << c.arguments;
  }
}

TEST_F(StabilityLimitCommand, FileErrorsExitWithThree) {
  const fs::path dir = FreshDirectory("files");
  Result r = StabilityLimit("--packing /nonexistent/p.packing --kn 7e10 --density 2000 --output " +
                            dir.string());
  EXPECT_EQ(r.status, 3) << r.output;
  // TOML that does not parse is bad input (2), as the same mistake on the command line.
  const fs::path broken = fs::temp_directory_path() / "specimen_stability_broken.toml";
  std::ofstream(broken) << "[material\nnormal_stiffness = \n";
  r = StabilityLimit("--packing " + packing_ + " --parameters " + broken.string() + " --output " +
                     dir.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("line 1"), std::string::npos) << r.output;
  EXPECT_TRUE(EmptyOrMissing(dir));
  // A directory as the parameter file is a file error (it was read as an empty file).
  r = StabilityLimit("--packing " + packing_ + " --parameters " + fs::temp_directory_path().string() +
                     " --kn 7e10 --density 2000 --output " + dir.string());
  EXPECT_EQ(r.status, 3) << r.output;
  EXPECT_NE(r.output.find("is a directory"), std::string::npos) << r.output;
  EXPECT_TRUE(EmptyOrMissing(dir));
  r = StabilityLimit("--packing " + packing_ +
                     " --kn 7e10 --density 2000 --output /proc/specimen_no");
  EXPECT_EQ(r.status, 3) << r.output;
}

// A packing given as a pipe (a FIFO, or a shell's <(...)) is read once: it cannot be reopened.
TEST_F(StabilityLimitCommand, ReadsAPackingFromAPipe) {
  const fs::path dir = FreshDirectory("fifo");
  fs::create_directories(dir);
  const fs::path fifo = dir / "packing.fifo";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const std::string writer = "cat " + packing_ + " > " + fifo.string() + " &";
  ASSERT_EQ(std::system(writer.c_str()), 0);
  const Result r = StabilityLimit("--packing " + fifo.string() + " --kn 7e10 --density 2000 --no-pictures --output " +
                                  (dir / "out").string());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "out" / "packing_stability.json")) << r.output;
}

// The fifth sample run: the six-spring lattice of the packing. Its verdict follows its own
// certified step (stable at half of it, unstable just above it); the Gershgorin bound lies
// below it; bad combinations are refused before any work.
TEST_F(StabilityLimitCommand, FifthSampleRunAnalysesTheLattice) {
  const fs::path dir = FreshDirectory("lattice");
  const std::string base = "--packing " + packing_ + " --lattice-E 40e9 --lattice-nu 0.25 --density 2650 --output ";
  Result r = StabilityLimit(base + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json j = ReadJson(dir / "packing_stability.json");
  EXPECT_EQ(j["model"], "lattice");
  const double critical = j["critical_time_step_s"].get<double>();
  EXPECT_GT(critical, 0.0);
  EXPECT_LE(j["gershgorin_time_step_s"].get<double>(), critical * (1.0 + 1e-12));
  EXPECT_GT(j["lattice"]["surface_nodes"].get<int>(), 0);
  char dt[64];
  std::snprintf(dt, sizeof dt, " --dt %.6g", 0.5 * critical);
  r = StabilityLimit(base + dir.string() + dt);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(ReadJson(dir / "packing_stability.json")["verdict"], "stable");
  std::snprintf(dt, sizeof dt, " --dt %.6g", 1.01 * critical);
  r = StabilityLimit(base + dir.string() + dt);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(ReadJson(dir / "packing_stability.json")["verdict"], "unstable");
  for (const char* bad : {" --lattice-E 40e9 --density 2650", " --lattice-E 40e9 --lattice-nu 0.25",
                          " --lattice-E 40e9 --lattice-nu 0.25 --density 2650 --kn 1e10",
                          " --lattice-E 40e9 --lattice-nu 0.7 --density 2650"}) {
    SCOPED_TRACE(bad);
    const fs::path out = FreshDirectory("lattice_bad");
    const Result b = StabilityLimit("--packing " + packing_ + bad + " --output " + out.string());
    EXPECT_EQ(b.status, 2) << b.output;
    EXPECT_TRUE(EmptyOrMissing(out));
  }
}

// A 2D setting on a 3D packing is refused, not ignored.
TEST(StabilityLimit3D, PlaneModelIsRefused) {
  const fs::path dir = FreshDirectory("plane3d");
  const Result g = Execute(std::string(SPECIMEN_BINARY_DIR) +
                           "/tools/generate-packing --domain \"box 0 0 0 0.01 0.01 0.01\" --count 200 "
                           "--no-pictures --quiet --output " + dir.string());
  ASSERT_EQ(g.status, 0) << g.output;
  const fs::path out = dir / "out";
  const Result r = StabilityLimit("--packing " + (dir / "packing.packing").string() +
                                  " --kn 1e7 --density 2000 --Ep 1e9 --nu-p 0.2 --plane stress --output " + out.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("2D setting"), std::string::npos) << r.output;
  EXPECT_TRUE(EmptyOrMissing(out));
}

}  // namespace

namespace {

// A particle outside the domain or two at one centre: refused before any analysis (they were
// judged "stable", and run-test diverged on them naming no cause).
TEST(StabilityLimitGeometry, NonsensePackingsAreRefused) {
  const fs::path dir = FreshDirectory("geometry");
  fs::create_directories(dir);
  const char* header = "# specimen-packing 1\ndimension 2\ndomain rectangle 0 0 0.01 0.01\ncreated_by test\nseed 1\n"
                       "contact_tolerance 0.02\nparticles 3\n";
  const struct {
    const char* particles;
    const char* words;
  } cases[] = {{"0.002 0.002 0.001\n0.005 0.002 0.001\n5 0.005 0.001\n", "outside the domain"},
               {"0.002 0.002 0.001\n0.005 0.002 0.001\n0.002 0.002 0.001\n", "the same centre"}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.words);
    const fs::path file = dir / "bad.packing";
    std::ofstream(file) << header << c.particles << "contacts 0\n";
    const Result r = StabilityLimit("--packing " + file.string() + " --kn 1e9 --density 2000 --output " +
                                    (dir / "out").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find(c.words), std::string::npos) << r.output;
    EXPECT_TRUE(EmptyOrMissing(dir / "out"));
  }
}

}  // namespace
