#pragma once
// Runs a node's executable (with this test's master) until it exits: for start-up error tests.

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace norm2tex {
namespace test {

/// Runs `executable` with `args` under a fresh node name (private _params stay on the parameter
/// server, so every run needs its own); returns its exit status and appends what it printed.
inline int runNodeUntilExit(const std::string& executable, const std::string& args,
                            std::string& output) {
  static int run = 0;
  const std::string command =
      executable + " __name:=bad_input_" + std::to_string(run++) + " " + args + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return -1;
  char buffer[4096];
  while (fgets(buffer, sizeof buffer, pipe)) output += buffer;
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace test
}  // namespace norm2tex
