// Every shipped yaml under config/ loads with its loader and validates (as cartographer's
// configuration_files_test does): a yaml nobody loads, or one a loader rejects, fails here.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/gripper_sim_config.hpp"

namespace norm2tex {
namespace {

TEST(ConfigFilesTest, EveryShippedYamlLoads) {
  const std::filesystem::path config = std::filesystem::path(NORM2TEX_SOURCE_DIR) / "config";
  int loaded = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(config)) {
    if (entry.path().extension() != ".yaml") continue;
    const std::string path = entry.path().string();
    const std::string folder = entry.path().parent_path().filename().string();
    SCOPED_TRACE(path);
    if (folder == "materials") {
      EXPECT_NO_THROW(loadMaterialConfig(path));
    } else if (folder == "scenes") {
      EXPECT_NO_THROW(loadGripperSimConfig(path));
    } else if (entry.path().filename() == "digit.yaml") {
      EXPECT_NO_THROW(loadSensorModel(path));
    } else {
      ADD_FAILURE() << "no loader knows " << path << ": add it to this test";
    }
    ++loaded;
  }
  EXPECT_GE(loaded, 8);  // digit, 5 materials, 2 scenes
}

}  // namespace
}  // namespace norm2tex
