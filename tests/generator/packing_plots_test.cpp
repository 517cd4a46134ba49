#include "generator/packing_plots.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>

#include "common/error.h"
#include "tests/generator/scratch_directory.h"

namespace specimen {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Discs on a jittered square grid filling `domain`'s bounding box, contacts between grid
// neighbours: a stand-in for a generated packing.
Packing<2> GridPacking(const Domain<2>& domain, int columns, int rows, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Packing<2> packing(domain);
  const Vector<2> lower = domain.Lower(), upper = domain.Upper();
  const double spacing =
      std::min((upper.x() - lower.x()) / columns, (upper.y() - lower.y()) / rows);
  for (int row = 0; row < rows; ++row)
    for (int column = 0; column < columns; ++column) {
      packing.centres.push_back(lower +
                                Vector<2>((column + 0.5) * spacing + 0.05 * spacing * unit(random),
                                          (row + 0.5) * spacing + 0.05 * spacing * unit(random)));
      packing.radii.push_back(spacing * (0.3 + 0.2 * unit(random)));
      const int i = packing.size() - 1;
      if (column > 0) packing.contacts.push_back({i - 1, i});
      if (row > 0) packing.contacts.push_back({i - columns, i});
    }
  std::sort(packing.contacts.begin(), packing.contacts.end());
  return packing;
}

// Metrics filled by hand (ComputePackingMetrics is not what is under test): the fields the
// pictures read, and an anisotropic orientation histogram.
template <int Dim>
PackingMetrics<Dim> HandMadeMetrics(const Packing<Dim>& packing, int bins) {
  PackingMetrics<Dim> metrics;
  metrics.particle_count = packing.size();
  metrics.contact_count = static_cast<int>(packing.contacts.size());
  if (packing.size() > 0) {
    metrics.min_radius = *std::min_element(packing.radii.begin(), packing.radii.end());
    metrics.max_radius = *std::max_element(packing.radii.begin(), packing.radii.end());
    metrics.radius_ratio = metrics.max_radius / metrics.min_radius;
    metrics.mean_radius = VolumeMeanRadius<Dim>(packing.radii);
  }
  const int rows = Dim == 2 ? 1 : 3;
  for (int row = 0; row < rows; ++row) {
    std::vector<double> histogram;
    for (int k = 0; k < bins; ++k) {
      const double angle = (k + 0.5) * kPi / bins;
      histogram.push_back(10.0 + (3.0 + row) * std::cos(2.0 * angle + row));
    }
    metrics.orientation_histograms.push_back(histogram);
  }
  return metrics;
}

std::vector<std::string> CsvRows(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> rows;
  std::string line;
  while (std::getline(in, line)) rows.push_back(line);
  return rows;
}

std::vector<double> CsvNumbers(const std::string& row) {
  std::vector<double> numbers;
  std::stringstream in(row);
  std::string cell;
  while (std::getline(in, cell, ',')) numbers.push_back(std::strtod(cell.c_str(), nullptr));
  return numbers;
}

void ExpectPng(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  ASSERT_TRUE(in) << path << " is missing";
  char signature[8] = {};
  in.read(signature, 8);
  const char expected[8] = {'\x89', 'P', 'N', 'G', '\r', '\n', '\x1a', '\n'};
  EXPECT_TRUE(std::equal(signature, signature + 8, expected)) << path << " is not a PNG";
  in.seekg(0, std::ios::end);
  EXPECT_GT(in.tellg(), 1000) << path << " is suspiciously small";
}

bool Contains(const std::vector<std::string>& list, const std::string& item) {
  return std::find(list.begin(), list.end(), item) != list.end();
}

std::string JoinWarnings(const PicturesWritten& written) {
  std::string text;
  for (const auto& warning : written.warnings) text += warning + "\n";
  return text;
}

TEST(PackingPictures, TwoDimensionalPackingWritesEveryFile) {
  ScratchDirectory directory;
  const Packing<2> packing = GridPacking(Domain<2>::Rectangle(0, 0, 0.2, 0.1), 20, 10, 1);
  const PackingMetrics<2> metrics = HandMadeMetrics(packing, 36);
  const std::string prefix = directory.File("run");
  const PicturesWritten written = WritePackingPictures(packing, metrics, prefix);
  EXPECT_TRUE(written.warnings.empty()) << JoinWarnings(written);

  for (const char* name : {"_radii.csv", "_orientation.csv", "_particles.csv", "_contacts.csv",
                           "_packing.png", "_radius_histogram.png", "_orientation_rose.png"})
    EXPECT_TRUE(Contains(written.files, prefix + name)) << name;
  EXPECT_EQ(directory.Entries().size(), written.files.size()) << "no temporary files left";
  for (const char* name : {"_packing.png", "_radius_histogram.png", "_orientation_rose.png"})
    ExpectPng(prefix + name);

  // Radius histogram: automatic bins (ceil(sqrt(200)) = 15), every particle counted once,
  // volume fractions summing to 1.
  const auto radii = CsvRows(prefix + "_radii.csv");
  ASSERT_EQ(radii.size(), 16u);
  EXPECT_EQ(radii[0], "bin_low_m,bin_high_m,count,volume_fraction");
  double count = 0.0, fraction = 0.0;
  for (size_t row = 1; row < radii.size(); ++row) {
    const auto numbers = CsvNumbers(radii[row]);
    ASSERT_EQ(numbers.size(), 4u);
    EXPECT_LT(numbers[0], numbers[1]);
    count += numbers[2];
    fraction += numbers[3];
  }
  EXPECT_EQ(count, packing.size());
  EXPECT_NEAR(fraction, 1.0, 1e-12);

  // Orientation: 36 bins over [0, 180) and their mirror over [180, 360).
  const auto orientation = CsvRows(prefix + "_orientation.csv");
  ASSERT_EQ(orientation.size(), 73u);
  EXPECT_EQ(orientation[0],
            "bin_low_deg,bin_high_deg,bin_centre_deg,mirrored,xy_weight,xy_relative_to_isotropic");
  const auto first = CsvNumbers(orientation[1]);
  const auto mirror = CsvNumbers(orientation[37]);
  EXPECT_EQ(first[0], 0.0);
  EXPECT_EQ(first[3], 0.0);
  EXPECT_EQ(mirror[0], 180.0);
  EXPECT_EQ(mirror[3], 1.0);
  EXPECT_EQ(first[4], mirror[4]);
  EXPECT_DOUBLE_EQ(first[4], metrics.orientation_histograms[0][0]);
  EXPECT_DOUBLE_EQ(CsvNumbers(orientation[72])[1], 360.0);
  double relative_sum = 0.0;
  for (size_t row = 1; row <= 36; ++row) relative_sum += CsvNumbers(orientation[row])[5];
  EXPECT_NEAR(relative_sum, 36.0, 1e-9) << "relative weights average 1";

  const auto particles = CsvRows(prefix + "_particles.csv");
  ASSERT_EQ(particles.size(), static_cast<size_t>(packing.size()) + 1);
  EXPECT_EQ(particles[0], "x_m,y_m,radius_m");
  EXPECT_EQ(CsvNumbers(particles[1])[2], packing.radii[0]);
  const auto contacts = CsvRows(prefix + "_contacts.csv");
  ASSERT_EQ(contacts.size(), packing.contacts.size() + 1);
  EXPECT_EQ(contacts[0], "i,j,x_i_m,y_i_m,x_j_m,y_j_m");
  const auto contact = CsvNumbers(contacts[1]);
  ASSERT_EQ(contact.size(), 6u);
  EXPECT_EQ(contact[0], packing.contacts[0][0]);
  EXPECT_EQ(contact[5], packing.centres[packing.contacts[0][1]].y());
}

TEST(PackingPictures, DiscAndPolygonDomainsAndEqualRadii) {
  ScratchDirectory directory;
  Packing<2> disc = GridPacking(Domain<2>::Disc(Vector<2>(0.5, 0.5), 0.5), 10, 10, 2);
  std::fill(disc.radii.begin(), disc.radii.end(), 0.04);
  PicturesWritten written =
      WritePackingPictures(disc, HandMadeMetrics(disc, 18), directory.File("disc"));
  EXPECT_TRUE(written.warnings.empty()) << JoinWarnings(written);
  ExpectPng(directory.File("disc_packing.png"));
  const auto radii = CsvRows(directory.File("disc_radii.csv"));
  ASSERT_EQ(radii.size(), 2u) << "equal radii: one bin";
  EXPECT_EQ(CsvNumbers(radii[1])[2], 100.0);

  const auto polygon =
      Domain<2>::Polygon({Vector<2>(0, 0), Vector<2>(1, 0), Vector<2>(1, 0.3), Vector<2>(0.3, 0.3),
                          Vector<2>(0.3, 1), Vector<2>(0, 1)});
  const Packing<2> lshape = GridPacking(polygon, 10, 10, 3);
  PackingPicturesOptions options;
  options.radius_bins = 5;
  options.contact_drawing_limit = 0;  // no contact lines; the contacts CSV all the same
  written = WritePackingPictures(lshape, HandMadeMetrics(lshape, 36), directory.File("l"), options);
  EXPECT_TRUE(written.warnings.empty()) << JoinWarnings(written);
  ExpectPng(directory.File("l_packing.png"));
  EXPECT_EQ(CsvRows(directory.File("l_radii.csv")).size(), 6u);
  EXPECT_TRUE(Contains(written.files, directory.File("l_contacts.csv")));
}

TEST(PackingPictures, ThreeDimensionalPackingWritesParticlesAndContactsButNoPackingPicture) {
  ScratchDirectory directory;
  Packing<3> packing(Domain<3>::Box(Vector<3>(0, 0, 0), Vector<3>(1, 1, 1)));
  std::mt19937 random(4);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 100; ++i) {
    packing.centres.push_back(Vector<3>(unit(random), unit(random), unit(random)));
    packing.radii.push_back(0.02 + 0.03 * unit(random));
    if (i > 0) packing.contacts.push_back({i - 1, i});
  }
  const std::string prefix = directory.File("solid");
  const PicturesWritten written =
      WritePackingPictures(packing, HandMadeMetrics(packing, 24), prefix);
  EXPECT_TRUE(written.warnings.empty()) << JoinWarnings(written);
  EXPECT_FALSE(Contains(written.files, prefix + "_packing.png"));
  // The particles and contacts with z, as in 2D.
  const auto particles = CsvRows(prefix + "_particles.csv");
  ASSERT_EQ(particles.size(), 101u);
  EXPECT_EQ(particles[0], "x_m,y_m,z_m,radius_m");
  EXPECT_EQ(CsvNumbers(particles[100]),
            (std::vector<double>{packing.centres[99].x(), packing.centres[99].y(),
                                 packing.centres[99].z(), packing.radii[99]}));
  const auto contacts = CsvRows(prefix + "_contacts.csv");
  ASSERT_EQ(contacts.size(), 100u);
  EXPECT_EQ(contacts[0], "i,j,x_i_m,y_i_m,z_i_m,x_j_m,y_j_m,z_j_m");
  EXPECT_EQ(CsvNumbers(contacts[99]),
            (std::vector<double>{98, 99, packing.centres[98].x(), packing.centres[98].y(),
                                 packing.centres[98].z(), packing.centres[99].x(),
                                 packing.centres[99].y(), packing.centres[99].z()}));
  ExpectPng(prefix + "_radius_histogram.png");
  ExpectPng(prefix + "_orientation_rose.png");
  const auto orientation = CsvRows(prefix + "_orientation.csv");
  ASSERT_EQ(orientation.size(), 49u);
  EXPECT_EQ(orientation[0],
            "bin_low_deg,bin_high_deg,bin_centre_deg,mirrored,xy_weight,xz_weight,yz_weight,"
            "xy_relative_to_isotropic,xz_relative_to_isotropic,yz_relative_to_isotropic");
  EXPECT_EQ(CsvNumbers(orientation[1]).size(), 10u);
  EXPECT_EQ(CsvRows(prefix + "_radii.csv").size(), 11u);  // ceil(sqrt(100)) bins + header
}

