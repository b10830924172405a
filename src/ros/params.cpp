#include "params.hpp"

#include <filesystem>

#include <ros/package.h>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace ros_params {

std::string packageFile(const std::string& relative) {
  return ros::package::getPath("norm2tex") + "/" + relative;
}

void badParameter(const std::string& name, const std::string& value, const std::string& valid) {
  throw Error("~" + name + " = " + value + " is not valid; valid: " + valid);
}

std::string materialConfigPath(const std::string& material, const std::string& alternatives) {
  const std::string path = packageFile("config/materials/" + material + ".yaml");
  if (!material.empty() && material.find('/') == std::string::npos &&
      std::filesystem::is_regular_file(path)) {
    return path;
  }
  std::string valid;
  for (const auto& entry : std::filesystem::directory_iterator(packageFile("config/materials"))) {
    if (entry.path().extension() == ".yaml") {
      valid += (valid.empty() ? "" : ", ") + entry.path().stem().string();
    }
  }
  badParameter("material", "'" + material + "'",
               valid + " (config/materials/*.yaml)" + alternatives);
}

}  // namespace ros_params
}  // namespace norm2tex
