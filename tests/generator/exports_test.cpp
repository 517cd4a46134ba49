#include "generator/exports.h"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "common/error.h"
#include "tests/generator/scratch_directory.h"

namespace specimen {
namespace {

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

// Small packings with values a short decimal format would round (1/3, 0.1, 1e-7).
Packing<2> SmallPacking2D() {
  Packing<2> packing(Domain<2>::Rectangle(0.0, 0.0, 1.0, 0.5));
  const double radii[] = {1.0 / 3.0 * 0.3, 0.1, 0.12, 0.05 + 1e-7, 0.08};
  const Vector<2> centres[] = {Vector<2>(0.1, 0.1), Vector<2>(0.3, 0.1), Vector<2>(0.5, 0.12),
                               Vector<2>(0.7, 0.3), Vector<2>(0.95, 0.45)};  // last one protrudes
  for (int i = 0; i < 5; ++i) {
    packing.centres.push_back(centres[i]);
    packing.radii.push_back(radii[i]);
  }
  packing.contacts = {{0, 1}, {1, 2}, {2, 3}, {3, 4}};
  packing.created_by = "exports test -- 2D";
  return packing;
}

Packing<3> SmallPacking3D() {
  Packing<3> packing(Domain<3>::Box(Vector<3>(0, 0, 0), Vector<3>(1, 1, 1)));
  for (int i = 0; i < 8; ++i) {
    packing.centres.push_back(Vector<3>(0.25 + 0.5 * (i & 1), 0.25 + 0.5 * ((i >> 1) & 1),
                                        0.25 + 0.5 * ((i >> 2) & 1) + 1.0 / 3.0 * 1e-3));
    packing.radii.push_back(0.25 - 1e-3 * i / 3.0);
  }
  for (int i = 0; i < 8; ++i)
    for (int bit = 0; bit < 3; ++bit)
      if ((i & (1 << bit)) == 0) packing.contacts.push_back({i, i | (1 << bit)});
  packing.created_by = "exports test 3D";
  return packing;
}

std::string ReadWholeFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

std::vector<std::string> Words(const std::string& line) {
  std::vector<std::string> words;
  std::istringstream in(line);
  std::string word;
  while (in >> word) words.push_back(word);
  return words;
}

double Number(const std::string& word) {
  char* end = nullptr;
  const double value = std::strtod(word.c_str(), &end);
  EXPECT_EQ(*end, '\0') << "not a number: " << word;
  return value;
}

// ---------------------------------------------------------------------------------------
// VTU, read back by VTK itself.

// A Python that can import vtk: $SPECIMEN_PYTHON, else python3 on PATH, else Debian's
// /usr/bin/python3 (python3-vtk9 installs for the system interpreter; a pyenv or venv
// python3 earlier on PATH does not see it). Empty if none can.
std::string PythonWithVtk() {
  std::vector<std::string> candidates;
  if (const char* configured = std::getenv("SPECIMEN_PYTHON")) candidates.push_back(configured);
  candidates.push_back("python3");
  candidates.push_back("/usr/bin/python3");
  for (const auto& python : candidates)
    if (std::system((python + " -c 'import vtk' >/dev/null 2>&1").c_str()) == 0) return python;
  return "";
}

// Runs check_vtu.py; returns its exit status (-1 if it could not run). `quiet` hides the
// messages of checks that are meant to fail.
int CheckVtu(const std::string& python, const std::string& file, int points, int lines,
             double first_radius, bool quiet = false) {
  const std::string command = python + " '" SPECIMEN_SOURCE_DIR "/tests/generator/check_vtu.py' '" +
                              file + "' " + std::to_string(points) + " " + std::to_string(lines) +
                              " " + ExactDouble(first_radius) + (quiet ? " 2>/dev/null" : "");
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Exports, VtuIsReadByVtk) {
  const std::string python = PythonWithVtk();
  ASSERT_FALSE(python.empty())
      << "python3 cannot import vtk, so the VTU export cannot be checked against VTK's own "
         "reader: install python3-vtk9 (apt-get install python3-vtk9), or set "
         "SPECIMEN_PYTHON to a Python that has the vtk module";
  ScratchDirectory directory;

  const Packing<2> flat = SmallPacking2D();
  const std::string flat_path = directory.File("flat.vtu");
  SaveVtu(flat, flat_path);
  EXPECT_EQ(CheckVtu(python, flat_path, flat.size(), 4, flat.radii[0]), 0);
  // The checker is not vacuous: wrong expectations fail.
  EXPECT_NE(CheckVtu(python, flat_path, flat.size() + 1, 4, flat.radii[0], true), 0);
  EXPECT_NE(CheckVtu(python, flat_path, flat.size(), 3, flat.radii[0], true), 0);
  EXPECT_NE(CheckVtu(python, flat_path, flat.size(), 4, std::nextafter(flat.radii[0], 1.0), true),
            0);

  const Packing<3> solid = SmallPacking3D();
  const std::string solid_path = directory.File("solid.vtu");
  SaveVtu(solid, solid_path);
  EXPECT_EQ(CheckVtu(python, solid_path, solid.size(), 12, solid.radii[0]), 0);

  Packing<3> empty(Domain<3>::Box(Vector<3>(0, 0, 0), Vector<3>(1, 1, 1)));
  SaveVtu(empty, directory.File("empty.vtu"));
  EXPECT_EQ(CheckVtu(python, directory.File("empty.vtu"), 0, 0, 1.0), 0);
}

TEST(Exports, VtuHoldsFullPrecisionAndZeroZIn2D) {
  const Packing<2> flat = SmallPacking2D();
  std::ostringstream out;
  WriteVtu(flat, out);
  const std::string text = out.str();
  EXPECT_NE(text.find(ExactDouble(flat.radii[0])), std::string::npos);
  EXPECT_NE(text.find(ExactDouble(flat.radii[3])), std::string::npos);
  EXPECT_NE(text.find("0.10000000000000001 0.10000000000000001 0\n"), std::string::npos);
  // The provenance comment cannot break the XML ("--" is not allowed in a comment).
  const size_t comment = text.find("<!--");
  ASSERT_NE(comment, std::string::npos);
  EXPECT_EQ(text.find("--", comment + 4), text.find("-->", comment + 4));
}

TEST(Exports, RefuseInconsistentPackings) {
  Packing<2> packing = SmallPacking2D();
  packing.contacts.push_back({0, 5});
  std::ostringstream out;
  EXPECT_THROW(WriteVtu(packing, out), InputError);
  packing = SmallPacking2D();
  packing.radii.pop_back();
  EXPECT_THROW(WriteYadeSphereList(packing, out), InputError);
  EXPECT_THROW(WriteLiggghtsData(packing, out), InputError);
  EXPECT_THROW(WriteLiggghtsData(SmallPacking2D(), out, 0.0), InputError);
  EXPECT_THROW(WriteLiggghtsData(SmallPacking2D(), out, std::nan("")), InputError);
}

TEST(Exports, SaveToAMissingDirectoryThrowsAndLeavesNothing) {
  ScratchDirectory directory;
  EXPECT_THROW(SaveVtu(SmallPacking2D(), directory.File("missing/a.vtu")), FileError);
  EXPECT_THROW(SaveYadeSphereList(SmallPacking2D(), directory.File("missing/a.txt")), FileError);
  EXPECT_THROW(SaveLiggghtsData(SmallPacking2D(), directory.File("missing/a.data")), FileError);
  EXPECT_TRUE(directory.Entries().empty());
}

// ---------------------------------------------------------------------------------------
// Yade: parsed the way yade.ymport.textExt does (split each line; a first word "#format"
// sets the format; other lines whose first word starts with '#' are skipped; a blank line
// would make it fail on data[0]).

template <int Dim>
void ExpectYadeListMatches(const Packing<Dim>& packing, const std::string& text) {
  std::string format = "x_y_z_r";
  int sphere = 0;
  for (const auto& line : Lines(text)) {
    const std::vector<std::string> data = Words(line);
    ASSERT_FALSE(data.empty()) << "a blank line makes ymport.textExt fail";
    if (data[0] == "#format") {
      ASSERT_GE(data.size(), 2u);
      format = data[1];
      continue;
    }
    if (data[0][0] == '#') continue;
    ASSERT_EQ(format, "x_y_z_r");
    ASSERT_EQ(data.size(), 4u) << line;
    ASSERT_LT(sphere, packing.size());
    for (int k = 0; k < 3; ++k) {
      const double expected = k < Dim ? packing.centres[sphere][k] : 0.0;
      EXPECT_TRUE(SameBits(Number(data[k]), expected)) << line;
    }
    EXPECT_TRUE(SameBits(Number(data[3]), packing.radii[sphere])) << line;
    ++sphere;
  }
  EXPECT_EQ(sphere, packing.size());
}

TEST(Exports, YadeSphereListParsesBack) {
  ScratchDirectory directory;
  const Packing<2> flat = SmallPacking2D();
  SaveYadeSphereList(flat, directory.File("flat.txt"));
  ExpectYadeListMatches(flat, ReadWholeFile(directory.File("flat.txt")));
  const Packing<3> solid = SmallPacking3D();
  SaveYadeSphereList(solid, directory.File("solid.txt"));
  ExpectYadeListMatches(solid, ReadWholeFile(directory.File("solid.txt")));
  EXPECT_EQ(Lines(ReadWholeFile(directory.File("solid.txt"))).front(), "#format x_y_z_r");
}

// ---------------------------------------------------------------------------------------
// LIGGGHTS: parsed the way read_data does (first line skipped; header lines with '#'
// comments stripped, recognised by keyword; the section keyword "Atoms"; the line after
// it is skipped; then one line per atom).

struct LiggghtsData {
  long long atoms = -1;
  int atom_types = -1;
  double lower[3] = {0, 0, 0};
  double upper[3] = {0, 0, 0};
  std::vector<std::vector<std::string>> atom_lines;
};

LiggghtsData ParseLiggghts(const std::string& text) {
  LiggghtsData data;
  const std::vector<std::string> lines = Lines(text);
  size_t next = 1;  // line 0 is the title, skipped
  std::string keyword;
  for (; next < lines.size(); ++next) {
    EXPECT_LT(lines[next].size(), 255u) << "read_data reads lines into 256 characters";
    std::string line = lines[next].substr(0, lines[next].find('#'));
    if (Words(line).empty()) continue;
    if (line.find("atoms") != std::string::npos)
      data.atoms = std::stoll(line);
    else if (line.find("atom types") != std::string::npos)
      data.atom_types = std::stoi(line);
    else if (line.find("xlo xhi") != std::string::npos)
      std::sscanf(line.c_str(), "%lg %lg", &data.lower[0], &data.upper[0]);
    else if (line.find("ylo yhi") != std::string::npos)
      std::sscanf(line.c_str(), "%lg %lg", &data.lower[1], &data.upper[1]);
    else if (line.find("zlo zhi") != std::string::npos)
      std::sscanf(line.c_str(), "%lg %lg", &data.lower[2], &data.upper[2]);
    else {
      keyword = Words(line).size() == 1 ? Words(line)[0] : line;
      break;
    }
  }
  EXPECT_EQ(keyword, "Atoms");
  EXPECT_LT(next + 1, lines.size());
  EXPECT_TRUE(Words(lines[next + 1]).empty()) << "read_data skips the line after 'Atoms'";
  for (size_t k = next + 2; k < lines.size(); ++k) {
    EXPECT_LT(lines[k].size(), 255u);
    data.atom_lines.push_back(Words(lines[k]));
  }
  return data;
}

template <int Dim>
void ExpectLiggghtsMatches(const Packing<Dim>& packing, const std::string& text, double density) {
  const LiggghtsData data = ParseLiggghts(text);
  EXPECT_EQ(data.atoms, packing.size());
  EXPECT_EQ(data.atom_types, 1);
  ASSERT_EQ(static_cast<int>(data.atom_lines.size()), packing.size());
  double largest_radius = 0.0;
  for (int i = 0; i < packing.size(); ++i) {
    const auto& words = data.atom_lines[i];
    ASSERT_EQ(words.size(), 7u) << "atom_style sphere: id type diameter density x y z";
    EXPECT_EQ(words[0], std::to_string(i + 1));
    EXPECT_EQ(words[1], "1");
    EXPECT_TRUE(SameBits(Number(words[2]), 2.0 * packing.radii[i]));
    EXPECT_TRUE(SameBits(Number(words[3]), density));
    for (int k = 0; k < 3; ++k) {
      const double x = Number(words[4 + k]);
      EXPECT_TRUE(SameBits(x, k < Dim ? packing.centres[i][k] : 0.0));
      // read_data drops atoms outside a non-periodic box: every sphere must be inside.
      const double r = k < Dim ? packing.radii[i] : 0.0;
      EXPECT_LE(data.lower[k], x - r) << "atom " << i + 1 << " axis " << k;
      EXPECT_GE(data.upper[k], x + r) << "atom " << i + 1 << " axis " << k;
    }
    largest_radius = std::max(largest_radius, packing.radii[i]);
  }
  for (int k = 0; k < Dim; ++k) {
    EXPECT_LE(data.lower[k], packing.domain.Lower()[k]);
    EXPECT_GE(data.upper[k], packing.domain.Upper()[k]);
  }
  if (Dim == 2) {
    EXPECT_EQ(data.lower[2], -largest_radius);
    EXPECT_EQ(data.upper[2], largest_radius);
  }
}

TEST(Exports, LiggghtsDataParsesBack) {
  ScratchDirectory directory;
  const Packing<2> flat = SmallPacking2D();
  SaveLiggghtsData(flat, directory.File("flat.data"));
  ExpectLiggghtsMatches(flat, ReadWholeFile(directory.File("flat.data")), 2650.0);
  // The protruding last disc grows the box beyond the domain.
  const LiggghtsData data = ParseLiggghts(ReadWholeFile(directory.File("flat.data")));
  EXPECT_DOUBLE_EQ(data.upper[0], 0.95 + 0.08);

  const Packing<3> solid = SmallPacking3D();
  SaveLiggghtsData(solid, directory.File("solid.data"), 1000.0 / 3.0);
  ExpectLiggghtsMatches(solid, ReadWholeFile(directory.File("solid.data")), 1000.0 / 3.0);
}

TEST(Exports, LiggghtsTitleLineStaysShort) {
  Packing<2> packing = SmallPacking2D();
  packing.created_by = std::string(1000, 'x') + "\natoms";
  std::ostringstream out;
  WriteLiggghtsData(packing, out);
  const std::vector<std::string> lines = Lines(out.str());
  EXPECT_LT(lines.front().size(), 255u);
  ExpectLiggghtsMatches(packing, out.str(), 2650.0);
}

}  // namespace
}  // namespace specimen
