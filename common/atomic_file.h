#pragma once
// Output files are written to a temporary name next to the target and renamed into
// place only when complete (design.md, "Files"): a crash or a bad input never leaves a
// half-written file behind.

#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

namespace specimen {

// Writes `path` atomically: `write` fills the stream; on success the temporary file is
// flushed, closed and renamed to `path`; on any exception it is removed and the
// exception propagates (as FileError when the stream itself failed).
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

// Throws FileError naming `what` if `directory` does not exist or is not writable.
// Call before long work so a bad output path fails in a second, not after an hour.
void RequireWritableDirectory(const std::string& directory, const std::string& what);

// Creates `directory` (and parents) if missing; throws FileError if that is impossible.
void EnsureDirectory(const std::string& directory, const std::string& what);

// Several files that must appear together (the outputs of one command): each Add()
// writes a temporary file; Commit() renames them all into place. If the group is
// destroyed without Commit(), every temporary file is removed.
class OutputGroup {
 public:
  OutputGroup() = default;
  OutputGroup(const OutputGroup&) = delete;
  OutputGroup& operator=(const OutputGroup&) = delete;
  ~OutputGroup();

  void Add(const std::string& path, const std::function<void(std::ostream&)>& write);
  // Renames all files into place; returns the final paths.
  std::vector<std::string> Commit();
  // Temporary path of a file already added (to let an external tool read it before
  // commit, e.g. a plotting script reading its CSV).
  const std::string& TemporaryPath(const std::string& path) const;

 private:
  std::vector<std::pair<std::string, std::string>> files_;  // (final, temporary)
  bool committed_ = false;
};

}  // namespace specimen
