// norm2tex_launch_check: checks a launch file's arguments while roslaunch reads the file, before
// any node starts. The launch files run it as a command parameter; a non-zero exit is the one
// way a launch file can make roslaunch itself exit non-zero (roslaunch 1.15 exits 0 after a
// required node died), so what can be checked without the nodes is checked here, with the
// nodes' own messages.
//
//   norm2tex_launch_check --launch NAME [--output-dir DIR [--min-free-mb MB]]
//                         [--file WHAT=PATH ...]
// Prints "ok" on stdout (the parameter's value) and exits 0, or prints one line
// "NAME: <reason>" on stderr and exits 1. An empty PATH means "not given" and is not checked.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include "cli_arguments.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/output_directory.hpp"
#include "norm2tex/mesh/object_mesh.hpp"

namespace {

constexpr const char* kUsage =
    "usage: norm2tex_launch_check --launch NAME [--output-dir DIR [--min-free-mb MB]]\n"
    "                             [--file WHAT=PATH ...]\n";

/// A file a node will read: it must exist, be a regular file and be readable.
void checkInputFile(const std::string& what_and_path) {
  const std::size_t eq = what_and_path.find('=');
  if (eq == std::string::npos) {
    throw norm2tex::cli::UsageError("--file takes WHAT=PATH, got '" + what_and_path + "'");
  }
  const std::string what = what_and_path.substr(0, eq);
  const std::string path = what_and_path.substr(eq + 1);
  // Empty: not given; a mesh may be a primitive ("sphere:45"), made, not read.
  if (path.empty() || (what == "mesh" && norm2tex::isPrimitiveMeshSpec(path))) return;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    throw norm2tex::Error(what + " file '" + path + "' does not exist");
  }
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw norm2tex::Error(what + " file '" + path + "' is not a regular file");
  }
  if (!std::ifstream(path)) throw norm2tex::Error(what + " file '" + path + "' cannot be read");
}

}  // namespace

int main(int argc, char** argv) {
  std::string launch = "norm2tex_launch_check";
  try {
    const norm2tex::cli::Arguments args(
        argc, argv, {"--launch", "--output-dir", "--min-free-mb", "--file"}, {});
    launch = args.value("--launch", launch);
    if (!args.positional().empty()) {
      throw norm2tex::cli::UsageError("unexpected argument '" + args.positional().front() + "'");
    }
    for (const std::string& file : args.values("--file")) checkInputFile(file);
    if (args.has("--output-dir")) {
      norm2tex::checkOutputDirectory(*args.value("--output-dir"),
                                     args.number("--min-free-mb", 0.0));
    }
  } catch (const norm2tex::cli::UsageError& e) {
    std::cerr << launch << ": " << e.what() << "\n" << kUsage;
    return 2;
  } catch (const std::exception& e) {
    std::cerr << launch << ": " << e.what() << std::endl;
    return 1;
  }
  std::cout << "ok" << std::endl;
  return 0;
}
