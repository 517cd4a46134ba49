// The generate-packing command as a user runs it: exit status, messages, files.
#include <gtest/gtest.h>

#include "tests/tools/command_runner.h"
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "generator/packing_io.h"
#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

using Result = specimen::testing::CommandResult;

Result RunCommandLine(const std::string& arguments) {
  return specimen::testing::RunProgram("generate-packing", arguments);
}

fs::path FreshDirectory(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("specimen_cli_" + name);
  fs::remove_all(dir);
  return dir;
}

bool EmptyOrMissing(const fs::path& dir) { return !fs::exists(dir) || fs::is_empty(dir); }

TEST(GeneratePackingCommand, WritesEveryFileAndTheyReadBack) {
  const fs::path dir = FreshDirectory("ok");
  const Result r = RunCommandLine("--domain \"rectangle 0 0 10 10\" --count 400 --output " + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* file : {"packing.packing", "packing.vtu", "packing_yade.txt", "packing.liggghts",
                           "packing_report.json", "packing_radii.csv", "packing_orientation.csv"})
    EXPECT_TRUE(fs::exists(dir / file)) << file;
  EXPECT_NE(r.output.find("coordination number"), std::string::npos);
  const auto packing = specimen::LoadPacking<2>((dir / "packing.packing").string());
  EXPECT_GT(packing.size(), 300);
}

TEST(GeneratePackingCommand, BadInputExitsWithTwoAndWritesNothing) {
  struct Case {
    std::string arguments;
    std::string must_mention;
  };
  const Case cases[] = {
      {"--domain \"hexagon 0 0 1\" --count 100", "unknown domain"},
      {"--domain \"rectangle 0 0 -5 10\" --count 100", "width"},
      {"--domain \"rectangle 0 0 10 10\" --count 100 --radius-ratio 0.5", "--radius-ratio"},
      // A bad value given is rejected, never replaced by the default.
      {"--domain \"rectangle 0 0 10 10\" --count 100 --radius-ratio -3", "--radius-ratio"},
      {"--domain \"rectangle 0 0 10 10\" --count 100 --max-rounds 0", "--max-rounds"},
      {"--domain \"rectangle 0 0 10 10\" --count 100 --node-spread 0", "--node-spread"},
      {"--domain \"rectangle 0 0 10 10\" --count 100 --overlap-tolerance -1", "--overlap-tolerance"},
      {"--domain \"rectangle 0 0 10 10\" --count 100 --threads 0", "--threads"},
      {"--domain \"rectangle 0 0 10 10\" --count 100 --seed -1", "--seed"},
      {"--domain \"rectangle 0 0 10 10\" --count 0", "--count"},
      {"--domain \"rectangle 0 0 10 10\" --mean-radius -0.1", "--mean-radius"},
      // Parse errors of the command line itself are bad input too (not CLI11's own codes).
      {"--domain \"rectangle 0 0 10 10\" --count nan", "--count"},
      {"--domain \"rectangle 0 0 10 10\" --count 100 --bogus", "--bogus"},
      {"--count 100", "--domain"},
      {"--domain \"rectangle 0 0 1 1\" --mean-radius 0.4", "too small"},
      {"--domain \"polygon 4 0 0 1 1 1 0 0 1\" --count 100", "self-intersecting"},
      {"--domain \"cylinder 0 0 0.5 1 1\" --count 100", "cylinder length"},
      {"--domain \"rectangle 0 0 10 10\" --count 100 --contact-tolerance 0.9", "--contact-tolerance"},
      {"--domain \"rectangle 0 0 10 10\" --count 100 --contact-tolerance 0", "--contact-tolerance"},
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --compaction maybe", "--compaction"},
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --compaction-exponent 9", "--compaction-exponent"},
      // The power-law preset and the settings it would ignore.
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --radius-distribution lognormal", "--radius-distribution"},
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --size-exponent 3", "--size-exponent"},
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --radius-distribution power-law --size-exponent 7",
       "--size-exponent"},
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --radius-distribution power-law --size-exponent -1",
       "--size-exponent"},
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --radius-distribution power-law --radius-factor 0.9 1.1",
       "--radius-factor"},
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --radius-distribution power-law --compaction off",
       "--compaction off"},
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --close-gap 0", "--close-gap"},
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --close-gap 0.6", "--close-gap"},
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --exact-pairs 0", "--exact-pairs"},
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --exact-pairs 2.5", "--exact-pairs"},
      // The contact band: it needs kept overlaps, and its settings need it.
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --contact-band", "--keep-overlaps"},
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --band-rounds 2", "--contact-band"},
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --refill-passes 1", "--contact-band"},
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --keep-overlaps --contact-band --band-rounds 21",
       "--band-rounds"},
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --keep-overlaps --contact-band --refill-passes -1",
       "--refill-passes"},
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --keep-overlaps --contact-band --band-candidate-gap 0",
       "--band-candidate-gap"},
      {"--domain \"box 0 0 0 1 1 1\" --count 100 --keep-overlaps --contact-band --band-rounds 0 "
       "--refill-passes 0", "nothing"},
  };
  for (const Case& c : cases) {
    const fs::path dir = FreshDirectory("bad");
    const Result r = RunCommandLine(c.arguments + " --output " + dir.string());
    EXPECT_EQ(r.status, 2) << c.arguments << "\n" << r.output;
    EXPECT_NE(r.output.find(c.must_mention), std::string::npos) << c.arguments << "\n" << r.output;
    EXPECT_TRUE(EmptyOrMissing(dir)) << c.arguments;
  }
}

