#pragma once
// Runs commands and node executables (with this test's master) until they exit: for start-up
// error tests and command-line checks.

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace norm2tex {
namespace test {

/// Runs a shell command; returns its exit status and appends what it printed (both streams).
inline int runCommand(const std::string& command, std::string& output) {
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return -1;
  char buffer[4096];
  while (fgets(buffer, sizeof buffer, pipe)) output += buffer;
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// Runs `executable` with `args` under a fresh node name (private _params stay on the parameter
/// server, so every run needs its own); returns its exit status and appends what it printed.
inline int runNodeUntilExit(const std::string& executable, const std::string& args,
                            std::string& output) {
  static int run = 0;
  return runCommand(executable + " __name:=bad_input_" + std::to_string(run++) + " " + args,
                    output);
}

}  // namespace test
}  // namespace norm2tex
