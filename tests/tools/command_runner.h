#pragma once
// Runs one of the project's command-line programs as a user would, for the CLI tests.
#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace specimen::testing {

struct CommandResult {
  int status = -1;     // exit status (-1: killed by a signal)
  std::string output;  // stdout and stderr
};

// `program` is the name under build/tools, e.g. "generate-packing"; --quiet is appended.
inline CommandResult RunProgram(const std::string& program, const std::string& arguments) {
  const std::string command =
      std::string(SPECIMEN_BINARY_DIR) + "/tools/" + program + " " + arguments + " --quiet 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  char buffer[4096];
  while (fgets(buffer, sizeof(buffer), pipe)) result.output += buffer;
  const int raw = pclose(pipe);
  result.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return result;
}

}  // namespace specimen::testing