TEST(GeneratePackingCommand, NoPicturesStillWritesTheirCsvFiles) {
  const fs::path dir = FreshDirectory("no_pictures");
  const Result r =
      RunCommandLine("--domain \"rectangle 0 0 10 10\" --count 400 --no-pictures --output " + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* file : {"packing_radii.csv", "packing_orientation.csv"})
    EXPECT_TRUE(fs::exists(dir / file)) << file;
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_NE(entry.path().extension(), ".png") << entry.path();
}

// Any tolerance in the documented range is usable: the fold-over threshold (conflict_overlap,
// 0.05 by default) follows a larger overlap tolerance instead of rejecting it.
TEST(GeneratePackingCommand, OverlapToleranceOverItsWholeRange) {
  for (const char* tolerance : {"0", "0.02", "0.1"}) {
    const fs::path dir = FreshDirectory("overlap_tolerance");
    const Result r = RunCommandLine("--domain \"rectangle 0 0 10 10\" --count 200 --keep-overlaps "
                                    "--no-pictures --overlap-tolerance " + std::string(tolerance) +
                                    " --output " + dir.string());
    EXPECT_EQ(r.status, 0) << tolerance << "\n" << r.output;
  }
}

TEST(GeneratePackingCommand, UnwritableOutputFailsBeforeWork) {
  const Result r = RunCommandLine("--domain \"rectangle 0 0 10 10\" --count 100 --output /proc/specimen_no");
  EXPECT_EQ(r.status, 3) << r.output;
  EXPECT_NE(r.output.find("output directory"), std::string::npos) << r.output;
}

TEST(GeneratePackingCommand, MissingSizeIsReported) {
  const Result r = RunCommandLine("--domain \"rectangle 0 0 10 10\"");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--count"), std::string::npos) << r.output;
}

}  // namespace

// The contact band from the command line: with power-law the rounds stop after 3, and the
// report and JSON list its steps (its effect on nc is checked in contact_band_test.cpp).
TEST(GeneratePackingCommand, ContactBandInABox) {
  const fs::path dir = FreshDirectory("contact_band");
  const Result r = RunCommandLine("--domain \"box 0 0 0 1 1 1\" --count 600 --radius-distribution power-law "
                                  "--keep-overlaps --overlap-tolerance 0.02 --contact-band --band-rounds 2 "
                                  "--quiet --no-pictures --output " + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("contact band"), std::string::npos) << r.output;
  // Rounds 0 to 2 in the table, then 2 refills and 2 band solves.
  std::ifstream report(dir / "packing_report.json");
  const auto json = nlohmann::json::parse(report);
  EXPECT_EQ(json["generator"]["rounds"].size(), 3u) << json.dump(1);
  ASSERT_EQ(json["generator"]["band_steps"].size(), 4u) << json.dump(1);
  EXPECT_EQ(json["generator"]["band_steps"][3]["kind"], "band");
  fs::remove_all(dir);
}

