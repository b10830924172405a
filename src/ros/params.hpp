#pragma once
// Helpers shared by the nodes' parameter readers: package files and one error format.

#include <sstream>
#include <string>

namespace norm2tex {
namespace ros_params {

/// ~material's word for "no procedural material" (roslaunch drops empty argument values).
constexpr const char* kNoMaterial = "none";

/// <share of norm2tex>/<relative>.
std::string packageFile(const std::string& relative);

/// Throws Error("~<name> = <value> is not valid; valid: <valid>").
[[noreturn]] void badParameter(const std::string& name, const std::string& value,
                               const std::string& valid);

template <typename T>
std::string text(const T& value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

/// config/materials/<material>.yaml of the package; throws badParameter("material", ...) listing
/// the shipped materials when there is no such file. `alternatives` is appended to that list.
std::string materialConfigPath(const std::string& material, const std::string& alternatives = "");

}  // namespace ros_params
}  // namespace norm2tex