TEST(PackingPictures, WithoutGnuplotTheNumbersAreStillWritten) {
  ScratchDirectory directory;
  const Packing<2> packing = GridPacking(Domain<2>::Rectangle(0, 0, 1, 1), 5, 5, 5);
  const std::string saved_path = std::getenv("PATH") ? std::getenv("PATH") : "";
  setenv("PATH", directory.path().c_str(), 1);  // an empty directory: no gnuplot
  PicturesWritten written;
  try {
    written = WritePackingPictures(packing, HandMadeMetrics(packing, 36), directory.File("run"));
  } catch (...) {
    setenv("PATH", saved_path.c_str(), 1);
    throw;
  }
  setenv("PATH", saved_path.c_str(), 1);
  ASSERT_EQ(written.warnings.size(), 1u) << JoinWarnings(written);
  EXPECT_NE(written.warnings[0].find("gnuplot"), std::string::npos);
  EXPECT_NE(written.warnings[0].find("run_packing.png"), std::string::npos);
  for (const auto& file : written.files) EXPECT_EQ(file.find(".png"), std::string::npos) << file;
  EXPECT_TRUE(Contains(written.files, directory.File("run_radii.csv")));
  EXPECT_TRUE(Contains(written.files, directory.File("run_orientation.csv")));
  EXPECT_TRUE(Contains(written.files, directory.File("run_particles.csv")));
  EXPECT_EQ(directory.Entries().size(), written.files.size());
}

