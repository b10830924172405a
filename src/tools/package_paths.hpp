#pragma once

#include <string>

namespace norm2tex {
namespace cli {

/// The package's config/ directory: $NORM2TEX_CONFIG_DIR; else share/norm2tex/config of the
/// prefix the running program is installed in (<prefix>/lib/norm2tex/<tool>), so an install
/// space or a binary package uses its own files wherever it was moved; else the source tree the
/// tools were built from (devel space); else the configured install space. Throws Error if none
/// exists.
std::string configDirectory();

/// config/materials/NAME.yaml; throws Error listing the valid material names if NAME is unknown.
std::string materialConfigPath(const std::string& name);

}  // namespace cli
}  // namespace norm2tex
