#include "common/atomic_file.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include "common/error.h"

namespace specimen {
namespace {

std::string TemporaryNameFor(const std::string& path) {
  static thread_local std::mt19937_64 rng(std::random_device{}() ^ static_cast<unsigned>(getpid()));
  char suffix[32];
  std::snprintf(suffix, sizeof(suffix), ".tmp-%08llx",
                static_cast<unsigned long long>(rng() & 0xffffffffULL));
  return path + suffix;
}

void WriteTemporary(const std::string& temporary, const std::string& path,
                    const std::function<void(std::ostream&)>& write) {
  std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
  if (!out) throw FileError("cannot open '" + path + "' for writing");
  try {
    write(out);
    out.flush();
    if (!out) throw FileError("writing '" + path + "' failed (disk full?)");
    out.close();
    if (!out) throw FileError("closing '" + path + "' failed");
  } catch (...) {
    out.close();
    std::remove(temporary.c_str());
    throw;
  }
}

}  // namespace

void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  const std::string temporary = TemporaryNameFor(path);
  WriteTemporary(temporary, path, write);
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    std::remove(temporary.c_str());
    throw FileError("cannot move the finished file into place at '" + path + "'");
  }
}

void RequireWritableDirectory(const std::string& directory, const std::string& what) {
  namespace fs = std::filesystem;
  const std::string dir = directory.empty() ? "." : directory;
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw FileError(what + ": '" + dir + "' exists and is not a directory");
  if (!fs::is_directory(dir, ec))
    throw FileError(what + ": directory '" + dir + "' does not exist");
  if (access(dir.c_str(), W_OK) != 0)
    throw FileError(what + ": directory '" + dir + "' is not writable");
}

void EnsureDirectory(const std::string& directory, const std::string& what) {
  namespace fs = std::filesystem;
  if (directory.empty()) return;
  std::error_code ec;
  fs::create_directories(directory, ec);
  if (ec && !fs::is_directory(directory))
    throw FileError(what + ": cannot create directory '" + directory + "': " + ec.message());
  RequireWritableDirectory(directory, what);
}

OutputGroup::~OutputGroup() {
  if (committed_) return;
  for (const auto& file : files_) std::remove(file.second.c_str());
}

void OutputGroup::Add(const std::string& path, const std::function<void(std::ostream&)>& write) {
  const std::string temporary = TemporaryNameFor(path);
  WriteTemporary(temporary, path, write);
  files_.emplace_back(path, temporary);
}

const std::string& OutputGroup::TemporaryPath(const std::string& path) const {
  for (const auto& file : files_)
    if (file.first == path) return file.second;
  throw std::logic_error("OutputGroup: no file '" + path + "' was added");
}

std::vector<std::string> OutputGroup::Commit() {
  // A destination that is a directory would make its rename fail after the others were in
  // place: refuse before the first one, so that the group appears whole or not at all.
  for (const auto& file : files_)
    if (std::filesystem::is_directory(file.first))
      throw FileError("cannot write '" + file.first + "': a directory of that name is in the way");
  std::vector<std::string> paths;
  for (const auto& file : files_) {
    if (std::rename(file.second.c_str(), file.first.c_str()) != 0)
      throw FileError("cannot move the finished file into place at '" + file.first + "'");
    paths.push_back(file.first);
  }
  committed_ = true;
  return paths;
}

}  // namespace specimen
