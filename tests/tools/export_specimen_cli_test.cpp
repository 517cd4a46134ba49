// export-specimen as a user runs it: the Yade script and the ESyS-Particle files written (default name next to the
// packing, or --output), the parameters carried; bad input exits 2 and unreadable input 3,
// writing nothing.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/generator/scratch_directory.h"
#include "tests/tools/command_runner.h"

namespace specimen {
namespace {

using testing::RunProgram;

std::string Read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

const char* const kParameters =
    "# calibrated\n[material]\nnormal_stiffness = 1.5e9\ntangential_stiffness = 3e8\n"
    "bond_tensile_strength = 40\nbond_shear_strength = 400\nfriction_coefficient = 0.6\ndensity = 2700\n";

class ExportSpecimenCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r = RunProgram("generate-packing", "--domain \"rectangle 0 0 0.01 0.01\" --count 150 --no-pictures "
                                                  "--threads 1 --output " + scratch_.path() + " --name p");
    ASSERT_EQ(r.status, 0) << r.output;
    std::filesystem::create_directory(scratch_.File("out"));
    WriteText(scratch_.File("params.toml"), kParameters);
  }
  ScratchDirectory scratch_;
};

TEST_F(ExportSpecimenCommand, WritesTheScriptWithTheParameters) {
  const auto r = RunProgram("export-specimen", scratch_.File("p.packing") + " --to yade --parameters " +
                                                   scratch_.File("params.toml"));
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string script = Read(scratch_.File("p_yade.py"));
  EXPECT_NE(script.find("KN = 1500000000  # [N/m]\n"), std::string::npos);
  EXPECT_NE(script.find("MU = 0.59999999999999998\n"), std::string::npos);
  EXPECT_NE(script.find("params.toml"), std::string::npos);
  EXPECT_NE(script.find("BONDS = ["), std::string::npos);
}

TEST_F(ExportSpecimenCommand, WritesTheEsysGeometryAndScript) {
  const auto r = RunProgram("export-specimen", scratch_.File("p.packing") + " --to esys --parameters " +
                                                   scratch_.File("params.toml"));
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string script = Read(scratch_.File("p_esys.py"));
  EXPECT_NE(script.find("KN = 1500000000  # [N/m]\n"), std::string::npos);
  EXPECT_NE(script.find("GEOMETRY = \"p_esys.geo\""), std::string::npos);
  EXPECT_EQ(Read(scratch_.File("p_esys.geo")).rfind("LSMGeometry 1.2\n", 0), 0u);
}

TEST_F(ExportSpecimenCommand, WritesTheLammpsDataAndInput) {
  const auto r = RunProgram("export-specimen", scratch_.File("p.packing") + " --to lammps --disc-thickness 0.01 "
                                                   "--parameters " + scratch_.File("params.toml"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(Read(scratch_.File("p_lammps.in")).find("read_data       p_lammps.data\n"), std::string::npos);
  EXPECT_NE(Read(scratch_.File("p_lammps.data")).find("rho = 2700 kg/m^3"), std::string::npos);
}

TEST_F(ExportSpecimenCommand, BadInputExitsTwoAndUnreadableInputThreeWritingNothing) {
  const std::string packing = scratch_.File("p.packing");
  const std::string out = " --output " + scratch_.File("out/s.py");
  WriteText(scratch_.File("ddem.toml"), std::string(kParameters) + "particle_youngs_modulus = 2e11\n");
  auto expect = [&](const std::string& arguments, int status, const std::string& message) {
    const auto r = RunProgram("export-specimen", arguments + out);
    EXPECT_EQ(r.status, status) << arguments << "\n" << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << arguments << "\n" << r.output;
    EXPECT_TRUE(std::filesystem::is_empty(scratch_.File("out"))) << arguments;
  };
  expect(packing + " --to pfc", 2, "--to = 'pfc' is not allowed: use yade, esys, lammps or liggghts");
  expect(packing + " --to lammps --disc-thickness 0", 2, "--disc-thickness = 0 is not allowed");
  expect(packing + " --to esys --parameters " + scratch_.File("ddem.toml"), 2, "particle_youngs_modulus");
  expect(packing + " --to yade --bond-gap-tolerance 3", 2, "bond_gap_tolerance = 3 is not allowed");
  expect(packing + " --to yade --parameters " + scratch_.File("ddem.toml"), 2, "particle_youngs_modulus");
  WriteText(scratch_.File("typo.toml"), std::string(kParameters) + "normal_stifness = 1\n");
  expect(packing + " --to yade --parameters " + scratch_.File("typo.toml"), 2, "unknown key 'normal_stifness'");
  expect(packing + " --to yade --parameters " + scratch_.File("missing.toml"), 3, "cannot read the parameter file");
  expect(scratch_.File("missing.packing") + " --to yade", 3, "missing.packing");
  expect(packing, 2, "--to");
}

}  // namespace
}  // namespace specimen
