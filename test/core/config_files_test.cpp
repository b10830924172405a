// Every shipped yaml under config/ loads with its loader and validates (as cartographer's
// configuration_files_test does): a yaml nobody loads, or one a loader rejects, fails here.
// Shipped Python scripts start with a shebang that honours the user's environment.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/gripper_sim_config.hpp"
#include "norm2tex/sim/hand_sim.hpp"

namespace norm2tex {
namespace {

TEST(ConfigFilesTest, EveryShippedYamlLoads) {
  const std::filesystem::path config = std::filesystem::path(NORM2TEX_SOURCE_DIR) / "config";
  int loaded = 0, sensors = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(config)) {
    if (entry.path().extension() != ".yaml") continue;
    const std::string path = entry.path().string();
    const std::string folder = entry.path().parent_path().filename().string();
    SCOPED_TRACE(path);
    if (folder == "materials") {
      EXPECT_NO_THROW(loadMaterialConfig(path));
    } else if (folder == "scenes") {
      EXPECT_NO_THROW(loadGripperSimConfig(path));
    } else if (folder == "hands") {
      // A hand yaml, its URDF and every mesh it names: the whole hand builds.
      EXPECT_NO_THROW({
        HandSimConfig hand;
        hand.hand = loadHandConfig(path);
        HandSim sim(hand);
      });
    } else if (folder == "config") {
      // The sensor yamls (digit.yaml, gelsight_mini.yaml) sit at the top.
      EXPECT_NO_THROW(loadSensorModel(path));
      ++sensors;
    } else {
      ADD_FAILURE() << "no loader knows " << path << ": add it to this test";
    }
    ++loaded;
  }
  EXPECT_GE(sensors, 2);  // digit, gelsight_mini
  EXPECT_GE(loaded, 10);  // and 5 materials, 2 scenes, the built-in hand
}

// Shipped Python scripts run on the user's python3, found on PATH: `#!/usr/bin/python3` would
// bypass the venv or conda environment where ROS 1 users on Ubuntu 20.04 pip-install torch.
TEST(ConfigFilesTest, PythonScriptsRunOnThePythonOnPath) {
  int scripts = 0;
  for (const char* folder : {"scripts", "python", "test/python"}) {
    const std::filesystem::path root = std::filesystem::path(NORM2TEX_SOURCE_DIR) / folder;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
      if (!entry.is_regular_file()) continue;
      std::ifstream file(entry.path());
      std::string first_line;
      std::getline(file, first_line);
      if (first_line.rfind("#!", 0) != 0 || first_line.find("python") == std::string::npos) {
        continue;
      }
      EXPECT_EQ(first_line, "#!/usr/bin/env python3") << entry.path();
      ++scripts;
    }
  }
  EXPECT_GE(scripts, 4);  // merge_dataset, train_material_classifier, junit_summary.py, free_port
}

}  // namespace
}  // namespace norm2tex
