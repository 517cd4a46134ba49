#include "generator/packing_io.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <set>
#include <sstream>

#include "common/error.h"
#include "tests/generator/scratch_directory.h"

namespace specimen {
namespace {

// Values that a decimal format can get wrong: not exactly representable, the extremes of
// the range, a signed zero, a denormal.
const double kAwkward[] = {0.1,    1.0 / 3.0, 1e-300, -0.0, 2.0 / 3.0 * 1e10,
                           5e-324, -1e300,    0.3,    1e22, std::nextafter(1.0, 2.0)};

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

// Random packing with awkward coordinates and radii mixed in, random distinct contacts
// (i < j, sorted, as Packing documents).
template <int Dim>
Packing<Dim> RandomPacking(const Domain<Dim>& domain, int count, unsigned seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Packing<Dim> packing(domain);
  for (int i = 0; i < count; ++i) {
    Vector<Dim> centre;
    for (int k = 0; k < Dim; ++k)
      centre[k] = i % 3 == 0
                      ? kAwkward[(i + k) % std::size(kAwkward)]
                      : domain.Lower()[k] + unit(random) * (domain.Upper()[k] - domain.Lower()[k]);
    double radius = unit(random) * 0.05 + 1e-3;
    if (i % 4 == 1) radius = std::abs(kAwkward[i % std::size(kAwkward)]);
    if (radius == 0.0) radius = std::numeric_limits<double>::denorm_min();
    packing.centres.push_back(centre);
    packing.radii.push_back(radius);
  }
  std::set<std::array<int, 2>> pairs;
  std::uniform_int_distribution<int> index(0, count - 1);
  for (int c = 0; c < 2 * count; ++c) {
    const int i = index(random), j = index(random);
    if (i != j) pairs.insert({std::min(i, j), std::max(i, j)});
  }
  packing.contacts.assign(pairs.begin(), pairs.end());
  packing.contact_tolerance = 1.0 / 3.0;
  packing.created_by = "specimen 0.1.0+148f915-dirty (test)";
  packing.seed = std::numeric_limits<std::uint64_t>::max();
  return packing;
}

template <int Dim>
void ExpectBitIdentical(const Packing<Dim>& expected, const Packing<Dim>& actual) {
  EXPECT_EQ(expected.domain.shape(), actual.domain.shape());
  EXPECT_EQ(expected.domain.ToText(), actual.domain.ToText());
  EXPECT_EQ(expected.created_by, actual.created_by);
  EXPECT_EQ(expected.seed, actual.seed);
  EXPECT_TRUE(SameBits(expected.contact_tolerance, actual.contact_tolerance));
  ASSERT_EQ(expected.size(), actual.size());
  ASSERT_EQ(actual.centres.size(), actual.radii.size());
  for (int i = 0; i < expected.size(); ++i) {
    for (int k = 0; k < Dim; ++k)
      ASSERT_TRUE(SameBits(expected.centres[i][k], actual.centres[i][k]))
          << "particle " << i << " coordinate " << k << ": " << ExactDouble(expected.centres[i][k])
          << " read back as " << ExactDouble(actual.centres[i][k]);
    ASSERT_TRUE(SameBits(expected.radii[i], actual.radii[i])) << "radius of particle " << i;
  }
  EXPECT_EQ(expected.contacts, actual.contacts);
}

template <int Dim>
std::string WriteToString(const Packing<Dim>& packing) {
  std::ostringstream out;
  WritePacking(packing, out);
  return out.str();
}

template <int Dim>
Packing<Dim> ReadFromString(const std::string& text) {
  std::istringstream in(text);
  return ReadPacking<Dim>(in, "test.packing");
}

std::vector<Domain<2>> Domains2D() {
  return {Domain<2>::Rectangle(0.1, 1.0 / 3.0, 1.1, 2.0),
          Domain<2>::Polygon({Vector<2>(0.0, 0.0), Vector<2>(1.0, -0.0), Vector<2>(1.0, 0.1),
                              Vector<2>(1.0 / 3.0, 0.1), Vector<2>(1.0 / 3.0, 0.7),
                              Vector<2>(0.0, 0.7)}),
          Domain<2>::Disc(Vector<2>(1.0 / 3.0, -0.0), 0.7)};
}

std::vector<Domain<3>> Domains3D() {
  return {Domain<3>::Box(Vector<3>(-0.0, 0.1, 1e-300), Vector<3>(1.0, 4.0 / 3.0, 2.0)),
          Domain<3>::Cylinder(1.0 / 3.0, 0.1, 0.5, -0.0, 1.7)};
}

TEST(PackingIo, RoundTripIsBitExact2D) {
  unsigned seed = 1;
  for (const auto& domain : Domains2D()) {
    const Packing<2> packing = RandomPacking(domain, 200, seed++);
    const std::string text = WriteToString(packing);
    const Packing<2> read = ReadFromString<2>(text);
    ExpectBitIdentical(packing, read);
    // Writing what was read gives the same bytes: nothing drifts over repeated saves.
    EXPECT_EQ(text, WriteToString(read)) << domain.ShapeName();
  }
}

TEST(PackingIo, RoundTripIsBitExact3D) {
  unsigned seed = 11;
  for (const auto& domain : Domains3D()) {
    const Packing<3> packing = RandomPacking(domain, 200, seed++);
    const std::string text = WriteToString(packing);
    const Packing<3> read = ReadFromString<3>(text);
    ExpectBitIdentical(packing, read);
    EXPECT_EQ(text, WriteToString(read)) << domain.ShapeName();
  }
}

TEST(PackingIo, EmptyPackingAndEmptyProvenanceRoundTrip) {
  Packing<2> packing(Domain<2>::Rectangle(0, 0, 1, 1));
  const Packing<2> read = ReadFromString<2>(WriteToString(packing));
  ExpectBitIdentical(packing, read);
}

TEST(PackingIo, SaveAndLoadThroughFiles) {
  ScratchDirectory directory;
  const Packing<3> packing = RandomPacking(Domains3D()[1], 50, 7);
  const std::string path = directory.File("specimen.packing");
  SavePacking(packing, path);
  EXPECT_EQ(directory.Entries(), std::vector<std::string>{"specimen.packing"});
  ExpectBitIdentical(packing, LoadPacking<3>(path));
  EXPECT_EQ(ReadPackingDimension(path), 3);

  const Packing<2> flat = RandomPacking(Domains2D()[0], 20, 8);
  SavePacking(flat, directory.File("flat.packing"));
  EXPECT_EQ(ReadPackingDimension(directory.File("flat.packing")), 2);
}

TEST(PackingIo, ReaderNormalisesContactsToSortedPairs) {
  const std::string text =
      "# specimen-packing 1\ndimension 2\ndomain rectangle 0 0 1 1\ncreated_by hand\nseed 1\n"
      "contact_tolerance 0\nparticles 3\n0.2 0.2 0.1\n0.5 0.2 0.1\n0.8 0.2 0.1\n"
      "contacts 2\n2 1\n1 0\n";
  const Packing<2> packing = ReadFromString<2>(text);
  const std::vector<std::array<int, 2>> expected = {{0, 1}, {1, 2}};
  EXPECT_EQ(packing.contacts, expected);
}

TEST(PackingIo, HeaderKeysInAnyOrderCommentsBlankLinesAndCrlf) {
  const std::string text =
      "# specimen-packing 1\r\n# a comment\r\n\r\nseed 5\r\ncontact_tolerance 0.5\r\n"
      "created_by  hand made  \r\ndomain disc 0 0 1\r\ndimension 2\r\nparticles 1\r\n"
      "  # indented comment\r\n0 0 0.5\r\ncontacts 0\r\n# trailing comment\r\n\r\n";
  const Packing<2> packing = ReadFromString<2>(text);
  EXPECT_EQ(packing.seed, 5u);
  EXPECT_EQ(packing.created_by, "hand made");
  EXPECT_EQ(packing.domain.shape(), DomainShape::kDisc);
  EXPECT_EQ(packing.size(), 1);
  EXPECT_DOUBLE_EQ(packing.radii[0], 0.5);
}

// ---------------------------------------------------------------------------------------
// Malformed files. The base file, line by line:
const std::vector<std::string> kValidLines = {
    "# specimen-packing 1",                  // 1
    "dimension 2",                           // 2
    "domain rectangle 0 0 1 1",              // 3
    "created_by specimen test",              // 4
    "seed 7",                                // 5
    "contact_tolerance 0.01",                // 6
    "# particle centre x y and radius r",    // 7
    "particles 3",                           // 8
    "0.25 0.25 0.1",                         // 9
    "0.75 0.25 0.1",                         // 10
    "0.5 0.75 0.1",                          // 11
    "# contacts: 0-based particle indices",  // 12
    "contacts 2",                            // 13
    "0 1",                                   // 14
    "1 2",                                   // 15
};

std::string Join(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& line : lines) text += line + "\n";
  return text;
}

// The base file with line `number` (1-based) replaced.
std::string WithLine(int number, const std::string& replacement) {
  std::vector<std::string> lines = kValidLines;
  lines.at(number - 1) = replacement;
  return Join(lines);
}

std::string WithoutLine(int number) {
  std::vector<std::string> lines = kValidLines;
  lines.erase(lines.begin() + (number - 1));
  return Join(lines);
}

// Reading `text` as a Dim packing fails with FileError or InputError whose message holds
// every fragment.
template <int Dim = 2>
void ExpectReadError(const std::string& text, const std::vector<std::string>& fragments) {
  std::string message;
  try {
    ReadFromString<Dim>(text);
    ADD_FAILURE() << "no error for:\n" << text;
    return;
  } catch (const FileError& error) {
    message = error.what();
  } catch (const InputError& error) {
    message = error.what();
  }
  EXPECT_NE(message.find("test.packing"), std::string::npos) << message;
  for (const auto& fragment : fragments)
    EXPECT_NE(message.find(fragment), std::string::npos)
        << "message lacks '" << fragment << "': " << message;
}

TEST(PackingIoErrors, TheBaseFileIsValid) {
  const Packing<2> packing = ReadFromString<2>(Join(kValidLines));
  EXPECT_EQ(packing.size(), 3);
  EXPECT_EQ(packing.contacts.size(), 2u);
}

TEST(PackingIoErrors, MagicAndVersion) {
  ExpectReadError("", {"empty", "# specimen-packing 1"});
  ExpectReadError(WithLine(1, "# some other file"), {"line 1", "# specimen-packing 1"});
  ExpectReadError(WithLine(1, "x y r"), {"line 1", "not a specimen packing file"});
  ExpectReadError(WithLine(1, "# specimen-packing 2"),
                  {"line 1", "version '2' is not supported", "version 1"});
  ExpectReadError(WithLine(1, "# specimen-packing"), {"line 1", "version"});
}

TEST(PackingIoErrors, DimensionMismatch) {
  ExpectReadError<3>(Join(kValidLines), {"line 2", "2D packing", "3D packing was expected"});
  const Packing<3> packing = RandomPacking(Domains3D()[0], 10, 3);
  ExpectReadError<2>(WriteToString(packing), {"line 2", "3D packing", "2D packing was expected"});
  ExpectReadError(WithLine(2, "dimension 4"), {"line 2", "dimension must be 2 or 3"});
  ExpectReadError(WithLine(2, "dimension two"), {"line 2", "dimension"});
}

TEST(PackingIoErrors, HeaderKeys) {
  ExpectReadError(WithoutLine(5), {"line 7", "missing 'seed'"});
  ExpectReadError(WithoutLine(3), {"missing 'domain'"});
  ExpectReadError(WithoutLine(4), {"missing 'created_by'"});
  ExpectReadError(WithoutLine(6), {"missing 'contact_tolerance'"});
  ExpectReadError(WithoutLine(2), {"missing 'dimension'"});
  ExpectReadError(WithLine(6, "seed 8"), {"line 6", "'seed' appears twice", "line 5"});
  ExpectReadError(WithLine(6, "colour blue"), {"line 6", "unknown header key 'colour'"});
  ExpectReadError(Join({kValidLines.begin(), kValidLines.begin() + 6}),
                  {"end of file after line 6", "particles <count>"});
}

TEST(PackingIoErrors, HeaderValues) {
  ExpectReadError(WithLine(3, "domain rectangle 0 0 1"), {"line 3", "domain rectangle needs 4"});
  ExpectReadError(WithLine(3, "domain rectangle 0 0 nan 1"), {"line 3", "'nan'"});
  ExpectReadError(WithLine(3, "domain box 0 0 0 1 1 1"), {"line 3", "unknown 2D domain"});
  ExpectReadError(WithLine(3, "domain rectangle 1 0 0 1"), {"line 3"});
  ExpectReadError(WithLine(3, "domain polygon -1"), {"line 3", "vertex count"});
  ExpectReadError(WithLine(3, "domain"), {"line 3", "domain"});
  ExpectReadError(WithLine(5, "seed -1"), {"line 5", "seed"});
  ExpectReadError(WithLine(5, "seed 18446744073709551616"), {"line 5", "seed"});
  ExpectReadError(WithLine(5, "seed 12abc"), {"line 5", "seed"});
  ExpectReadError(WithLine(5, "seed 1 2"), {"line 5", "seed"});
  ExpectReadError(WithLine(6, "contact_tolerance -0.1"), {"line 6", "contact_tolerance"});
  ExpectReadError(WithLine(6, "contact_tolerance inf"), {"line 6", "contact_tolerance"});
  ExpectReadError(WithLine(6, "contact_tolerance"), {"line 6", "contact_tolerance"});
}

TEST(PackingIoErrors, ParticleCountAndLines) {
  ExpectReadError(WithLine(8, "particles 4"),
                  {"line 13", "particle 4 of 4", "fewer particle lines"});
  ExpectReadError(WithLine(8, "particles 2"), {"line 11", "'contacts <count>'", "more particle"});
  ExpectReadError(WithLine(8, "particles"), {"line 8", "particles <count>"});
  ExpectReadError(WithLine(8, "particles -3"), {"line 8", "particle count"});
  ExpectReadError(WithLine(8, "particles 3 4"), {"line 8", "particles <count>"});
  ExpectReadError(WithLine(8, "particles 99999999999"), {"line 8", "particle count"});
  ExpectReadError(WithLine(10, "0.75 0.25"), {"line 10", "particle 2 of 3", "expected 3 numbers"});
  ExpectReadError(WithLine(10, "0.75 0.25 0.1 7"), {"line 10", "expected 3 numbers"});
  ExpectReadError(Join({kValidLines.begin(), kValidLines.begin() + 10}),
                  {"end of file after line 10", "particle 3 of 3"});
}

TEST(PackingIoErrors, ParticleNumbers) {
  ExpectReadError(WithLine(9, "inf 0.25 0.1"), {"line 9", "particle 1 of 3", "'inf' is not a finite decimal number"});
  ExpectReadError(WithLine(9, "0.25 nan 0.1"), {"line 9", "not a finite decimal number"});
  ExpectReadError(WithLine(9, "0.25 1e999 0.1"), {"line 9", "not a finite decimal number"});
  ExpectReadError(WithLine(9, "0.25 0.25 abc"), {"line 9", "'abc' is not a finite decimal number"});
  ExpectReadError(WithLine(9, "0.25 0.25 0.1x"), {"line 9", "is not a finite decimal number"});
  // One number grammar with the options and the domains: no hexadecimal.
  ExpectReadError(WithLine(9, "0x1p-2 0.25 0.1"), {"line 9", "'0x1p-2' is not a finite decimal number"});
  ExpectReadError(WithLine(11, "0.5 0.75 0"), {"line 11", "radius 0 must be > 0"});
  ExpectReadError(WithLine(11, "0.5 0.75 -0.1"), {"line 11", "radius"});
  ExpectReadError(WithLine(11, "0.5 0.75 -0"), {"line 11", "radius"});
}

// What a file can state but no specimen is: refused by CheckPackingGeometry, which the
// commands call (the reader itself round-trips any finite numbers).
TEST(PackingIoErrors, GeometryNoSpecimenHas) {
  auto expect = [](const std::string& text, const std::string& fragment) {
    const Packing<2> packing = ReadFromString<2>(text);
    try {
      CheckPackingGeometry<2>(packing, "test.packing");
      ADD_FAILURE() << "accepted:\n" << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expect(WithLine(11, "5 0.75 0.1"), "particle 3 lies");
  expect(WithLine(11, "0.5 0.75 0.9"), "larger than half the domain");
  expect(WithLine(11, "0.25 0.25 0.1"), "particles 1 and 3 have the same centre");
  EXPECT_NO_THROW(CheckPackingGeometry<2>(ReadFromString<2>(Join(kValidLines)), "test.packing"));
}

TEST(PackingIoErrors, Contacts) {
  ExpectReadError(WithLine(14, "0 3"), {"line 14", "out of range", "3 particles"});
  ExpectReadError(WithLine(14, "-1 2"), {"line 14", "negative"});
  ExpectReadError(WithLine(14, "1 1"), {"line 14", "itself"});
  ExpectReadError(WithLine(14, "0 x"), {"line 14", "contact 1 of 2"});
  ExpectReadError(WithLine(14, "0 1 2"), {"line 14", "two particle indices"});
  ExpectReadError(WithLine(15, "1 0"), {"line 15", "duplicate contact 0 1", "line 14"});
  ExpectReadError(WithLine(13, "contacts 3"), {"end of file after line 15", "contact 3 of 3"});
  ExpectReadError(WithLine(13, "contacts 1"), {"line 15", "after the last contact"});
  ExpectReadError(WithLine(13, "contacts"), {"line 13", "contacts <count>"});
  ExpectReadError(WithLine(13, "bonds 2"), {"line 13", "'contacts <count>'"});
  ExpectReadError(Join({kValidLines.begin(), kValidLines.begin() + 11}),
                  {"end of file after line 11", "contacts <count>"});
}

TEST(PackingIoErrors, TrailingGarbage) {
  std::vector<std::string> lines = kValidLines;
  lines.push_back("# a comment is fine");
  lines.push_back("");
  lines.push_back("hello");
  ExpectReadError(Join(lines), {"line 18", "unexpected content after the last contact"});
}

TEST(PackingIoErrors, LineNumbersCountCommentsAndBlankLines) {
  std::vector<std::string> lines = kValidLines;
  lines.at(10) = "0.5 0.75 -1";  // line 11 of the base file
  lines.insert(lines.begin() + 8, {"# inserted comment", ""});
  ExpectReadError(Join(lines), {"line 13", "radius"});
}

TEST(PackingIoErrors, ReadPackingDimensionAndLoadReportTheFile) {
  ScratchDirectory directory;
  const std::string missing = directory.File("missing.packing");
  EXPECT_THROW(LoadPacking<2>(missing), FileError);
  EXPECT_THROW(ReadPackingDimension(missing), FileError);
  EXPECT_THROW(LoadPacking<2>(directory.path()), FileError);
  const std::string bad = directory.File("bad.packing");
  {
    std::ofstream out(bad);
    out << "not a packing\n";
  }
  try {
    ReadPackingDimension(bad);
    ADD_FAILURE() << "no error";
  } catch (const FileError& error) {
    EXPECT_NE(std::string(error.what()).find(bad), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("line 1"), std::string::npos) << error.what();
  }
  try {
    LoadPacking<2>(missing);
  } catch (const FileError& error) {
    EXPECT_NE(std::string(error.what()).find(missing), std::string::npos) << error.what();
  }
}

// ---------------------------------------------------------------------------------------
// Writing.

TEST(PackingIoWrite, RefusesPackingsThatCouldNotBeReadBack) {
  const Packing<2> valid = RandomPacking(Domains2D()[0], 10, 5);
  std::ostringstream sink;
  {
    Packing<2> packing = valid;
    packing.radii.pop_back();
    EXPECT_THROW(WritePacking(packing, sink), InputError);
  }
  {
    Packing<2> packing = valid;
    packing.radii[3] = 0.0;
    EXPECT_THROW(WritePacking(packing, sink), InputError);
  }
  {
    Packing<2> packing = valid;
    packing.centres[2].x() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(WritePacking(packing, sink), InputError);
  }
  {
    Packing<2> packing = valid;
    packing.contacts.push_back({4, 4});
    EXPECT_THROW(WritePacking(packing, sink), InputError);
  }
  {
    Packing<2> packing = valid;
    packing.contacts.push_back({0, 10});
    EXPECT_THROW(WritePacking(packing, sink), InputError);
  }
  {
    Packing<2> packing = valid;
    packing.contacts = {{0, 1}, {1, 0}};
    EXPECT_THROW(WritePacking(packing, sink), InputError);
  }
  {
    Packing<2> packing = valid;
    packing.contact_tolerance = -1.0;
    EXPECT_THROW(WritePacking(packing, sink), InputError);
  }
  EXPECT_TRUE(sink.str().empty()) << "validation must come before the first byte";
}

TEST(PackingIoWrite, ProvenanceLineBreaksBecomeSpaces) {
  Packing<2> packing = RandomPacking(Domains2D()[2], 5, 2);
  packing.created_by = "line one\nline two\r\n";
  const Packing<2> read = ReadFromString<2>(WriteToString(packing));
  EXPECT_EQ(read.created_by, "line one line two");
}

TEST(PackingIoWrite, SaveToAMissingDirectoryThrowsAndLeavesNothing) {
  ScratchDirectory directory;
  const Packing<2> packing = RandomPacking(Domains2D()[0], 10, 5);
  EXPECT_THROW(SavePacking(packing, directory.File("missing/sub/specimen.packing")), FileError);
  EXPECT_TRUE(directory.Entries().empty());
}

TEST(PackingIoWrite, SaveOfAnInvalidPackingLeavesNoFileAndKeepsTheOldOne) {
  ScratchDirectory directory;
  const std::string path = directory.File("specimen.packing");
  Packing<2> packing = RandomPacking(Domains2D()[0], 10, 5);
  Packing<2> broken = packing;
  broken.radii[0] = -1.0;
  EXPECT_THROW(SavePacking(broken, directory.File("new.packing")), InputError);
  EXPECT_TRUE(directory.Entries().empty());

  SavePacking(packing, path);
  EXPECT_THROW(SavePacking(broken, path), InputError);
  EXPECT_EQ(directory.Entries(), std::vector<std::string>{"specimen.packing"});
  ExpectBitIdentical(packing, LoadPacking<2>(path));
}

TEST(PackingIoWrite, SaveToAReadOnlyDirectoryThrowsAndLeavesNothing) {
  if (geteuid() == 0) {
    GTEST_SKIP() << "root ignores directory permissions; covered by the missing-directory test";
  }
  ScratchDirectory directory;
  const std::string locked = directory.File("locked");
  ASSERT_EQ(mkdir(locked.c_str(), 0500), 0);
  const Packing<2> packing = RandomPacking(Domains2D()[0], 10, 5);
  EXPECT_THROW(SavePacking(packing, locked + "/specimen.packing"), FileError);
  chmod(locked.c_str(), 0700);
  EXPECT_TRUE(std::filesystem::is_empty(locked));
}

}  // namespace
}  // namespace specimen
