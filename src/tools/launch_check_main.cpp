// norm2tex_launch_check: checks a launch file's arguments while roslaunch reads the file, before
// any node starts. The launch files run it as a command parameter; a non-zero exit is the one
// way a launch file can make roslaunch itself exit non-zero (roslaunch 1.15 exits 0 after a
// required node died), so what can be checked without the nodes is checked here, with the
// nodes' own messages.
//
// Its options and exit statuses: norm2tex_launch_check --help.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include "cli_arguments.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/output_directory.hpp"
#include "norm2tex/mesh/object_mesh.hpp"

namespace {

namespace po = norm2tex::cli::po;

norm2tex::cli::Program makeProgram() {
  norm2tex::cli::Program program(
      "norm2tex_launch_check",
      "norm2tex_launch_check --launch NAME [--output-dir DIR [--min-free-mb MB]]\n"
      "                             [--file WHAT=PATH ...]",
      "Checks a launch file's arguments while roslaunch reads the file, before any node starts.\n"
      "It prints \"ok\" on stdout (the value of the parameter that runs it) and exits 0, or\n"
      "prints the one line \"NAME: <reason>\" on stderr and exits 1 (2 for a mistake in its own\n"
      "arguments).");
  program.add()  //
      ("launch", po::value<std::string>()->value_name("NAME"),
       "The launch file, named in every message.")  //
      ("output-dir", po::value<std::string>()->value_name("DIR"),
       "A directory a node will write to: it is made if needed and must be writable.")  //
      ("min-free-mb", po::value<double>()->value_name("MB"),
       "With --output-dir: the free space it must have, MB (default 0).")  //
      ("file", po::value<std::vector<std::string>>()->composing()->value_name("WHAT=PATH"),
       "A file a node will read, repeatable: it must exist, be a regular file and be readable. "
       "An empty PATH means \"not given\" and is not checked, nor is a primitive mesh "
       "(mesh=sphere:45).");
  return program;
}

/// The launch file's name (--launch) read on its own, so that a message about another argument
/// names the launch file too; the program's name when it is not there.
std::string launchName(int argc, char** argv) {
  po::options_description launch_only;
  launch_only.add_options()("launch", po::value<std::string>());
  try {
    po::variables_map args;
    po::store(po::command_line_parser(argc, argv).options(launch_only).allow_unregistered().run(),
              args);
    if (args.count("launch")) return args["launch"].as<std::string>();
  } catch (const po::error&) {
    // The full parse below says what is wrong.
  }
  return "norm2tex_launch_check";
}

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
  const norm2tex::cli::Program program = makeProgram();
  if (norm2tex::cli::asksForHelp(argc, argv)) {
    std::cout << program.help();
    return 0;
  }
  // Messages name the launch file (they are roslaunch's), not this program.
  const std::string launch = launchName(argc, argv);
  try {
    const po::variables_map args = program.parse(argc, argv);
    for (const std::string& file :
         norm2tex::cli::valueOr(args, "file", std::vector<std::string>())) {
      checkInputFile(file);
    }
    if (args.count("output-dir")) {
      norm2tex::checkOutputDirectory(args["output-dir"].as<std::string>(),
                                     norm2tex::cli::valueOr(args, "min-free-mb", 0.0));
    }
  } catch (const norm2tex::cli::UsageError& e) {
    std::cerr << launch << ": " << e.what() << "\n" << program.usage();
    return 2;
  } catch (const std::exception& e) {
    std::cerr << launch << ": " << e.what() << std::endl;
    return 1;
  }
  std::cout << "ok" << std::endl;
  return 0;
}
