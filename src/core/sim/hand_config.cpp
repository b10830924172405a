#include "norm2tex/sim/hand_config.hpp"

#include <cmath>
#include <filesystem>
#include <set>

#include <yaml-cpp/yaml.h>

#include "norm2tex/common/error.hpp"
#include "sim/yaml_keys.hpp"

namespace fs = std::filesystem;

namespace norm2tex {
namespace {

using detail::requireKnownKeys;

std::string resolvePath(const std::string& path, const fs::path& base) {
  if (path.empty() || fs::path(path).is_absolute()) return path;
  std::string out = (base / path).lexically_normal().string();
  if (out.size() > 1 && out.back() == '/') out.pop_back();  // "." -> the folder itself
  return out;
}

std::vector<double> readNumbers(const YAML::Node& node, const std::string& key, size_t count) {
  const auto values = node.as<std::vector<double>>();
  if (values.size() != count) {
    throw Error(key + " needs " + std::to_string(count) + " numbers, got " +
                std::to_string(values.size()));
  }
  for (double v : values) {
    if (!std::isfinite(v)) throw Error(key + " has a value that is not finite");
  }
  return values;
}

JointDriveOptions readDrive(const YAML::Node& node, const std::string& key) {
  requireKnownKeys(node, key, {"effort", "velocity", "stiffness"});
  JointDriveOptions drive;
  const auto positive = [&](const char* name, double& value, bool zero_ok) {
    if (!node[name]) return;
    value = node[name].as<double>();
    if (!(std::isfinite(value) && (zero_ok ? value >= 0.0 : value > 0.0))) {
      throw Error(key + "." + name + " = " + node[name].as<std::string>() +
                  " is out of range; valid: " + (zero_ok ? ">= 0" : "> 0"));
    }
  };
  positive("effort", drive.effort, false);
  positive("velocity", drive.velocity, false);
  positive("stiffness", drive.stiffness, true);
  return drive;
}

/// The hand yaml's keys from its parsed document; `yaml_path` names it in messages, relative
/// paths are resolved against `base`.
HandConfig readHandConfig(const YAML::Node& root, const std::string& yaml_path,
                          const fs::path& base);

}  // namespace

Eigen::Isometry3d poseFromXyzRpy(const std::vector<double>& v) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  pose.linear() = (Eigen::AngleAxisd(v[5], Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(v[4], Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(v[3], Eigen::Vector3d::UnitX()))
                      .toRotationMatrix();
  return pose;
}

Eigen::Isometry3d gelInDigit() {
  // Columns: the gel's x (image right), y (image down), z (out of the gel), in the DIGIT frame.
  Eigen::Matrix3d r;
  r << 0, 0, 1,  //
      -1, 0, 0,  //
      0, -1, 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = r;
  return pose;
}

HandConfig loadHandConfig(const std::string& yaml_path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(yaml_path);
  } catch (const YAML::Exception& e) {
    throw Error("hand config '" + yaml_path + "': " + e.what());
  }
  return readHandConfig(root, yaml_path, fs::absolute(fs::path(yaml_path)).parent_path());
}

HandConfig parseHandConfig(const std::string& yaml_text, const std::string& source,
                           const std::string& base_dir) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw Error("hand config '" + source + "': " + e.what());
  }
  return readHandConfig(root, source, fs::absolute(fs::path(base_dir)));
}

