#pragma once

#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace norm2tex {
namespace cli {

/// A mistake on the command line: the tool prints it with its usage and exits with 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Minimal parser: positional arguments, `--name value`, `--name=value` and flags. Unknown
/// options are errors, so a typo never silently falls back to a default.
class Arguments {
 public:
  Arguments(int argc, char** argv, const std::set<std::string>& value_options,
            const std::set<std::string>& flag_options);

  const std::vector<std::string>& positional() const { return positional_; }
  bool has(const std::string& name) const;
  bool flag(const std::string& name) const { return flags_.count(name) > 0; }
  /// The last value given for `name` (options may repeat; see values()).
  std::optional<std::string> value(const std::string& name) const;
  /// Every value given for `name`, in order (empty if none).
  std::vector<std::string> values(const std::string& name) const;
  std::string value(const std::string& name, const std::string& fallback) const;
  /// The option as a finite number, or `fallback` if absent; UsageError if not a number.
  double number(const std::string& name, double fallback) const;
  int integer(const std::string& name, int fallback) const;

 private:
  std::vector<std::string> positional_;
  std::map<std::string, std::vector<std::string>> values_;
  std::set<std::string> flags_;
};

/// True when an argument is exactly `-h` or `--help`.
bool asksForHelp(int argc, char** argv);

/// Runs a tool's `run` and turns what it throws into the tools' shared exit convention:
/// `-h`/`--help` anywhere -> the usage on stdout, exit 0 (run is not called); UsageError ->
/// "<name>: <reason>" plus the usage on stderr, exit 2; any other exception -> one line
/// "<name>: error: <reason>", exit 1.
int runMain(const char* name, const char* usage, int (*run)(int, char**), int argc, char** argv);

}  // namespace cli
}  // namespace norm2tex
