#pragma once
// Shared plumbing of the command-line programs: turning the library's typed errors into a
// message and an exit status, and small parsing helpers. No physics here.

#include <exception>
#include <functional>
#include <iostream>
#include <string>

#include "common/error.h"

namespace specimen {

// Exit statuses, the same for every command.
enum ExitStatus : int {
  kExitOk = 0,
  kExitFailure = 1,        // unexpected internal error
  kExitBadInput = 2,       // a field or file content out of range (message names it)
  kExitFileError = 3,      // a file could not be read or written
  kExitComputation = 4,    // diverged or did not converge within its budget
};

// Runs `body`, printing "<program>: error: <message>" on stderr for any exception.
inline int RunCommand(const std::string& program, const std::function<int()>& body) {
  try {
    return body();
  } catch (const InputError& e) {
    std::cerr << program << ": error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const FileError& e) {
    std::cerr << program << ": error: " << e.what() << "\n";
    return kExitFileError;
  } catch (const ComputationError& e) {
    std::cerr << program << ": error: " << e.what() << "\n";
    return kExitComputation;
  } catch (const std::exception& e) {
    std::cerr << program << ": internal error: " << e.what() << "\n";
    return kExitFailure;
  }
}

}  // namespace specimen
