#pragma once
// The command line of every norm2tex program is parsed by Boost.Program_options; this is the thin
// layer the package adds on top of it: one exit convention and error format, the layout of
// --help, and numbers that must be finite.
//
// Why Boost.Program_options and not CLI11: CLI11 (libcli11-dev) is not packaged for Debian 11
// (bullseye has none; bookworm has 2.1.2, trixie 2.4.1), and rosdep's cli11 key is null on
// Ubuntu 20.04, ROS Noetic's platform; the package builds on both. Boost.Program_options is in
// every release it supports (Boost 1.71 on focal, 1.74 on bullseye and bookworm, 1.83 on trixie),
// and roscpp already brings Boost.
//
// Exit convention of every program: --help (or -h) anywhere on the line prints the help on
// stdout and exits 0; a mistake on the command line (an unknown option, a missing or malformed
// value, a number out of range, a missing argument) prints
//   NAME: error: <what is wrong>
//   usage: <synopsis>
//   Run 'NAME --help' for every option.
// on stderr and exits 2; any other failure prints the one line "NAME: error: <reason>" and exits 1.
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <boost/program_options.hpp>

namespace norm2tex {
namespace cli {

namespace po = boost::program_options;

/// A mistake on the command line: exit status 2, with the synopsis.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A program's command line: its options, its positional arguments and its help.
///
///   Program program("norm2tex_x", "norm2tex_x IN -o OUT [--size PX]", "Does x. ...");
///   program.add()("output,o", po::value<std::string>()->value_name("OUT"), "Where x goes.");
///   program.positional("input", 1, po::value<std::vector<std::string>>());
///   return program.main(argc, argv, [&](int argc, char** argv) {
///     const po::variables_map args = program.parse(argc, argv);
///     ...
///   });
///
/// Options are matched by their exact names (no abbreviations); a value may follow as the next
/// argument or after '=' (`--size 64`, `--size=64`), a negative number too (`--press-mm -1`).
class Program {
 public:
  /// `synopsis`: the usage lines without "usage: " (continuation lines indented as they are to be
  /// printed); `description`: the first paragraph of --help, whole sentences.
  Program(std::string name, std::string synopsis, std::string description);

  /// Declares options, as options_description::add_options() does; -h/--help is declared already.
  po::options_description_easy_init add() { return options_.add_options(); }
  /// The next `count` positional arguments (-1: all the rest) are the values of `name`, as the
  /// synopsis names them (e.g. "FRAMES"), which --help does not list among the options (the
  /// synopsis and description say what they are). Positional arguments beyond the declared ones
  /// are refused, naming the first.
  Program& positional(const std::string& name, int count, const po::value_semantic* semantic);
  /// Paragraphs printed after the options.
  Program& notes(std::string text);

  const std::string& name() const { return name_; }
  /// Usage, description, options and notes.
  std::string help() const;
  /// "usage: " and the synopsis.
  std::string usage() const;

  /// The parsed command line (po::notify done, so values bound to variables are set). Throws
  /// UsageError for anything Boost.Program_options refuses, for a positional argument beyond the
  /// declared ones and for a number that is not finite (Boost takes "nan" and "inf" as doubles).
  po::variables_map parse(int argc, const char* const* argv) const;

  /// Runs `body` under the exit convention above (--help before `body` is called).
  int main(int argc, char** argv, const std::function<int(int, char**)>& body) const;

 private:
  std::string name_, synopsis_, description_, notes_;
  std::vector<std::string> positional_names_;
  po::options_description options_;
  po::options_description hidden_;
  po::positional_options_description positional_;
  bool takes_the_rest_ = false;
};

/// The option's value, or `fallback` when it was not given. T is the option's declared type.
template <typename T>
T valueOr(const po::variables_map& args, const std::string& name, const T& fallback) {
  const auto it = args.find(name);
  return it == args.end() || it->second.empty() ? fallback : it->second.as<T>();
}

/// True when an argument is exactly `-h` or `--help`.
bool asksForHelp(int argc, const char* const* argv);

}  // namespace cli
}  // namespace norm2tex
