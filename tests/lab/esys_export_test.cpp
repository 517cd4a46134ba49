// The ESyS-Particle export (lab/esys_export.h): what the two files hold (every particle, the
// solver's bonds with their group tags, the constants written exactly, the mass convention),
// the grouping by initial length, what it refuses without leaving a file, and, when
// ESyS-Particle is installed, the specimen in ESyS itself: every bond at rest at step 1 and
// none broken in 1,000 steps without load, in 2D and 3D. Without ESyS those tests are skipped,
// saying so.
#include <gtest/gtest.h>

#include <cstdlib>
#include <sstream>
#include <string>

#include "common/error.h"
#include "lab/esys_export.h"
#include "tests/generator/scratch_directory.h"
#include "tests/lab/bonded_export_fixtures.h"

namespace specimen {
namespace {

MaterialParameters Material() { return ExportTestMaterial(); }

template <int Dim>
Packing<Dim> Generated(const Domain<Dim>& domain, int count) {
  return ExportTestPacking<Dim>(domain, count);
}

EsysExportOptions Options() {
  EsysExportOptions options;
  options.material = Material();
  return options;
}

template <int Dim>
std::string Geometry(const Packing<Dim>& packing, const EsysExportOptions& options) {
  std::ostringstream out;
  WriteEsysGeometry<Dim>(packing, options, out);
  return out.str();
}

template <int Dim>
std::string Script(const Packing<Dim>& packing, const EsysExportOptions& options) {
  std::ostringstream out;
  WriteEsysScript<Dim>(packing, options, out);
  return out.str();
}

TEST(EsysExport, GeometryHoldsEveryParticleAndTheSolversBondsTagged) {
  const Packing<2> packing = Generated<2>(Domain<2>::Rectangle(0, 0, 0.01, 0.01), 200);
  const std::vector<std::array<int, 2>> bonds = ExportedBonds(packing, 0.05);
  std::istringstream in(Geometry(packing, Options()));
  std::string word;
  std::vector<std::string> words;
  while (in >> word) words.push_back(word);
  ASSERT_EQ(words[0], "LSMGeometry");
  EXPECT_EQ(words[14], "2D");
  const size_t particles = std::find(words.begin(), words.end(), "Simple") - words.begin() + 1;
  ASSERT_EQ(std::stoi(words[particles]), packing.size());
  // Particle 5: x y z r id tag, written exactly.
  EXPECT_EQ(std::stod(words[particles + 1 + 6 * 5 + 3]), packing.radii[5]);
  EXPECT_EQ(words[particles + 1 + 6 * 5 + 4], "5");
  const size_t connect = std::find(words.begin(), words.end(), "BeginConnect") - words.begin() + 1;
  ASSERT_EQ(std::stoul(words[connect]), bonds.size());
  // Every bond's tag is its group's, and the group's length is within the width of its d0.
  const std::vector<EsysBondGroup> groups = EsysBondGroups(packing, bonds, 0.01);
  for (const auto& group : groups)
    for (int b : group.bonds) {
      EXPECT_EQ(std::stoi(words[connect + 1 + 3 * b + 2]), group.tag);
      const double d0 = (packing.centres[bonds[b][1]] - packing.centres[bonds[b][0]]).norm();
      EXPECT_LE(std::abs(d0 / group.length_m - 1.0), 0.01 / 2.01 + 1e-15);
    }
}

TEST(EsysExport, ScriptCarriesTheConstantsExactlyAndStatesTheConventions) {
  const Packing<2> packing = Generated<2>(Domain<2>::Rectangle(0, 0, 0.01, 0.01), 200);
  const std::string script = Script(packing, Options());
  EXPECT_NE(script.find("KN = 2000000  # [N/m]\n"), std::string::npos);
  EXPECT_NE(script.find("RT = 50  # [N]\n"), std::string::npos);
  EXPECT_NE(script.find("DIMENSION = 2\n"), std::string::npos);
  EXPECT_NE(script.find("m = rho pi r^2 per\n# metre"), std::string::npos);
  EXPECT_NE(script.find("NRotShortBondPrms"), std::string::npos);
  const std::string without = Script(packing, EsysExportOptions());
  EXPECT_NE(without.find("KN = None"), std::string::npos);
}

TEST(EsysExport, RefusesWhatItCannotCarryAndWritesNothing) {
  const Packing<2> packing = Generated<2>(Domain<2>::Rectangle(0, 0, 0.01, 0.01), 100);
  ScratchDirectory scratch;
  ExpectRigidPairRefusals([&](const MaterialParameters& material) {
    EsysExportOptions options;
    options.material = material;
    options.parameters_source = "p.toml";
    SaveEsysSpecimen<2>(packing, options, scratch.File("s.py"), scratch.File("s.geo"));
  });
  EsysExportOptions options = Options();
  options.tension_group_width = 0.0;
  EXPECT_THROW(SaveEsysSpecimen<2>(packing, options, scratch.File("s.py"), scratch.File("s.geo")), InputError);
  options = Options();
  options.bond_gap_tolerance = -1.0;
  EXPECT_THROW(SaveEsysSpecimen<2>(packing, options, scratch.File("s.py"), scratch.File("s.geo")), InputError);
  EXPECT_TRUE(scratch.Entries().empty());
}

// --- In ESyS-Particle ---

// The launcher: $SPECIMEN_ESYS (e.g. "mpirun -np 2 esysparticle"), else mpirun with
// `esysparticle` when both are on PATH; empty when there is none.
std::string EsysCommand() {
  if (const char* given = std::getenv("SPECIMEN_ESYS")) return given;
  if (std::system("command -v esysparticle > /dev/null 2>&1 && command -v mpirun > /dev/null 2>&1") != 0) return "";
  // Root may run it (containers); two ranks (master and one worker) on any core count.
  return "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe --bind-to none -np 2 "
         "esysparticle";
}

template <int Dim>
void ExpectAtRestInEsys(const Packing<Dim>& packing) {
  const std::string esys = EsysCommand();
  if (esys.empty())
    GTEST_SKIP() << "esysparticle (ESyS-Particle) or mpirun is not installed (nor SPECIMEN_ESYS set): the export "
                    "is not run in ESyS-Particle";
  ScratchDirectory scratch;
  SaveEsysSpecimen<Dim>(packing, Options(), scratch.File("specimen_esys.py"), scratch.File("specimen_esys.geo"));
  ExpectBondsAtRest<Dim>(RunAtRestCheck(esys + " '" + scratch.File("specimen_esys.py") + "' --run at-rest", 1000,
                                        scratch.File("at_rest.json")),
                         packing, 1000);
}

TEST(EsysExportInEsys, BondsStartAtRest2D) {
  ExpectAtRestInEsys<2>(Generated<2>(Domain<2>::Rectangle(0, 0, 0.01, 0.01), 400));
}

TEST(EsysExportInEsys, BondsStartAtRest3D) {
  ExpectAtRestInEsys<3>(Generated<3>(Domain<3>::Cylinder(0, 0, 0.004, 0, 0.008), 600));
}

}  // namespace
}  // namespace specimen
