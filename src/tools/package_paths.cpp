#include "package_paths.hpp"

#include <cstdlib>
#include <filesystem>

#include "norm2tex/common/error.hpp"
#include "norm2tex/materials/procedural_material.hpp"

namespace norm2tex {
namespace cli {

namespace {

/// <prefix>/share/norm2tex/config for a program running as <prefix>/lib/norm2tex/<name>; empty
/// when the executable's path cannot be read.
std::filesystem::path configBesideExecutable() {
  std::error_code error;
  const std::filesystem::path executable = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) return {};
  return executable.parent_path().parent_path().parent_path() / "share" / "norm2tex" / "config";
}

}  // namespace

std::string configDirectory() {
  if (const char* dir = std::getenv("NORM2TEX_CONFIG_DIR"); dir && *dir) return dir;
  const std::filesystem::path installed = configBesideExecutable();
  if (!installed.empty() && std::filesystem::is_directory(installed)) return installed.string();
  for (const char* candidate : {NORM2TEX_SOURCE_CONFIG_DIR, NORM2TEX_INSTALL_CONFIG_DIR}) {
    if (std::filesystem::is_directory(candidate)) return candidate;
  }
  throw Error("cannot find norm2tex's config directory; set NORM2TEX_CONFIG_DIR");
}

std::string materialConfigPath(const std::string& name) {
  const std::string path = configDirectory() + "/materials/" + name + ".yaml";
  if (!std::filesystem::exists(path)) makeMaterial(name);  // unknown: the registry lists names
  return path;
}

}  // namespace cli
}  // namespace norm2tex
