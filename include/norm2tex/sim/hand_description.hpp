#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace norm2tex {

/// One collision element of a link, in the link frame.
struct HandCollision {
  enum class Kind { kBox, kCylinder, kSphere, kMesh };
  Kind kind = Kind::kBox;
  /// kBox: full sizes x, y, z; kCylinder: (radius, length, 0) along the element's z;
  /// kSphere: (radius, 0, 0); kMesh: unused.
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  std::string mesh_path;  ///< kMesh: the resolved file
  Eigen::Vector3d mesh_scale = Eigen::Vector3d::Ones();
  /// kMesh: the file's vertices (loaded with the package's mesh loader), scaled, in metres, in
  /// the element's frame.
  std::vector<Eigen::Vector3d> mesh_vertices;
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
};

struct HandLink {
  std::string name;
  double mass_kg = 0.0;
  /// Inertial frame (centre of mass and principal axes' frame) in the link frame.
  Eigen::Isometry3d inertial_origin = Eigen::Isometry3d::Identity();
  /// Inertia about the centre of mass, in the inertial frame, kg m^2.
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  /// The URDF's inertia was implausible for the link and was replaced (see loadHandDescription).
  bool inertia_replaced = false;
  std::vector<HandCollision> collisions;
  int parent_joint = -1;  ///< index into HandDescription::joints; -1 for the root
};

struct HandJoint {
  enum class Type { kRevolute, kContinuous, kPrismatic, kFixed };
  std::string name;
  Type type = Type::kFixed;
  int parent_link = -1;
  int child_link = -1;
  /// The child link's frame in the parent link's frame at joint position 0.
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();  ///< unit, in the child (= joint) frame
  /// Position limits (rad or m); +-infinity for a continuous joint.
  double lower = 0.0;
  double upper = 0.0;
  double effort = 0.0;    ///< N or N m; 0 when the URDF gives none (the hand yaml then must)
  double velocity = 0.0;  ///< m/s or rad/s; 0 when the URDF gives none
  /// Mimic: position = multiplier * master's position + offset (master < 0: none).
  int mimic_master = -1;
  double mimic_multiplier = 1.0;
  double mimic_offset = 0.0;

  bool movable() const { return type != Type::kFixed; }
};

/// A hand (or any kinematic tree) read from a URDF: its links ordered parents first (links[0]
/// is the root), joints ordered likewise (joints[i] leads to one link), every length in metres.
struct HandDescription {
  std::string name;
  std::vector<HandLink> links;
  std::vector<HandJoint> joints;
  /// What loading changed or ignored (duplicated tags, replaced inertias, left-out links), one
  /// line each, for the user to read.
  std::vector<std::string> warnings;
  /// The URDF text as read.
  std::string urdf_xml;
  /// The same with every mesh file name resolved to an absolute `file://` URI (what
  /// /robot_description carries: rviz finds the meshes without the hand yaml's package_paths).
  std::string resolved_urdf_xml;

  /// Index of a link or joint by name, -1 when absent.
  int linkIndex(const std::string& name) const;
  int jointIndex(const std::string& name) const;
};

/// Where `package://NAME/...` URIs are looked for.
struct PackagePaths {
  /// Explicit map, tried first: package name -> folder.
  std::map<std::string, std::string> explicit_paths;
  /// Also search ROS_PACKAGE_PATH (folders holding NAME/package.xml, or named NAME).
  bool use_ros_package_path = true;
};

/// Resolves a URDF file name: `package://NAME/rest` through `paths`, `file://` and absolute
/// paths as they are, relative ones against `base_dir`. Throws Error naming the package and
/// every place looked in when it cannot be found.
std::string resolveUri(const std::string& uri, const std::string& base_dir,
                       const PackagePaths& paths);

/// Loads a hand from URDF with urdfdom. `root_link` (optional) keeps only that link's subtree
/// (a whole robot's URDF with the hand at its tip). Mesh collision files are resolved and loaded
/// (TexturedMesh::load). Messy files are accepted with a warning each: a tag given twice in a joint
/// or link (the first is used, as urdfdom does), `<gazebo>`, `<transmission>` and other unknown
/// blocks (ignored without a word), and an inertia that is not a solid's of the link's mass within
/// its collision geometry's bounding box (principal moments outside [I_min / 10, 10 I_max] of that
/// box's, or violating the triangle inequality) is replaced by the bounding box's inertia.
/// Throws Error for: an unreadable file, XML that is not well formed (with its line), a URDF
/// urdfdom refuses (its reason), floating or planar joints, an unknown root_link, a mimic joint
/// whose master is missing, and a mesh file that is missing or unreadable.
HandDescription loadHandDescription(const std::string& urdf_path, const PackagePaths& paths,
                                    const std::string& root_link = "");

/// loadHandDescription of URDF text already read: `source` names it in messages (a file name),
/// relative mesh file names are resolved against `base_dir`.
HandDescription parseHandDescription(const std::string& urdf_xml, const std::string& source,
                                     const std::string& base_dir, const PackagePaths& paths,
                                     const std::string& root_link = "");

}  // namespace norm2tex
