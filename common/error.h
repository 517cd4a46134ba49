#pragma once
// Typed errors. Library code never exits: it throws one of these with a message that
// names the offending field, its value and the allowed range; the command-line tools
// turn them into a message on stderr and a non-zero exit status.

#include <stdexcept>
#include <string>

namespace specimen {

// Bad input from the user: an option, a file field, a geometry that cannot work.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A file could not be read, parsed or written.
class FileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A computation failed to reach its goal (divergence, no convergence within budget).
class ComputationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Debug-only invariant check (MFEM_ASSERT style); input checks use InputError instead.
#ifndef NDEBUG
#define SPECIMEN_ASSERT(cond, msg)                                                     \
  do {                                                                                  \
    if (!(cond)) throw std::logic_error(std::string("assertion failed: ") + (msg));   \
  } while (0)
#else
#define SPECIMEN_ASSERT(cond, msg) \
  do {                             \
  } while (0)
#endif

}  // namespace specimen
