#pragma once
// Progress for long work. A stage reports (fraction, message) through a callback; the
// command-line tools plug in a TerminalProgress, which draws one self-overwriting line
// on stderr when stderr is a terminal and stays silent otherwise or with --quiet.

#include <chrono>
#include <functional>
#include <string>

namespace specimen {

// fraction in [0, 1] (or negative when unknown), message: what is being done now.
using ProgressCallback = std::function<void(double fraction, const std::string& message)>;

class TerminalProgress {
 public:
  // quiet: never draw. Otherwise draws only when stderr is a terminal, or, with `lines`,
  // prints lines (rank 0 of an MPI run, whose stderr mpirun forwards through a pipe): one
  // each time the fraction has moved by 2 % (each point of a sweep of up to 50; a new
  // stage starting again from 0), at least every 10 s.
  explicit TerminalProgress(bool quiet, bool lines = false);
  ~TerminalProgress();

  void Update(double fraction, const std::string& message);
  // Clears the progress line (before printing a report).
  void Finish();
  bool enabled() const { return enabled_; }
  ProgressCallback Callback();

 private:
  bool enabled_;
  bool lines_;
  bool drawn_ = false;
  double last_fraction_ = -1.0;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace specimen
