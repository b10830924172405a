#pragma once
// Private to norm2tex_sim: what the config readers share.

#include <set>
#include <string>

#include <yaml-cpp/yaml.h>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace detail {

/// A misspelled key must not silently keep a default: throws Error naming the first key of
/// `section` that is not in `keys`, and the valid ones. `name` prefixes the key ("" at the top).
inline void requireKnownKeys(const YAML::Node& section, const std::string& name,
                             const std::set<std::string>& keys) {
  if (!section) return;
  if (!section.IsMap()) throw Error(name + " must be a map");
  for (const auto& entry : section) {
    const std::string key = entry.first.as<std::string>();
    if (!keys.count(key)) {
      std::string valid;
      for (const std::string& k : keys) valid += (valid.empty() ? "" : ", ") + k;
      throw Error((name.empty() ? "" : name + ".") + key + " is not a known key; valid: " + valid);
    }
  }
}

}  // namespace detail
}  // namespace norm2tex
