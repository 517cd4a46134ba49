#pragma once
// Output files are written to a temporary name next to the target and renamed into
// place only when complete (docs/exports.md, "Output files are written atomically"): a
// crash or a bad input never leaves a half-written file behind.

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

// Whether `name` can prefix a command's output files: non-empty, without '/', not starting
// with '.' (no hidden files, no ".."), without control characters, and at most 200 bytes (a
// file name holds 255; the longest suffix a command adds, temporary tag included, is about
// 45). Else false, with the rule in *rule. Checked before any work.
bool IsValidOutputName(const std::string& name, std::string* rule);

// Installs handlers of SIGINT and SIGTERM that remove the temporary files in flight, say on
// stderr that `program` was interrupted, and exit with 128 + the signal (130, 143). Files of
// a run that were completed before the signal stay. Temporaries that a killed run (SIGKILL)
// leaves, "<name>.tmp-<pid>-<hex>", are removed by the next write of <name>.
void InstallInterruptHandler(const std::string& program);
// Removes the temporary files in flight (async-signal-safe).
void RemoveTemporaryFilesNow() noexcept;

namespace detail {
// The rename used to move files into place; tests replace it to simulate a failed move.
extern int (*rename_file)(const char*, const char*);
}  // namespace detail

// Several files that must appear together (the outputs of one command): each Add()
// writes a temporary file; Commit() renames them all into place, as a whole: the files of
// an earlier set of the same names step aside first, and if any move fails the new files
// are removed and the earlier ones put back (FileError). If the group is destroyed without
// Commit(), every temporary file is removed.
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
  std::vector<int> slots_;  // their places in the signal handler's list
  bool committed_ = false;
};

}  // namespace specimen
