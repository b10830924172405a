#include "cli_arguments.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace norm2tex {
namespace cli {

Arguments::Arguments(int argc, char** argv, const std::set<std::string>& value_options,
                     const std::set<std::string>& flag_options) {
  for (int i = 1; i < argc; ++i) {
    std::string argument = argv[i];
    if (argument.size() < 2 || argument[0] != '-' || argument == "--" ||
        (argument[1] != '-' && std::isdigit(static_cast<unsigned char>(argument[1])))) {
      positional_.push_back(argument);
      continue;
    }
    std::string name = argument, inline_value;
    const bool has_inline = argument.rfind("--", 0) == 0 && argument.find('=') != std::string::npos;
    if (has_inline) {
      name = argument.substr(0, argument.find('='));
      inline_value = argument.substr(argument.find('=') + 1);
    }
    if (flag_options.count(name)) {
      if (has_inline) throw UsageError(name + " takes no value");
      flags_.insert(name);
    } else if (value_options.count(name)) {
      if (!has_inline) {
        if (i + 1 >= argc) throw UsageError(name + " needs a value");
        inline_value = argv[++i];
      }
      values_[name].push_back(inline_value);
    } else {
      throw UsageError("unknown option " + name);
    }
  }
}

bool Arguments::has(const std::string& name) const { return values_.count(name) > 0; }

std::optional<std::string> Arguments::value(const std::string& name) const {
  const auto it = values_.find(name);
  if (it == values_.end()) return std::nullopt;
  return it->second.back();
}

std::vector<std::string> Arguments::values(const std::string& name) const {
  const auto it = values_.find(name);
  return it == values_.end() ? std::vector<std::string>() : it->second;
}

std::string Arguments::value(const std::string& name, const std::string& fallback) const {
  return value(name).value_or(fallback);
}

double Arguments::number(const std::string& name, double fallback) const {
  const auto text = value(name);
  if (!text) return fallback;
  char* end = nullptr;
  const double parsed = std::strtod(text->c_str(), &end);
  if (text->empty() || *end != '\0' || !std::isfinite(parsed)) {
    throw UsageError(name + " expects a number, got '" + *text + "'");
  }
  return parsed;
}

int Arguments::integer(const std::string& name, int fallback) const {
  const double parsed = number(name, fallback);
  if (parsed != std::floor(parsed) || std::abs(parsed) > 1e9) {
    throw UsageError(name + " expects an integer, got '" + *value(name) + "'");
  }
  return static_cast<int>(parsed);
}

bool asksForHelp(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "-h") == 0 || std::strcmp(argv[i], "--help") == 0) return true;
  }
  return false;
}

int runMain(const char* name, const char* usage, int (*run)(int, char**), int argc, char** argv) {
  // Help is asked for, not a mistake: the usage on stdout and success, before any option is
  // checked (so `tool --help` works whatever else is on the line).
  if (asksForHelp(argc, argv)) {
    std::fputs(usage, stdout);
    return 0;
  }
  try {
    return run(argc, argv);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "%s: %s\n%s", name, e.what(), usage);
    return 2;
  } catch (const std::exception& e) {
    std::string reason = e.what();  // one line, even when OpenCV's message has several
    for (char& c : reason) c = (c == '\n' || c == '\r') ? ' ' : c;
    std::fprintf(stderr, "%s: error: %s\n", name, reason.c_str());
    return 1;
  }
}

}  // namespace cli
}  // namespace norm2tex
