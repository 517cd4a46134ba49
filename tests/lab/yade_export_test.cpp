// The Yade export (lab/yade_export.h): what the script holds (every sphere, the solver's bonds,
// the constants written exactly, the 2D mass convention), what it refuses (DDEM, moments,
// unbreakable bonds, a malformed parameter file) without leaving a file, and, when `yade` is
// installed, the script in Yade itself: every bond at rest at step 1 and none broken in
// 1,000 steps without load, in 2D and 3D. Without Yade those two tests are skipped, saying so.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "common/error.h"
#include "lab/lab_scene_file.h"
#include "lab/yade_export.h"
#include "tests/generator/scratch_directory.h"
#include "tests/lab/bonded_export_fixtures.h"

namespace specimen {
namespace {

MaterialParameters Material() { return ExportTestMaterial(); }

template <int Dim>
Packing<Dim> Generated(const Domain<Dim>& domain, int count) {
  return ExportTestPacking<Dim>(domain, count);
}

template <int Dim>
std::string Script(const Packing<Dim>& packing, const YadeExportOptions& options) {
  std::ostringstream out;
  WriteYadeScript<Dim>(packing, options, out);
  return out.str();
}

// Lines between "NAME = [" and "]".
int ListLength(const std::string& script, const std::string& name) {
  std::istringstream in(script.substr(script.find(name + " = [")));
  std::string line;
  std::getline(in, line);
  int count = 0;
  while (std::getline(in, line) && line != "]") ++count;
  return count;
}

TEST(YadeExport, BondsAreTheSolversBondsAndTheConstantsAreExact) {
  // Two discs 1 mm apart, listed as a contact: a bond within 5 % of the mean radius only.
  Packing<2> pair(Domain<2>::Rectangle(0, 0, 0.1, 0.1));
  pair.centres = {Vector<2>(0.02, 0.05), Vector<2>(0.041, 0.05)};
  pair.radii = {0.01, 0.01};
  pair.contacts = {{0, 1}};
  EXPECT_TRUE(ExportedBonds(pair, 0.05).empty());  // gap 1e-3 > 0.05 x 0.01
  EXPECT_EQ(ExportedBonds(pair, 0.2).size(), 1u);  // 1e-3 <= 0.2 x 0.01

  const Packing<2> packing = Generated<2>(Domain<2>::Rectangle(0, 0, 0.01, 0.01), 200);
  YadeExportOptions options;
  options.material = Material();
  const std::string script = Script(packing, options);
  EXPECT_EQ(ListLength(script, "SPHERES"), packing.size());
  EXPECT_EQ(ListLength(script, "BONDS"), static_cast<int>(ExportedBonds(packing, 0.05).size()));
  EXPECT_NE(script.find("KN = 2000000  # [N/m]\n"), std::string::npos);
  EXPECT_NE(script.find("RT = 50  # [N]\n"), std::string::npos);
  EXPECT_NE(script.find("DIMENSION = 2\n"), std::string::npos);
  // The 2D mass convention is stated in the header.
  EXPECT_NE(script.find("m = rho pi r^2 l"), std::string::npos);
  EXPECT_NE(script.find("UCS_AXIS = 1"), std::string::npos);
}

TEST(YadeExport, WithoutParametersTheConstantsAreLeftToSet) {
  const Packing<2> packing = Generated<2>(Domain<2>::Rectangle(0, 0, 0.01, 0.01), 100);
  const std::string script = Script(packing, YadeExportOptions());
  EXPECT_NE(script.find("KN = None"), std::string::npos);
  EXPECT_NE(script.find("DENSITY = None"), std::string::npos);
}

TEST(YadeExport, AnotherShapeHasNoPlatensAndSaysWhy) {
  const Packing<2> disc = Generated<2>(Domain<2>::Disc(Vector<2>(0, 0), 0.005), 100);
  YadeExportOptions options;
  options.material = Material();
  const std::string script = Script(disc, options);
  EXPECT_NE(script.find("UCS_AXIS = None"), std::string::npos);
  EXPECT_NE(script.find("UCS_REFUSAL = \""), std::string::npos);
}

TEST(YadeExport, RefusesWhatYadesLawCannotCarryAndWritesNothing) {
  const Packing<2> packing = Generated<2>(Domain<2>::Rectangle(0, 0, 0.01, 0.01), 100);
  ScratchDirectory scratch;
  ExpectRigidPairRefusals([&](const MaterialParameters& material) {
    YadeExportOptions options;
    options.material = material;
    options.parameters_source = "p.toml";
    SaveYadeScript<2>(packing, options, scratch.File("s.py"));
  });
  YadeExportOptions options;
  options.bond_gap_tolerance = 2.0;
  EXPECT_THROW(SaveYadeScript<2>(packing, options, scratch.File("s.py")), InputError);
  EXPECT_TRUE(scratch.Entries().empty());
}

TEST(YadeExport, ParameterFileIsAMaterialTable) {
  const MaterialParameters m = ParseMaterialFile(
      "[material]\nnormal_stiffness = 1e9\ntangential_stiffness = 2e8\nbond_tensile_strength = 10\n"
      "bond_shear_strength = 20\nfriction_coefficient = 0.5\ndensity = 2650\n",
      "p.toml");
  EXPECT_EQ(m.normal_stiffness_n_per_m, 1e9);
  EXPECT_EQ(m.bond_shear_strength_n, 20.0);
  EXPECT_THROW(ParseMaterialFile("[material]\nnormal_stiffness = 1e9\ndensity = 1\n[test]\nkind = \"ucs\"\n", "p"),
               InputError);
  EXPECT_THROW(ParseMaterialFile("[material]\nnormal_stiffness = 1e9\n", "p"), InputError);  // no density
  EXPECT_THROW(ParseMaterialFile("[material]\nmodel = \"lattice\"\nyoungs_modulus = 1e9\npoisson_ratio = 0.2\n"
                                 "tensile_strength = 1e6\ncohesion = 1e6\nfriction_angle = 30\ndensity = 1\n",
                                 "p"),
               InputError);
  EXPECT_THROW(ParseMaterialFile("[material\n", "p"), InputError);
  EXPECT_THROW(LoadMaterialFile("/nonexistent/p.toml"), FileError);
}

// --- In Yade ---

// The yade command: $SPECIMEN_YADE, else `yade` on PATH; empty when there is none.
std::string YadeCommand() {
  if (const char* given = std::getenv("SPECIMEN_YADE")) return given;
  return std::system("command -v yade > /dev/null 2>&1") == 0 ? "yade" : "";
}

template <int Dim>
void ExpectAtRestInYade(const Packing<Dim>& packing) {
  const std::string yade = YadeCommand();
  if (yade.empty()) GTEST_SKIP() << "yade is not installed (nor SPECIMEN_YADE set): the export is not run in Yade";
  ScratchDirectory scratch;
  YadeExportOptions options;
  options.material = Material();
  SaveYadeScript<Dim>(packing, options, scratch.File("specimen_yade.py"));
  ExpectBondsAtRest<Dim>(
      RunAtRestCheck(yade + " -x -n '" + scratch.File("specimen_yade.py") + "' --run at-rest", 1000,
                     scratch.File("at_rest.json")),
      packing, 1000);
}

TEST(YadeExportInYade, BondsStartAtRest2D) {
  ExpectAtRestInYade<2>(Generated<2>(Domain<2>::Rectangle(0, 0, 0.01, 0.01), 400));
}

TEST(YadeExportInYade, BondsStartAtRest3D) {
  ExpectAtRestInYade<3>(Generated<3>(Domain<3>::Cylinder(0, 0, 0.004, 0, 0.008), 600));
}

}  // namespace
}  // namespace specimen
