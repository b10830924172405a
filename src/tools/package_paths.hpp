#pragma once

#include <string>

namespace norm2tex {
namespace cli {

/// The package's config/ directory: $NORM2TEX_CONFIG_DIR, else the source tree the tools were
/// built from, else the install space. Throws Error if none exists.
std::string configDirectory();

/// config/materials/NAME.yaml; throws Error listing the valid material names if NAME is unknown.
std::string materialConfigPath(const std::string& name);

}  // namespace cli
}  // namespace norm2tex