namespace {

HandConfig readHandConfig(const YAML::Node& root, const std::string& yaml_path,
                          const fs::path& base) {
  try {
    HandConfig c;
    if (!root.IsMap()) throw Error("must be a map with hand and sensors");
    requireKnownKeys(root, "", {"hand", "sensors", "joints", "initial_positions", "gripper"});
    const YAML::Node hand = root["hand"];
    if (!hand || !hand["urdf"]) throw Error("hand.urdf is required");
    requireKnownKeys(hand, "hand", {"urdf", "root_link", "base_pose", "package_paths"});
    c.urdf_path = resolvePath(hand["urdf"].as<std::string>(), base);
    if (hand["root_link"]) c.root_link = hand["root_link"].as<std::string>();
    if (hand["base_pose"])
      c.base_pose = poseFromXyzRpy(readNumbers(hand["base_pose"], "hand.base_pose", 6));
    if (hand["package_paths"]) {
      if (!hand["package_paths"].IsMap())
        throw Error("hand.package_paths must map package names to folders");
      for (const auto& entry : hand["package_paths"]) {
        c.package_paths.explicit_paths[entry.first.as<std::string>()] =
            resolvePath(entry.second.as<std::string>(), base);
      }
    }

    const YAML::Node sensors = root["sensors"];
    if (!sensors || !sensors.IsSequence() || sensors.size() == 0) {
      throw Error("sensors is required: a list of {name, link[, gel, sensor]}");
    }
    std::set<std::string> names;
    for (size_t i = 0; i < sensors.size(); ++i) {
      const std::string key = "sensors[" + std::to_string(i) + "]";
      const YAML::Node s = sensors[i];
      requireKnownKeys(s, key, {"name", "link", "gel", "sensor"});
      if (!s["name"] || !s["link"]) throw Error(key + " needs a name and a link");
      SensorMount mount;
      mount.name = s["name"].as<std::string>();
      mount.link = s["link"].as<std::string>();
      // A ROS name: it becomes a topic namespace and a TF frame prefix.
      const bool valid_name =
          !mount.name.empty() && std::isalpha(static_cast<unsigned char>(mount.name[0])) &&
          mount.name.find_first_not_of(
              "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") ==
              std::string::npos;
      if (!valid_name)
        throw Error(key + ".name '" + mount.name +
                    "' is not a valid ROS name (a letter, then letters, digits, _)");
      if (!names.insert(mount.name).second)
        throw Error(key + ".name '" + mount.name + "' is used twice");
      if (s["gel"]) {
        mount.digit_in_link = poseFromXyzRpy(readNumbers(s["gel"], key + ".gel", 6));
        mount.gel_given = true;
      }
      if (s["sensor"]) mount.sensor_yaml = resolvePath(s["sensor"].as<std::string>(), base);
      c.sensors.push_back(mount);
    }

    const YAML::Node joints = root["joints"];
    if (joints) {
      if (!joints.IsMap())
        throw Error("joints must map joint names (or default) to {effort, velocity, stiffness}");
      for (const auto& entry : joints) {
        const std::string name = entry.first.as<std::string>();
        const JointDriveOptions drive = readDrive(entry.second, "joints." + name);
        if (name == "default") {
          c.default_drive = drive;
        } else {
          c.drives[name] = drive;
        }
      }
    }
    const YAML::Node initial = root["initial_positions"];
    if (initial) {
      if (!initial.IsMap()) throw Error("initial_positions must map joint names to positions");
      for (const auto& entry : initial) {
        const double value = entry.second.as<double>();
        if (!std::isfinite(value))
          throw Error("initial_positions." + entry.first.as<std::string>() + " is not finite");
        c.initial_positions[entry.first.as<std::string>()] = value;
      }
    }
    const YAML::Node gripper = root["gripper"];
    if (gripper) {
      requireKnownKeys(gripper, "gripper", {"joints", "closed", "open"});
      if (!gripper["joints"] || !gripper["closed"] || !gripper["open"]) {
        throw Error("gripper needs joints, closed and open (one position per joint)");
      }
      c.gripper_joints = gripper["joints"].as<std::vector<std::string>>();
      c.gripper_closed = readNumbers(gripper["closed"], "gripper.closed", c.gripper_joints.size());
      c.gripper_open = readNumbers(gripper["open"], "gripper.open", c.gripper_joints.size());
    }
    return c;
  } catch (const YAML::Exception& e) {
    throw Error("hand config '" + yaml_path + "': " + e.what());
  } catch (const Error& e) {
    throw Error("hand config '" + yaml_path + "': " + e.what());
  }
}

}  // namespace

}  // namespace norm2tex