TEST(PackingPictures, InconsistentInputThrowsBeforeWritingAnything) {
  ScratchDirectory directory;
  const Packing<2> packing = GridPacking(Domain<2>::Rectangle(0, 0, 1, 1), 5, 5, 6);
  PackingMetrics<2> metrics = HandMadeMetrics(packing, 36);

  PackingMetrics<2> three_rows = metrics;
  three_rows.orientation_histograms.resize(3, metrics.orientation_histograms[0]);
  EXPECT_THROW(WritePackingPictures(packing, three_rows, directory.File("a")), InputError);
  PackingMetrics<2> negative = metrics;
  negative.orientation_histograms[0][3] = -1.0;
  EXPECT_THROW(WritePackingPictures(packing, negative, directory.File("b")), InputError);
  PackingMetrics<2> other = metrics;
  other.particle_count = 7;
  EXPECT_THROW(WritePackingPictures(packing, other, directory.File("c")), InputError);
  PackingPicturesOptions options;
  options.radius_bins = -2;
  EXPECT_THROW(WritePackingPictures(packing, metrics, directory.File("d"), options), InputError);
  EXPECT_TRUE(directory.Entries().empty());

  EXPECT_THROW(WritePackingPictures(packing, metrics, directory.File("missing/run")), FileError);
  EXPECT_TRUE(directory.Entries().empty());
}