// The dense preset runs end to end from the command line and reports its radius bounds.
TEST(GeneratePackingCommand, PowerLawPresetInABox) {
  const fs::path dir = FreshDirectory("power_law");
  const Result r = RunCommandLine("--domain \"box 0 0 0 1 1 1\" --count 600 --radius-distribution power-law "
                                  "--quiet --no-pictures --output " + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("compaction before round 0"), std::string::npos) << r.output;
  const auto packing = specimen::LoadPacking<3>((dir / "packing.packing").string());
  EXPECT_GT(packing.size(), 450);
  fs::remove_all(dir);
}

namespace {

bool HasTemporaries(const fs::path& dir) {
  if (!fs::exists(dir)) return false;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp-") != std::string::npos) return true;
  return false;
}

TEST(GeneratePackingCommand, InterruptStopsWithItsStatusAndLeavesNoTemporaries) {
  for (const int signal_number : {SIGINT, SIGTERM}) {
    const fs::path dir = FreshDirectory(signal_number == SIGINT ? "sigint" : "sigterm");
    fs::create_directories(dir);
    // Long enough (tens of seconds) to be interrupted during the work.
    const Result r = specimen::testing::RunProgramInterrupted(
        "generate-packing", "--domain \"rectangle 0 0 100 100\" --count 300000 --output " + dir.string(),
        signal_number, 1.5, (fs::temp_directory_path() / "specimen_cli_interrupt.log").string());
    EXPECT_EQ(r.status, 128 + signal_number) << r.output;
    EXPECT_NE(r.output.find(signal_number == SIGINT ? "interrupted by SIGINT" : "interrupted by SIGTERM"),
              std::string::npos)
        << r.output;
    EXPECT_TRUE(EmptyOrMissing(dir)) << "an interrupted run left files";
  }
}

TEST(GeneratePackingCommand, TemporariesOfAKilledRunAreRemovedByTheNextRun) {
  const fs::path dir = FreshDirectory("stale");
  fs::create_directories(dir);
  // A pid that no longer exists: a child that has exited and been reaped.
  const pid_t child = fork();
  if (child == 0) _exit(0);
  waitpid(child, nullptr, 0);
  const std::string dead = std::to_string(child);
  const fs::path stale = dir / ("packing.packing.tmp-" + dead + "-0badf00d");
  const fs::path live = dir / ("packing.packing.tmp-" + std::to_string(getpid()) + "-0badf00d");
  for (const fs::path& p : {stale, live}) std::ofstream(p) << "half a packing";
  const Result r = RunCommandLine("--domain \"rectangle 0 0 10 10\" --count 200 --output " + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_FALSE(fs::exists(stale)) << "a killed run's temporary stayed";
  EXPECT_TRUE(fs::exists(live)) << "a live process's temporary was removed";
  fs::remove(live);
  EXPECT_FALSE(HasTemporaries(dir));
}

}  // namespace

namespace {

// An empty value is refused, naming the option, never read as 0 or the default.
TEST(GeneratePackingCommand, EmptyValuesAreRefused) {
  for (const char* arguments : {"--radius-ratio ''", "--seed=", "--overlap-tolerance ''"}) {
    SCOPED_TRACE(arguments);
    const fs::path dir = FreshDirectory("empty_value");
    const Result r = RunCommandLine(std::string("--domain \"rectangle 0 0 10 10\" --count 100 ") + arguments +
                                    " --output " + dir.string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("empty value"), std::string::npos) << r.output;
    EXPECT_TRUE(EmptyOrMissing(dir));
  }
}

}  // namespace
