#include "common/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/error.h"

namespace specimen {
namespace {

namespace fs = std::filesystem;

fs::path FreshDirectory(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("specimen_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string ReadAll(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

TEST(AtomicFile, WritesCompleteFile) {
  const fs::path dir = FreshDirectory("atomic_ok");
  WriteFileAtomically((dir / "a.txt").string(), [](std::ostream& out) { out << "hello\n"; });
  EXPECT_EQ(ReadAll(dir / "a.txt"), "hello\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

TEST(AtomicFile, FailureLeavesNothingBehind) {
  const fs::path dir = FreshDirectory("atomic_fail");
  EXPECT_THROW(WriteFileAtomically((dir / "a.txt").string(),
                                   [](std::ostream& out) {
                                     out << "partial";
                                     throw std::runtime_error("boom");
                                   }),
               std::runtime_error);
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(AtomicFile, UnwritableDirectoryIsReported) {
  EXPECT_THROW(WriteFileAtomically("/nonexistent_dir_xyz/a.txt", [](std::ostream&) {}), FileError);
  EXPECT_THROW(RequireWritableDirectory("/nonexistent_dir_xyz", "output"), FileError);
}

TEST(OutputGroup, CommitsAllOrNothing) {
  const fs::path dir = FreshDirectory("group");
  {
    OutputGroup group;
    group.Add((dir / "one.txt").string(), [](std::ostream& out) { out << "1"; });
    group.Add((dir / "two.txt").string(), [](std::ostream& out) { out << "2"; });
    // Destroyed without Commit(): nothing may remain.
  }
  EXPECT_TRUE(fs::is_empty(dir));
  OutputGroup group;
  group.Add((dir / "one.txt").string(), [](std::ostream& out) { out << "1"; });
  group.Add((dir / "two.txt").string(), [](std::ostream& out) { out << "2"; });
  const auto paths = group.Commit();
  EXPECT_EQ(paths.size(), 2u);
  EXPECT_EQ(ReadAll(dir / "one.txt"), "1");
  EXPECT_EQ(ReadAll(dir / "two.txt"), "2");
}

TEST(AtomicFile, AFailedMoveLeavesTheEarlierSetWhole) {
  const fs::path dir = FreshDirectory("atomic_set_rollback");
  const std::string a = (dir / "a.txt").string(), b = (dir / "b.txt").string(), c = (dir / "c.txt").string();
  {
    OutputGroup first;
    first.Add(a, [](std::ostream& out) { out << "old a"; });
    first.Add(b, [](std::ostream& out) { out << "old b"; });
    first.Commit();
  }
  // The third move into place fails (as on a full or read-only file system).
  static int calls = 0;
  calls = 0;
  auto* real = detail::rename_file;
  detail::rename_file = [](const char* from, const char* to) {
    const std::string target(to);
    if (target.find(".tmp-") == std::string::npos && target.size() >= 5 &&
        target.compare(target.size() - 5, 5, "c.txt") == 0)
      return -1;
    ++calls;
    return std::rename(from, to);
  };
  {
    OutputGroup second;
    second.Add(a, [](std::ostream& out) { out << "new a"; });
    second.Add(b, [](std::ostream& out) { out << "new b"; });
    second.Add(c, [](std::ostream& out) { out << "new c"; });
    EXPECT_THROW(second.Commit(), FileError);
  }
  detail::rename_file = real;
  EXPECT_GT(calls, 0);
  EXPECT_EQ(ReadAll(a), "old a");
  EXPECT_EQ(ReadAll(b), "old b");
  EXPECT_FALSE(fs::exists(c));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 2) << "leftovers";
  // Without the fault the new set replaces the old one whole.
  {
    OutputGroup third;
    third.Add(a, [](std::ostream& out) { out << "new a"; });
    third.Add(c, [](std::ostream& out) { out << "new c"; });
    third.Commit();
  }
  EXPECT_EQ(ReadAll(a), "new a");
  EXPECT_EQ(ReadAll(c), "new c");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 3);
}

}  // namespace
}  // namespace specimen
