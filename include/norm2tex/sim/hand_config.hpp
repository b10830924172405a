#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "norm2tex/sim/hand_description.hpp"

namespace norm2tex {

/// A DIGIT mounted on a link of the hand.
struct SensorMount {
  std::string name;  ///< topic namespace and TF frame prefix: <name>_gel
  std::string link;
  /// The DIGIT's own frame in the link frame, in TACTO's convention: the camera looks along
  /// its +x, the gel's centre on its surface, 20 mm wide along y and 30 mm tall along z.
  /// Default: TACTO's DIGIT link, (0.022, 0, 0.015) with no rotation.
  Eigen::Isometry3d digit_in_link = Eigen::Isometry3d(Eigen::Translation3d(0.022, 0.0, 0.015));
  bool gel_given = false;   ///< the yaml gave `gel` (else TACTO's default)
  std::string sensor_yaml;  ///< optional sensor model (resolved path), empty: the shipped one
};

/// How a joint's drive behaves; a value < 0 is "not given" (the URDF's, or the default's).
struct JointDriveOptions {
  double effort = -1.0;     ///< force (N) or torque (N m) limit of the drive
  double velocity = -1.0;   ///< speed limit, m/s or rad/s
  double stiffness = -1.0;  ///< series compliance, N/m or N m/rad; 0 = rigid
};

/// The hand yaml (docs/hands.md): the URDF, where the hand stands, its DIGITs, its drives.
struct HandConfig {
  std::string urdf_path;  ///< resolved against the yaml's folder
  std::string root_link;  ///< empty: the URDF's root
  /// The root link's pose in the world (yaml: [x, y, z, roll, pitch, yaw], m and rad).
  Eigen::Isometry3d base_pose = Eigen::Isometry3d::Identity();
  PackagePaths package_paths;  ///< hand.package_paths (relative to the yaml) + ROS_PACKAGE_PATH
  std::vector<SensorMount> sensors;
  /// joints.default and joints.<name>: the drive of every joint, and per joint.
  JointDriveOptions default_drive;
  std::map<std::string, JointDriveOptions> drives;
  /// initial_positions.<joint>: where a joint starts (rad or m); others start at 0 clamped to
  /// their limits.
  std::map<std::string, double> initial_positions;
  /// gripper.joints: the joints a parallel GripperCommand drives (two-finger hands), and their
  /// positions at opening 0 (closed) and 1 (open).
  std::vector<std::string> gripper_joints;
  std::vector<double> gripper_closed;
  std::vector<double> gripper_open;
};

/// Reads a hand yaml. Every key is optional but hand.urdf and sensors; unknown keys are errors
/// naming the key and the valid ones. Throws Error naming the file and the key at fault.
HandConfig loadHandConfig(const std::string& yaml_path);
/// loadHandConfig of yaml text already read: `source` names it in messages, relative paths
/// (hand.urdf, package_paths, sensor yamls) are resolved against `base_dir`.
HandConfig parseHandConfig(const std::string& yaml_text, const std::string& source,
                           const std::string& base_dir);

/// Pose from [x, y, z, roll, pitch, yaw] (URDF's fixed-axis rpy: R = Rz(yaw) Ry(pitch) Rx(roll)).
Eigen::Isometry3d poseFromXyzRpy(const std::vector<double>& xyz_rpy);

/// The gel frame (the renderer's: +x image right, +y image down, +z out of the gel) in the
/// DIGIT's TACTO frame: the gel's normal is the DIGIT's +x, image down is its -z (towards the
/// sensor's base, where it is mounted), image right its -y.
Eigen::Isometry3d gelInDigit();

}  // namespace norm2tex
