// The LAMMPS and LIGGGHTS exports (generator/exports.h, WriteGranularData and
// WriteGranularInput): the density column that gives this toolkit's masses in each code, the
// dimension lines of the input, and, when `lmp` or `liggghts` is installed, the files loaded in
// the real program: every atom's mass as the code computes it equals this toolkit's, rho pi r^2 t
// for 2D discs of thickness t and 4/3 pi r^3 rho for spheres. Without the program the check is
// skipped, saying so.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "common/error.h"
#include "generator/exports.h"
#include "generator/generate.h"
#include "tests/generator/scratch_directory.h"

namespace specimen {
namespace {

constexpr double kDensity = 2650.0;
constexpr double kThickness = 0.01;

template <int Dim>
Packing<Dim> Generated(const Domain<Dim>& domain, int count) {
  GeneratorOptions options = DefaultGeneratorOptions<Dim>();
  options.particle_count = count;
  options.seed = 5;
  options.num_threads = 1;
  return GeneratePacking<Dim>(domain, options, nullptr);
}

// This toolkit's mass of particle i: a disc of thickness kThickness in 2D, a sphere in 3D.
template <int Dim>
double ToolkitMass(const Packing<Dim>& packing, int i) {
  const double r = packing.radii[i];
  return Dim == 2 ? kDensity * M_PI * r * r * kThickness : kDensity * 4.0 / 3.0 * M_PI * r * r * r;
}

TEST(GranularCodes, DensityColumnGivesTheToolkitsMassUnderEachCodesRule) {
  const double r = 2e-4;
  // LIGGGHTS 2D: m = pi r^2 x column; LAMMPS: m = 4/3 pi r^3 x column.
  EXPECT_DOUBLE_EQ(M_PI * r * r * GranularDensityColumn(GranularCode::kLiggghts, 2, kDensity, kThickness, r),
                   kDensity * M_PI * r * r * kThickness);
  EXPECT_DOUBLE_EQ(4.0 / 3.0 * M_PI * r * r * r * GranularDensityColumn(GranularCode::kLammps, 2, kDensity, kThickness, r),
                   kDensity * M_PI * r * r * kThickness);
  EXPECT_EQ(GranularDensityColumn(GranularCode::kLammps, 3, kDensity, kThickness, r), kDensity);
}

TEST(GranularCodes, InputWritesTheDimensionLinesAndTheDataStatesItsConvention) {
  const Packing<2> packing = Generated<2>(Domain<2>::Rectangle(0, 0, 0.004, 0.004), 60);
  std::ostringstream input, data;
  WriteGranularInput(packing, input, GranularCode::kLammps, "p.data");
  EXPECT_NE(input.str().find("dimension       2\n"), std::string::npos);
  EXPECT_NE(input.str().find("boundary        f f p\n"), std::string::npos);
  EXPECT_NE(input.str().find("enforce2d"), std::string::npos);
  EXPECT_LT(input.str().find("dimension       2"), input.str().find("read_data       "));
  WriteGranularData(packing, data, GranularCode::kLammps, kDensity, kThickness);
  EXPECT_NE(data.str().find("# 2D masses: discs of thickness t = 0.01 m"), std::string::npos);
  EXPECT_THROW(WriteGranularData(packing, data, GranularCode::kLammps, kDensity, 0.0), InputError);
}

// The program: $SPECIMEN_<NAME>, else `command` on PATH; empty when there is none.
std::string Program(const char* variable, const std::string& command) {
  if (const char* given = std::getenv(variable)) return given;
  return std::system(("command -v " + command + " > /dev/null 2>&1").c_str()) == 0 ? command : "";
}

// Loads the exported files in the program, dumps every atom's mass, and compares it with
// this toolkit's.
template <int Dim>
void ExpectToolkitMassesIn(GranularCode code, const Packing<Dim>& packing) {
  const bool lammps = code == GranularCode::kLammps;
  const std::string program = lammps ? Program("SPECIMEN_LAMMPS", "lmp") : Program("SPECIMEN_LIGGGHTS", "liggghts");
  if (program.empty())
    GTEST_SKIP() << (lammps ? "lmp (LAMMPS)" : "liggghts") << " is not installed: the masses are not checked in it";
  ScratchDirectory scratch;
  SaveGranularSpecimen<Dim>(packing, code, kDensity, kThickness, scratch.File("p.in"), scratch.File("p.data"));
  {
    std::ofstream input(scratch.File("p.in"), std::ios::app);
    input << "dump masses all custom 1 masses.dump id radius mass\n"
          << (lammps ? "dump_modify masses format line \"%d %.17g %.17g\"\n"
                     : "dump_modify masses format \"%d %.17g %.17g\"\n")
          << "run 0\n";
  }
  const std::string command = "cd '" + scratch.path() + "' && " + program + " -in p.in -log none > run.log 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  std::ifstream dump(scratch.File("masses.dump"));
  std::string line;
  while (std::getline(dump, line) && line.rfind("ITEM: ATOMS", 0) != 0) {
  }
  int atoms = 0;
  double worst = 0.0;
  for (int id; dump >> id;) {
    double radius, mass;
    dump >> radius >> mass;
    ASSERT_EQ(radius, packing.radii[id - 1]);
    worst = std::max(worst, std::abs(mass / ToolkitMass(packing, id - 1) - 1.0));
    ++atoms;
  }
  EXPECT_EQ(atoms, packing.size());
  EXPECT_LT(worst, 1e-12);
}

TEST(GranularCodesInPrograms, LammpsGetsTheToolkitsMasses) {
  ExpectToolkitMassesIn<2>(GranularCode::kLammps, Generated<2>(Domain<2>::Rectangle(0, 0, 0.004, 0.004), 60));
  ExpectToolkitMassesIn<3>(GranularCode::kLammps, Generated<3>(Domain<3>::Box(Vector<3>(0, 0, 0), Vector<3>(0.004, 0.004, 0.004)), 60));
}

TEST(GranularCodesInPrograms, LiggghtsGetsTheToolkitsMasses) {
  ExpectToolkitMassesIn<2>(GranularCode::kLiggghts, Generated<2>(Domain<2>::Rectangle(0, 0, 0.004, 0.004), 60));
  ExpectToolkitMassesIn<3>(GranularCode::kLiggghts, Generated<3>(Domain<3>::Box(Vector<3>(0, 0, 0), Vector<3>(0.004, 0.004, 0.004)), 60));
}

}  // namespace
}  // namespace specimen
