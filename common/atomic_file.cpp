#include "common/atomic_file.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "common/error.h"

namespace specimen {
namespace {

// The temporary files in flight, for the signal handler: fixed slots it can read without a
// lock (0 free, 1 being filled, 2 holds a path).
constexpr int kSlots = 128;
constexpr int kPathCapacity = 4096;
struct TemporarySlot {
  std::atomic<int> state{0};
  char path[kPathCapacity];
};
TemporarySlot g_temporaries[kSlots];

int RegisterTemporary(const std::string& path) {
  if (path.size() >= kPathCapacity) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (!g_temporaries[i].state.compare_exchange_strong(expected, 1)) continue;
    std::memcpy(g_temporaries[i].path, path.c_str(), path.size() + 1);
    g_temporaries[i].state.store(2);
    return i;
  }
  return -1;  // all slots taken: this one is not removed on a signal
}

void ReleaseTemporary(int slot) {
  if (slot >= 0) g_temporaries[slot].state.store(0);
}

// "<name>.tmp-<pid>-<8 hex>": the pid lets a later run tell a dead run's leftovers from a
// live run's files.
constexpr char kTemporaryTag[] = ".tmp-";

// Removes "<path>.tmp-<pid>-*" files whose process no longer exists (a run killed with
// SIGKILL, or a crash, left them).
void RemoveStaleTemporaries(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path directory = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const std::string prefix = target.filename().string() + kTemporaryTag;
  std::error_code error;
  for (const fs::directory_entry& e : fs::directory_iterator(directory, error)) {
    const std::string name = e.path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    char* end = nullptr;
    const long pid = std::strtol(name.c_str() + prefix.size(), &end, 10);
    if (pid <= 0 || end == nullptr || *end != '-') continue;
    if (kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;  // alive, or not ours to judge
    std::error_code ignored;
    fs::remove(e.path(), ignored);
  }
}

std::string TemporaryNameFor(const std::string& path) {
  static thread_local std::mt19937_64 rng(std::random_device{}() ^ static_cast<unsigned>(getpid()));
  RemoveStaleTemporaries(path);
  char suffix[64];
  std::snprintf(suffix, sizeof(suffix), "%s%ld-%08llx", kTemporaryTag, static_cast<long>(getpid()),
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

namespace {

// Writes a registered temporary for `path`; returns its name and slot.
std::pair<std::string, int> WriteRegisteredTemporary(const std::string& path,
                                                      const std::function<void(std::ostream&)>& write) {
  const std::string temporary = TemporaryNameFor(path);
  const int slot = RegisterTemporary(temporary);
  try {
    WriteTemporary(temporary, path, write);
  } catch (...) {
    ReleaseTemporary(slot);
    throw;
  }
  return {temporary, slot};
}

}  // namespace

void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  const auto [temporary, slot] = WriteRegisteredTemporary(path, write);
  const bool moved = detail::rename_file(temporary.c_str(), path.c_str()) == 0;
  if (!moved) std::remove(temporary.c_str());
  ReleaseTemporary(slot);
  if (!moved) throw FileError("cannot move the finished file into place at '" + path + "'");
}

namespace detail {
int (*rename_file)(const char*, const char*) = std::rename;
}  // namespace detail

void RemoveTemporaryFilesNow() noexcept {
  for (TemporarySlot& slot : g_temporaries)
    if (slot.state.load() == 2) unlink(slot.path);
}

namespace {

volatile sig_atomic_t g_interrupt_installed = 0;
char g_program[128] = "specimen";

void OnInterrupt(int signal_number) {
  RemoveTemporaryFilesNow();
  const char* what = signal_number == SIGINT ? "SIGINT" : "SIGTERM";
  // write(2) only: the handler may run inside any library call.
  auto say = [](const char* text) {
    const ssize_t ignored = write(STDERR_FILENO, text, std::strlen(text));
    (void)ignored;
  };
  say("\n");
  say(g_program);
  say(": interrupted by ");
  say(what);
  say(": stopped; its temporary files were removed, files it had already completed stay\n");
  _exit(128 + signal_number);
}

}  // namespace

void InstallInterruptHandler(const std::string& program) {
  std::snprintf(g_program, sizeof g_program, "%s", program.c_str());
  if (g_interrupt_installed) return;
  struct sigaction action {};
  action.sa_handler = OnInterrupt;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  g_interrupt_installed = 1;
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

bool IsValidOutputName(const std::string& name, std::string* rule) {
  constexpr size_t kLongest = 200;
  bool control = false;
  for (const unsigned char c : name) control = control || c < 0x20 || c == 0x7f;
  if (!name.empty() && name.find('/') == std::string::npos && name.front() != '.' && !control &&
      name.size() <= kLongest)
    return true;
  if (rule)
    *rule = "it must be a non-empty file name without '/' or control characters, not starting with '.', of at most " +
            std::to_string(kLongest) + " bytes (this one has " + std::to_string(name.size()) + ")";
  return false;
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
  for (std::size_t i = 0; i < files_.size(); ++i) {
    std::remove(files_[i].second.c_str());
    ReleaseTemporary(slots_[i]);
  }
}

void OutputGroup::Add(const std::string& path, const std::function<void(std::ostream&)>& write) {
  const auto [temporary, slot] = WriteRegisteredTemporary(path, write);
  files_.emplace_back(path, temporary);
  slots_.push_back(slot);
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
  // The files of an earlier set step aside first, so that a failed move can put them back.
  std::vector<std::string> aside(files_.size());
  std::vector<int> aside_slots(files_.size(), -1);
  std::size_t moved = 0;
  auto roll_back = [&]() {
    for (std::size_t i = 0; i < moved; ++i) std::remove(files_[i].first.c_str());
    for (std::size_t i = 0; i < files_.size(); ++i)
      if (!aside[i].empty()) {
        detail::rename_file(aside[i].c_str(), files_[i].first.c_str());
        ReleaseTemporary(aside_slots[i]);
      }
  };
  for (std::size_t i = 0; i < files_.size(); ++i) {
    if (!std::filesystem::exists(files_[i].first)) continue;
    const std::string name = TemporaryNameFor(files_[i].first + ".previous");
    if (detail::rename_file(files_[i].first.c_str(), name.c_str()) != 0) {
      roll_back();
      throw FileError("cannot replace '" + files_[i].first + "' (the earlier file could not be moved aside); "
                      "nothing of this output set was written");
    }
    aside[i] = name;
  }
  for (; moved < files_.size(); ++moved) {
    const auto& file = files_[moved];
    if (detail::rename_file(file.second.c_str(), file.first.c_str()) != 0) {
      roll_back();
      throw FileError("cannot move the finished file into place at '" + file.first +
                      "'; nothing of this output set was written (earlier files restored)");
    }
  }
  std::vector<std::string> paths;
  for (std::size_t i = 0; i < files_.size(); ++i) {
    if (!aside[i].empty()) std::remove(aside[i].c_str());
    ReleaseTemporary(slots_[i]);
    paths.push_back(files_[i].first);
  }
  committed_ = true;
  return paths;
}

}  // namespace specimen
