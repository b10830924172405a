#pragma once
// Helpers shared by the nodes' parameter readers: package files and one error format.

#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include <ros/node_handle.h>

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

/// What a parameter of type T must be, for readParam's error.
template <typename T>
std::string expectedType() {
  if (std::is_same<T, bool>::value) return "true or false";
  if (std::is_integral<T>::value) return "an integer";
  if (std::is_floating_point<T>::value) return "a number";
  if (std::is_same<T, std::string>::value) return "a string";
  if (std::is_same<T, std::vector<std::string>>::value) return "a list of strings";
  return "a value of the parameter's type";
}

template <typename T>
struct Identity {
  using type = T;
};

/// nh.param(name, value, fallback), except that a parameter set to something that is not a T
/// (`_beta:=.nan` sets the string ".nan"; a number where a name belongs) is a badParameter
/// error naming it, where roscpp would silently take the fallback. An integer is a number
/// (roscpp converts it); a number where an integer belongs is rounded, as roscpp does.
template <typename T>
void readParam(const ros::NodeHandle& nh, const std::string& name, T& value,
               const typename Identity<T>::type& fallback) {
  if (!nh.hasParam(name)) {
    value = fallback;
    return;
  }
  if (nh.getParam(name, value)) return;
  XmlRpc::XmlRpcValue raw;
  nh.getParam(name, raw);
  std::ostringstream shown;
  raw.write(shown);
  badParameter(name, shown.str(), expectedType<T>());
}

/// config/materials/<material>.yaml of the package; throws badParameter("material", ...) listing
/// the shipped materials when there is no such file. `alternatives` is appended to that list.
std::string materialConfigPath(const std::string& material, const std::string& alternatives = "");

}  // namespace ros_params
}  // namespace norm2tex
