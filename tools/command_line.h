#pragma once
// Shared plumbing of the command-line programs: turning the library's typed errors into a
// message and an exit status, and small parsing helpers. No physics here.

#include <CLI/CLI.hpp>
#include <exception>
#include <functional>
#include <iostream>
#include <string>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/field_names.h"
#include "common/format.h"

namespace specimen {

// Exit statuses, the same for every command.
enum ExitStatus : int {
  kExitOk = 0,
  kExitFailure = 1,        // unexpected internal error
  kExitBadInput = 2,       // a field or file content out of range (message names it)
  kExitFileError = 3,      // a file could not be read or written
  kExitComputation = 4,    // diverged or did not converge within its budget
};

// Parses the command line. False when the program must stop here, with *status set: 0 after
// --help or --version, kExitBadInput for an unknown option, a missing required one, a value
// CLI11 cannot convert or a conflict (CLI11 prints its message; its own exit codes, 100 and
// up, would break the "2 = bad input" contract of every command).
inline bool ParseCommandLine(CLI::App& app, int argc, char** argv, int* status) {
  // An empty value ("--kt ''", "--seed=") would reach CLI11 as 0, the default or an empty
  // string: refused, naming the option.
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool empty_after_equals = arg.rfind("--", 0) == 0 && !arg.empty() && arg.back() == '=';
    const bool empty_after_option = arg.empty() && i > 1 && argv[i - 1][0] == '-' && argv[i - 1][1] != '\0';
    if (empty_after_equals || empty_after_option) {
      const std::string option = empty_after_equals ? arg.substr(0, arg.size() - 1) : std::string(argv[i - 1]);
      std::string program = argv[0];
      program = program.substr(program.find_last_of('/') + 1);
      std::cerr << program << ": error: " << option << " is given an empty value\n";
      *status = kExitBadInput;
      return false;
    }
  }
  // One number grammar for every input (common/format.h): a numeric option takes finite
  // decimals only (CLI11 would also take "0x10", "inf" and "nan").
  for (CLI::Option* option : app.get_options()) {
    const std::string type = option->get_type_name();
    if (type.find("FLOAT") == std::string::npos && type.find("INT") == std::string::npos) continue;
    option->check(CLI::Validator(
        [](std::string& text) {
          double unused = 0.0;
          return ParseDecimal(text, &unused) ? std::string() : "'" + text + "' is not a finite decimal number";
        },
        "", "decimal"));
  }
  try {
    app.parse(argc, argv);
    return true;
  } catch (const CLI::ParseError& e) {
    *status = app.exit(e) == 0 ? kExitOk : kExitBadInput;
    return false;
  }
}

// Runs `body`, printing "<program>: error: <message>" on stderr for any exception. The
// messages of bad input name the fields in the user's terms (`names`). Ctrl-C and SIGTERM
// stop it with status 130 / 143, its temporary files removed (common/atomic_file.h).
inline int RunCommand(const std::string& program, const std::function<int()>& body,
                      const FieldNames& names = {}) {
  InstallInterruptHandler(program);
  try {
    return body();
  } catch (const InputError& e) {
    std::cerr << program << ": error: " << InUserTerms(e.what(), names) << "\n";
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
