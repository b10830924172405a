// loadHandDescription: urdfdom reads the model; tinyxml2 only checks what urdfdom does not
// report (where XML is malformed, tags given twice) so that a messy real URDF loads with a word
// on what was changed, and a broken one fails with its line.
#include "norm2tex/sim/hand_description.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include <console_bridge/console.h>
#include <tinyxml2.h>
#include <urdf_parser/urdf_parser.h>
#include <Eigen/Eigenvalues>

#include "norm2tex/common/error.hpp"
#include "norm2tex/mesh/textured_mesh.hpp"

namespace fs = std::filesystem;

namespace norm2tex {

int HandDescription::linkIndex(const std::string& name) const {
  for (size_t i = 0; i < links.size(); ++i) {
    if (links[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

int HandDescription::jointIndex(const std::string& name) const {
  for (size_t i = 0; i < joints.size(); ++i) {
    if (joints[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

namespace {

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::stringstream stream(text);
  std::string part;
  while (std::getline(stream, part, separator)) {
    if (!part.empty()) parts.push_back(part);
  }
  return parts;
}

std::string readFile(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw Error("cannot read the URDF '" + path + "'");
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

// urdfdom reports why it refuses a file through console_bridge, not through its return value:
// collect those messages for the exception.
class CollectErrors : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) {
      messages_ += (messages_.empty() ? "" : "; ") + text;
    }
  }
  const std::string& messages() const { return messages_; }

 private:
  std::string messages_;
};

// Tags that urdfdom reads once per joint or link: a second one is silently ignored by it.
void warnDuplicatedTags(const tinyxml2::XMLElement& robot, const std::string& urdf_path,
                        std::vector<std::string>& warnings) {
  static const std::set<std::string> kOnce = {"parent",   "child",       "origin",
                                              "axis",     "limit",       "mimic",
                                              "dynamics", "calibration", "safety_controller",
                                              "inertial"};
  for (const tinyxml2::XMLElement* element = robot.FirstChildElement(); element;
       element = element->NextSiblingElement()) {
    const std::string kind = element->Name();
    if (kind != "joint" && kind != "link") continue;
    std::map<std::string, int> count;
    for (const tinyxml2::XMLElement* child = element->FirstChildElement(); child;
         child = child->NextSiblingElement()) {
      const std::string tag = child->Name();
      if (kOnce.count(tag) && ++count[tag] == 2) {
        const char* name = element->Attribute("name");
        std::ostringstream message;
        message << urdf_path << ":" << child->GetLineNum() << ": " << kind << " '"
                << (name ? name : "?") << "' has a second <" << tag
                << ">: the first is used, this one is ignored";
        warnings.push_back(message.str());
      }
    }
  }
}

Eigen::Isometry3d toIsometry(const urdf::Pose& pose) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  t.linear() =
      Eigen::Quaterniond(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z)
          .normalized()
          .toRotationMatrix();
  return t;
}

const char* jointTypeName(int type) {
  switch (type) {
    case urdf::Joint::FLOATING:
      return "floating";
    case urdf::Joint::PLANAR:
      return "planar";
    default:
      return "unknown";
  }
}

// The solid box's inertia about its centre.
Eigen::Vector3d boxMoments(double mass, const Eigen::Vector3d& size) {
  const Eigen::Vector3d s2 = size.cwiseProduct(size);
  return mass / 12.0 * Eigen::Vector3d(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y());
}

// Bounds of the link's collision geometry in the link frame (empty when it has none).
Eigen::AlignedBox3d collisionBounds(const HandLink& link) {
  Eigen::AlignedBox3d bounds;
  const auto add = [&](const Eigen::Isometry3d& origin, const Eigen::Vector3d& p) {
    bounds.extend(origin * p);
  };
  for (const HandCollision& c : link.collisions) {
    if (c.kind == HandCollision::Kind::kMesh) {
      for (const Eigen::Vector3d& v : c.mesh_vertices) add(c.origin, v);
      continue;
    }
    Eigen::Vector3d half = Eigen::Vector3d::Zero();
    if (c.kind == HandCollision::Kind::kBox) half = c.size / 2;
    if (c.kind == HandCollision::Kind::kCylinder) half = {c.size.x(), c.size.x(), c.size.y() / 2};
    if (c.kind == HandCollision::Kind::kSphere) half = Eigen::Vector3d::Constant(c.size.x());
    for (int k = 0; k < 8; ++k) {
      add(c.origin,
          half.cwiseProduct(Eigen::Vector3d(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1)));
    }
  }
  return bounds;
}

// A URDF inertia is plausible when it could be a solid of the link's mass that fits in its
// collision geometry's bounding box: principal moments that satisfy the triangle inequality and
// lie within a factor of 10 of the box's (a solid inside the box has smaller moments than the
// box, hollow or elongated ones are within a few times of them). TACTO's files give 1 kg m^2
// to 0.1 kg fingertips, 10^4 times a 3 cm box's: a body that would barely turn.
void repairInertia(HandLink& link, const std::string& urdf_path,
                   std::vector<std::string>& warnings) {
  const Eigen::AlignedBox3d bounds = collisionBounds(link);
  if (bounds.isEmpty() || !(link.mass_kg > 0.0)) return;
  const Eigen::Vector3d box = boxMoments(link.mass_kg, bounds.sizes());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(link.inertia);
  const Eigen::Vector3d moments = solver.eigenvalues();  // ascending
  const bool finite = link.inertia.allFinite();
  const bool triangle =
      finite && moments(0) + moments(1) >= moments(2) * (1 - 1e-9) && moments(0) > 0.0;
  const bool scale = finite && moments.maxCoeff() <= 10.0 * box.maxCoeff() &&
                     moments.minCoeff() >= 0.1 * box.minCoeff();
  if (triangle && scale) return;
  std::ostringstream message;
  message << urdf_path << ": link '" << link.name << "': inertia (principal moments " << moments(0)
          << ", " << moments(1) << ", " << moments(2) << " kg m^2) is not a solid's of "
          << link.mass_kg << " kg within its collision geometry's " << bounds.sizes().x() * 1e3
          << " x " << bounds.sizes().y() * 1e3 << " x " << bounds.sizes().z() * 1e3
          << " mm bounding box; replaced by that box's (" << box.x() << ", " << box.y() << ", "
          << box.z() << " kg m^2)";
  warnings.push_back(message.str());
  link.inertia = box.asDiagonal();
  link.inertial_origin = Eigen::Isometry3d(Eigen::Translation3d(bounds.center()));
  link.inertia_replaced = true;
}

HandCollision readCollision(const urdf::Collision& collision, const std::string& link_name,
                            const std::string& base_dir, const PackagePaths& paths) {
  HandCollision c;
  c.origin = toIsometry(collision.origin);
  const urdf::Geometry& g = *collision.geometry;
  switch (g.type) {
    case urdf::Geometry::BOX: {
      const auto& box = static_cast<const urdf::Box&>(g);
      c.kind = HandCollision::Kind::kBox;
      c.size = {box.dim.x, box.dim.y, box.dim.z};
      break;
    }
    case urdf::Geometry::CYLINDER: {
      const auto& cylinder = static_cast<const urdf::Cylinder&>(g);
      c.kind = HandCollision::Kind::kCylinder;
      c.size = {cylinder.radius, cylinder.length, 0.0};
      break;
    }
    case urdf::Geometry::SPHERE: {
      c.kind = HandCollision::Kind::kSphere;
      c.size = {static_cast<const urdf::Sphere&>(g).radius, 0.0, 0.0};
      break;
    }
    case urdf::Geometry::MESH: {
      const auto& mesh = static_cast<const urdf::Mesh&>(g);
      c.kind = HandCollision::Kind::kMesh;
      c.mesh_path = resolveUri(mesh.filename, base_dir, paths);
      c.mesh_scale = {mesh.scale.x, mesh.scale.y, mesh.scale.z};
      if (!fs::is_regular_file(c.mesh_path)) {
        throw Error("link '" + link_name + "': collision mesh '" + mesh.filename +
                    "' does not exist (looked for " + c.mesh_path + ")");
      }
      try {
        const TexturedMesh loaded = TexturedMesh::load(c.mesh_path);
        c.mesh_vertices.reserve(loaded.vertices().size());
        for (const Eigen::Vector3f& v : loaded.vertices()) {
          c.mesh_vertices.push_back(v.cast<double>().cwiseProduct(c.mesh_scale));
        }
      } catch (const Error& e) {
        throw Error("link '" + link_name + "': collision mesh: " + e.what());
      }
      break;
    }
    default:
      throw Error("link '" + link_name + "': collision geometry of an unknown type");
  }
  return c;
}

}  // namespace

std::string resolveUri(const std::string& uri, const std::string& base_dir,
                       const PackagePaths& paths) {
  const std::string package_prefix = "package://";
  const std::string file_prefix = "file://";
  if (uri.rfind(file_prefix, 0) == 0) return uri.substr(file_prefix.size());
  if (uri.rfind(package_prefix, 0) != 0) {
    const fs::path path(uri);
    return path.is_absolute() ? uri : (fs::path(base_dir) / path).lexically_normal().string();
  }
  const std::string rest = uri.substr(package_prefix.size());
  const size_t slash = rest.find('/');
  const std::string package = rest.substr(0, slash);
  const std::string inside = slash == std::string::npos ? "" : rest.substr(slash + 1);
  std::vector<std::string> looked;
  const auto found = [&](const fs::path& folder) {
    looked.push_back(folder.string());
    return fs::is_directory(folder);
  };
  const auto explicit_path = paths.explicit_paths.find(package);
  if (explicit_path != paths.explicit_paths.end()) {
    fs::path folder(explicit_path->second);
    if (folder.is_relative()) folder = fs::path(base_dir) / folder;
    if (found(folder)) return (folder / inside).lexically_normal().string();
  }
  if (paths.use_ros_package_path) {
    const char* ros_package_path = std::getenv("ROS_PACKAGE_PATH");
    for (const std::string& root : split(ros_package_path ? ros_package_path : "", ':')) {
      // A package is a folder named like it, at the root or one level down (a workspace's
      // src/ holds packages, ROS_PACKAGE_PATH often names src/ or the package itself).
      const fs::path root_path(root);
      if (root_path.filename() == package && found(root_path)) {
        return (root_path / inside).lexically_normal().string();
      }
      if (found(root_path / package))
        return (root_path / package / inside).lexically_normal().string();
    }
  }
  std::ostringstream message;
  message << "cannot resolve '" << uri << "': package '" << package << "' not found";
  if (looked.empty()) {
    message << " (no package_paths entry for it, ROS_PACKAGE_PATH "
            << (paths.use_ros_package_path ? "empty" : "not searched") << ")";
  } else {
    message << "; looked in:";
    for (const std::string& folder : looked) message << " " << folder;
  }
  message << "; name its folder in the hand yaml's hand.package_paths";
  throw Error(message.str());
}

HandDescription loadHandDescription(const std::string& urdf_path, const PackagePaths& paths,
                                    const std::string& root_link) {
  return parseHandDescription(readFile(urdf_path), urdf_path,
                              fs::absolute(fs::path(urdf_path)).parent_path().string(), paths,
                              root_link);
}

HandDescription parseHandDescription(const std::string& urdf_xml, const std::string& source,
                                     const std::string& base_dir, const PackagePaths& paths,
                                     const std::string& root_link) {
  HandDescription hand;
  hand.urdf_xml = urdf_xml;

  tinyxml2::XMLDocument document;
  if (document.Parse(hand.urdf_xml.c_str(), hand.urdf_xml.size()) != tinyxml2::XML_SUCCESS) {
    std::ostringstream message;
    message << source << ":" << document.ErrorLineNum() << ": not well-formed XML ("
            << document.ErrorName() << ")";
    throw Error(message.str());
  }
  const tinyxml2::XMLElement* robot = document.FirstChildElement("robot");
  if (!robot) throw Error(source + ": not a URDF (no <robot> element)");
  warnDuplicatedTags(*robot, source, hand.warnings);
  {
    // Visual and collision meshes alike: a URI that cannot be resolved is left as it is (a
    // visual mesh the simulation does not need; a collision mesh fails below with the reason).
    tinyxml2::XMLDocument resolved;
    resolved.Parse(hand.urdf_xml.c_str(), hand.urdf_xml.size());
    std::function<void(tinyxml2::XMLElement*)> visit = [&](tinyxml2::XMLElement* element) {
      for (tinyxml2::XMLElement* child = element->FirstChildElement(); child;
           child = child->NextSiblingElement()) {
        const char* filename = child->Attribute("filename");
        if (std::string(child->Name()) == "mesh" && filename) {
          try {
            child->SetAttribute("filename",
                                ("file://" + resolveUri(filename, base_dir, paths)).c_str());
          } catch (const Error&) {
          }
        }
        visit(child);
      }
    };
    visit(resolved.RootElement());
    tinyxml2::XMLPrinter printer;
    resolved.Print(&printer);
    hand.resolved_urdf_xml = printer.CStr();
  }

  CollectErrors errors;
  console_bridge::useOutputHandler(&errors);
  urdf::ModelInterfaceSharedPtr model;
  try {
    model = urdf::parseURDF(hand.urdf_xml);
  } catch (const std::exception& e) {
    console_bridge::restorePreviousOutputHandler();
    throw Error(source + ": invalid URDF: " + e.what());
  }
  console_bridge::restorePreviousOutputHandler();
  if (!model) {
    throw Error(
        source + ": invalid URDF: " +
        (errors.messages().empty() ? std::string("urdfdom refused it") : errors.messages()));
  }
  hand.name = model->getName();

  urdf::LinkConstSharedPtr root = model->getRoot();
  if (!root_link.empty()) {
    root = model->getLink(root_link);
    if (!root) throw Error(source + ": root_link '" + root_link + "' is not a link of the URDF");
  }

  // Breadth first from the root: parents before children, as HandSim's kinematics needs.
  std::vector<urdf::LinkConstSharedPtr> queue{root};
  for (size_t next = 0; next < queue.size(); ++next) {
    const urdf::LinkConstSharedPtr& link = queue[next];
    HandLink out;
    out.name = link->name;
    if (link->inertial) {
      out.mass_kg = link->inertial->mass;
      out.inertial_origin = toIsometry(link->inertial->origin);
      const urdf::Inertial& i = *link->inertial;
      out.inertia << i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz;
    }
    for (const urdf::CollisionSharedPtr& collision : link->collision_array) {
      if (collision && collision->geometry) {
        out.collisions.push_back(readCollision(*collision, link->name, base_dir, paths));
      }
    }
    if (link->collision_array.empty() && link->collision && link->collision->geometry) {
      out.collisions.push_back(readCollision(*link->collision, link->name, base_dir, paths));
    }
    repairInertia(out, source, hand.warnings);
    if (next > 0) {
      const urdf::Joint& j = *link->parent_joint;
      HandJoint joint;
      joint.name = j.name;
      joint.parent_link = hand.linkIndex(j.parent_link_name);
      joint.child_link = static_cast<int>(hand.links.size());
      joint.origin = toIsometry(j.parent_to_joint_origin_transform);
      switch (j.type) {
        case urdf::Joint::REVOLUTE:
          joint.type = HandJoint::Type::kRevolute;
          break;
        case urdf::Joint::CONTINUOUS:
          joint.type = HandJoint::Type::kContinuous;
          break;
        case urdf::Joint::PRISMATIC:
          joint.type = HandJoint::Type::kPrismatic;
          break;
        case urdf::Joint::FIXED:
          joint.type = HandJoint::Type::kFixed;
          break;
        default:
          throw Error(source + ": joint '" + j.name + "' is " + jointTypeName(j.type) +
                      ": a hand's joints are revolute, continuous, prismatic or fixed");
      }
      if (joint.movable()) {
        const Eigen::Vector3d axis(j.axis.x, j.axis.y, j.axis.z);
        if (!(axis.norm() > 0.0))
          throw Error(source + ": joint '" + j.name + "' has a zero axis");
        joint.axis = axis.normalized();
      }
      if (joint.type == HandJoint::Type::kContinuous) {
        joint.lower = -std::numeric_limits<double>::infinity();
        joint.upper = std::numeric_limits<double>::infinity();
      } else if (j.limits) {
        joint.lower = j.limits->lower;
        joint.upper = j.limits->upper;
      }
      if (j.limits) {
        joint.effort = j.limits->effort;
        joint.velocity = j.limits->velocity;
      }
      if (joint.movable() && joint.type != HandJoint::Type::kContinuous &&
          !(joint.lower <= joint.upper)) {
        std::ostringstream message;
        message << source << ": joint '" << j.name << "' has lower limit " << joint.lower
                << " above its upper limit " << joint.upper;
        throw Error(message.str());
      }
      if (j.mimic) {
        joint.mimic_multiplier = j.mimic->multiplier;
        joint.mimic_offset = j.mimic->offset;
        // Resolved below, when every joint is known.
        joint.mimic_master = -2;
      }
      out.parent_joint = static_cast<int>(hand.joints.size());
      hand.joints.push_back(joint);
    }
    hand.links.push_back(std::move(out));
    for (const urdf::LinkSharedPtr& child : link->child_links) queue.push_back(child);
  }
  // Mimic masters, by name, within the kept subtree.
  for (HandJoint& joint : hand.joints) {
    if (joint.mimic_master != -2) continue;
    const urdf::JointConstSharedPtr j = model->getJoint(joint.name);
    const std::string& master = j->mimic->joint_name;
    joint.mimic_master = hand.jointIndex(master);
    if (joint.mimic_master < 0) {
      throw Error(source + ": joint '" + joint.name + "' mimics '" + master + "', which " +
                  (model->getJoint(master) ? "is outside root_link's subtree" : "does not exist"));
    }
    if (!hand.joints[joint.mimic_master].movable() ||
        hand.joints[joint.mimic_master].mimic_master >= 0) {
      throw Error(source + ": joint '" + joint.name + "' mimics '" + master +
                  "', which is fixed or itself a mimic joint");
    }
  }
  const size_t left_out = model->links_.size() - hand.links.size();
  if (left_out > 0) {
    std::ostringstream message;
    message << source << ": " << left_out << " link(s) outside root_link '" << root->name
            << "' are left out";
    hand.warnings.push_back(message.str());
  }
  return hand;
}

}  // namespace norm2tex
