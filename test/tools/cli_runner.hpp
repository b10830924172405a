#pragma once
// Runs a command-line tool in a shell and captures its exit code and combined output.

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace norm2tex {
namespace test {

struct CliRun {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

inline CliRun runCommand(const std::string& executable, const std::string& arguments) {
  const std::string command = executable + " " + arguments + " 2>&1";
  CliRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  char buffer[4096];
  while (fgets(buffer, sizeof(buffer), pipe) != nullptr) run.output += buffer;
  const int status = pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

}  // namespace test
}  // namespace norm2tex