TEST(PackingPictures, MissingOrEmptyOrientationsAreWarnings) {
  ScratchDirectory directory;
  const Packing<2> packing = GridPacking(Domain<2>::Rectangle(0, 0, 1, 1), 5, 5, 7);
  PackingMetrics<2> metrics = HandMadeMetrics(packing, 36);
  metrics.orientation_histograms.clear();
  PicturesWritten written = WritePackingPictures(packing, metrics, directory.File("none"));
  ASSERT_EQ(written.warnings.size(), 1u) << JoinWarnings(written);
  EXPECT_FALSE(Contains(written.files, directory.File("none_orientation_rose.png")));

  metrics.orientation_histograms = {std::vector<double>(36, 0.0)};
  written = WritePackingPictures(packing, metrics, directory.File("zero"));
  ASSERT_EQ(written.warnings.size(), 1u) << JoinWarnings(written);
  EXPECT_TRUE(Contains(written.files, directory.File("zero_orientation.csv")));
  EXPECT_FALSE(Contains(written.files, directory.File("zero_orientation_rose.png")));
}

TEST(PackingPictures, TwoHundredThousandDiscsDrawInReasonableTime) {
  ScratchDirectory directory;
  const Packing<2> packing = GridPacking(Domain<2>::Rectangle(0, 0, 1, 1), 500, 400, 8);
  ASSERT_EQ(packing.size(), 200000);
  const auto start = std::chrono::steady_clock::now();
  const PicturesWritten written =
      WritePackingPictures(packing, HandMadeMetrics(packing, 36), directory.File("large"));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(written.warnings.empty()) << JoinWarnings(written);
  ExpectPng(directory.File("large_packing.png"));
  EXPECT_TRUE(Contains(written.files, directory.File("large_contacts.csv")));  // written, not drawn
  EXPECT_LT(seconds, 60.0);
}

}  // namespace
}  // namespace specimen
