#include "launch_end.hpp"

#include <signal.h>
#include <unistd.h>

#include <fstream>
#include <string>
#include <vector>

namespace norm2tex {
namespace {

/// The words of a process's command line (NUL-separated in /proc).
std::vector<std::string> commandLineOf(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/cmdline", std::ios::binary);
  std::vector<std::string> words;
  std::string word;
  while (std::getline(in, word, '\0')) words.push_back(word);
  return words;
}

std::string baseName(const std::string& path) { return path.substr(path.rfind('/') + 1); }

/// roslaunch runs as "python3 /usr/bin/roslaunch ..." or as the script itself. rostest, which
/// also starts nodes, is not one: it is running tests and must not be stopped this way.
bool isRoslaunch(const std::vector<std::string>& words) {
  for (std::size_t i = 0; i < words.size() && i < 2; ++i) {
    if (baseName(words[i]) == "roslaunch") return true;
  }
  return false;
}

}  // namespace

bool endParentLaunch() {
  const pid_t parent = getppid();
  if (parent <= 1 || !isRoslaunch(commandLineOf(parent))) return false;
  return kill(parent, SIGINT) == 0;
}

}  // namespace norm2tex
