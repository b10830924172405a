#include "cli_arguments.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <utility>
#include <vector>

namespace norm2tex {
namespace cli {

namespace {

// Where positional arguments beyond the declared ones land, to be refused by name.
constexpr const char* kUnexpected = "norm2tex-unexpected-argument";

// Help is printed 100 columns wide (the sources' width); option descriptions start at column 40
// at most, so a long option name does not squeeze its description into a narrow column.
constexpr unsigned kLineLength = 100;
constexpr unsigned kMinDescriptionLength = 60;

std::string optionName(const std::string& key) { return (key.size() == 1 ? "-" : "--") + key; }

std::string shortNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

/// Boost's lexical_cast reads "nan" and "inf" as doubles; no option of the package takes them.
void requireFinite(const po::variables_map& args) {
  for (const auto& [key, value] : args) {
    std::vector<double> numbers;
    if (const auto* number = boost::any_cast<double>(&value.value())) {
      numbers.push_back(*number);
    } else if (const auto* list = boost::any_cast<std::vector<double>>(&value.value())) {
      numbers = *list;
    }
    for (const double number : numbers) {
      if (!std::isfinite(number)) {
        throw UsageError(optionName(key) + " expects a finite number, got '" + shortNumber(number) +
                         "'");
      }
    }
  }
}

/// One line, even when a library's message has several.
std::string oneLine(std::string text) {
  for (char& c : text) c = (c == '\n' || c == '\r') ? ' ' : c;
  return text;
}

}  // namespace

Program::Program(std::string name, std::string synopsis, std::string description)
    : name_(std::move(name)),
      synopsis_(std::move(synopsis)),
      description_(std::move(description)),
      options_("options", kLineLength, kMinDescriptionLength) {
  options_.add_options()("help,h", "Print this help and exit.");
}

Program& Program::positional(const std::string& name, int count,
                             const po::value_semantic* semantic) {
  hidden_.add_options()(name.c_str(), semantic);
  positional_.add(name.c_str(), count);
  positional_names_.push_back(name);
  takes_the_rest_ = count < 0;
  return *this;
}

Program& Program::notes(std::string text) {
  notes_ = std::move(text);
  return *this;
}

std::string Program::usage() const { return "usage: " + synopsis_ + "\n"; }

std::string Program::help() const {
  std::ostringstream out;
  out << usage() << "\n" << description_ << "\n\n" << options_;
  if (!notes_.empty()) out << "\n" << notes_ << "\n";
  return out.str();
}

po::variables_map Program::parse(int argc, const char* const* argv) const {
  po::options_description all;
  all.add(options_).add(hidden_);
  po::positional_options_description positional = positional_;
  if (!takes_the_rest_) {
    all.add_options()(kUnexpected, po::value<std::vector<std::string>>());
    positional.add(kUnexpected, -1);
  }
  // Exact option names only: an abbreviation that works today would change meaning (or become
  // ambiguous) when an option is added.
  const int style = po::command_line_style::unix_style & ~po::command_line_style::allow_guessing;
  po::variables_map args;
  try {
    po::store(
        po::command_line_parser(argc, argv).options(all).positional(positional).style(style).run(),
        args);
  } catch (const po::error& e) {
    // A positional argument is named as the synopsis names it, not as an option.
    std::string message = e.what();
    for (const std::string& name : positional_names_) {
      const std::string as_option = "option '--" + name + "'";
      for (auto at = message.find(as_option); at != std::string::npos;
           at = message.find(as_option)) {
        message.replace(at, as_option.size(), name);
      }
    }
    throw UsageError(message);
  }
  if (args.count(kUnexpected)) {
    throw UsageError("unexpected argument '" +
                     args[kUnexpected].as<std::vector<std::string>>().front() + "'");
  }
  requireFinite(args);
  try {
    po::notify(args);
  } catch (const po::error& e) {
    throw UsageError(e.what());
  }
  return args;
}

int Program::main(int argc, char** argv, const std::function<int(int, char**)>& body) const {
  // Help is asked for, not a mistake: the help on stdout and success, before anything else is
  // checked (so `NAME --help` works whatever else is on the line).
  if (asksForHelp(argc, argv)) {
    std::fputs(help().c_str(), stdout);
    return 0;
  }
  try {
    return body(argc, argv);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "%s: error: %s\n%sRun '%s --help' for every option.\n", name_.c_str(),
                 oneLine(e.what()).c_str(), usage().c_str(), name_.c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", name_.c_str(), oneLine(e.what()).c_str());
    return 1;
  }
}

bool asksForHelp(int argc, const char* const* argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "-h") == 0 || std::strcmp(argv[i], "--help") == 0) return true;
  }
  return false;
}

}  // namespace cli
}  // namespace norm2tex
