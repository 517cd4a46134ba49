#pragma once
// Runs one of the project's command-line programs as a user would, for the CLI tests.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

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

// Starts `program` with `arguments` (and --quiet), sends it `signal_number` after
// `delay_s`, and waits for it. `log` receives its stdout and stderr.
inline CommandResult RunProgramInterrupted(const std::string& program, const std::string& arguments,
                                           int signal_number, double delay_s, const std::string& log) {
  const std::string command =
      "exec " + std::string(SPECIMEN_BINARY_DIR) + "/tools/" + program + " " + arguments + " --quiet > " + log + " 2>&1";
  CommandResult result;
  const pid_t pid = fork();
  if (pid < 0) return result;
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  std::this_thread::sleep_for(std::chrono::duration<double>(delay_s));
  kill(pid, signal_number);
  int raw = 0;
  waitpid(pid, &raw, 0);
  result.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  result.output = text.str();
  return result;
}

}  // namespace specimen::testing
