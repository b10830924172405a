#include "norm2tex/sim/hand_sim.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include <btBulletDynamicsCommon.h>

#include "common/error_messages.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "sim/bullet_eigen.hpp"
#include "sim/gel_pad_contacts.hpp"
#include "sim/object_collision.hpp"

namespace norm2tex {
namespace {

// Collision groups: links meet the object (not each other, not the floor: they are placed by
// the drives); gels never collide through Bullet (the package makes their contacts).
constexpr int kLinkGroup = 1 << 5;
constexpr int kGelGroup = 1 << 6;
constexpr int kObjectGroup = 1 << 7;

bool isPose(const Eigen::Isometry3d& pose) {
  return pose.matrix().allFinite() &&
         (pose.linear() * pose.linear().transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-6 &&
         pose.linear().determinant() > 0.0;
}

}  // namespace

struct HandSim::World {
  btDefaultCollisionConfiguration collision_config;
  btCollisionDispatcher dispatcher{&collision_config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &collision_config};

  std::vector<std::unique_ptr<btCollisionShape>> shapes;  // every shape the bodies use
  std::unique_ptr<btRigidBody> floor;
  /// Per link: its kinematic body, or null when it has no collision geometry.
  std::vector<std::unique_ptr<btRigidBody>> links;
  std::unique_ptr<GelPadContacts> gels;
  std::unique_ptr<btRigidBody> object;

  ~World() {
    gels.reset();  // its manifolds name the object
    if (object) world.removeRigidBody(object.get());
    for (auto& link : links) {
      if (link) world.removeRigidBody(link.get());
    }
    if (floor) world.removeRigidBody(floor.get());
  }
};

HandSimConfig makeHandSimConfig(const std::string& hand_yaml, const GripperSimConfig& scene) {
  return makeHandSimConfig(loadHandConfig(hand_yaml), scene);
}

HandSimConfig makeHandSimConfig(HandConfig hand, const GripperSimConfig& scene) {
  HandSimConfig config;
  config.hand = std::move(hand);
  config.object = scene.object;
  config.physics = scene.physics;
  config.gel_law = scene.gel_law;
  config.gel_width_m = scene.gel_width_m;
  config.gel_height_m = scene.gel_height_m;
  config.gel_thickness_m = scene.gel_thickness_m;
  return config;
}

HandSim::HandSim(const HandSimConfig& config)
    : HandSim(config, loadHandDescription(config.hand.urdf_path, config.hand.package_paths,
                                          config.hand.root_link)) {}

HandSim::HandSim(const HandSimConfig& config, HandDescription description)
    : config_(config), description_(std::move(description)) {
  if (!isPose(config_.hand.base_pose)) throw Error("hand.base_pose is not a finite rigid pose");
  if (!isPose(config_.object_pose)) throw Error("the object's pose is not a finite rigid pose");
  warnings_ = description_.warnings;
  base_pose_ = config_.hand.base_pose;
  for (const SensorMount& mount : config_.hand.sensors) {
    const int link = description_.linkIndex(mount.link);
    if (link < 0) {
      std::string links;
      for (const HandLink& l : description_.links) links += (links.empty() ? "" : ", ") + l.name;
      throw Error("sensor '" + mount.name + "': link '" + mount.link + "' is not in the hand " +
                  "(" + config_.hand.urdf_path + "; links: " + links + ")");
    }
    if (std::count(sensor_links_.begin(), sensor_links_.end(), link)) {
      throw Error("sensor '" + mount.name + "': link '" + mount.link + "' carries another sensor");
    }
    sensor_links_.push_back(link);
  }
  resolveDrives();

  const size_t joints = description_.joints.size();
  q_.assign(joints, 0.0);
  load_.assign(joints, 0.0);
  contact_stiffness_.assign(joints, 0.0);
  for (const auto& [name, value] : config_.hand.initial_positions) {
    const int j = description_.jointIndex(name);
    if (j < 0 || !description_.joints[j].movable() || description_.joints[j].mimic_master >= 0) {
      throw Error("initial_positions." + name + ": not an actuated joint of the hand");
    }
    q_[j] = value;
  }
  for (size_t j = 0; j < joints; ++j) {
    bool clamped = false;
    if (description_.joints[j].movable())
      q_[j] = clampToLimits(static_cast<int>(j), q_[j], clamped);
  }
  for (size_t j = 0; j < joints; ++j) {
    const HandJoint& joint = description_.joints[j];
    if (joint.mimic_master >= 0) {
      q_[j] = joint.mimic_multiplier * q_[joint.mimic_master] + joint.mimic_offset;
    }
  }
  initial_q_ = q_;
  drive_q_ = q_;
  target_ = q_;
  // The movable joints from the root to each link.
  link_joints_.resize(description_.links.size());
  for (size_t l = 1; l < description_.links.size(); ++l) {
    const HandJoint& joint = description_.joints[description_.links[l].parent_joint];
    link_joints_[l] = link_joints_[joint.parent_link];
    if (joint.movable()) link_joints_[l].push_back(description_.links[l].parent_joint);
  }
  link_poses_.assign(description_.links.size(), Eigen::Isometry3d::Identity());
  forwardKinematics();

  object_ = loadObjectMesh(config_.object.mesh, config_.object.scale);
  const Eigen::Vector3d centre = object_.mesh.bounds().center().cast<double>();
  object_in_body_ = Eigen::Translation3d(-centre);
  checkMounts();
  makeCollision();
  buildWorld();
}

HandSim::~HandSim() = default;

void HandSim::resolveDrives() {
  drives_.assign(description_.joints.size(), Drive{});
  for (const auto& [name, drive] : config_.hand.drives) {
    const int j = description_.jointIndex(name);
    if (j < 0) throw Error("joints." + name + ": no such joint in the hand");
  }
  for (size_t j = 0; j < description_.joints.size(); ++j) {
    const HandJoint& joint = description_.joints[j];
    if (!joint.movable() || joint.mimic_master >= 0) {
      if (joint.mimic_master < 0) continue;
    } else {
      actuated_.push_back(static_cast<int>(j));
      actuated_names_.push_back(joint.name);
    }
    const auto own = config_.hand.drives.find(joint.name);
    const JointDriveOptions none;
    const JointDriveOptions& specific = own != config_.hand.drives.end() ? own->second : none;
    const JointDriveOptions& fallback = config_.hand.default_drive;
    const auto pick = [&](double yaml_own, double urdf, double yaml_default) {
      if (yaml_own >= 0) return yaml_own;
      if (yaml_default >= 0) return yaml_default;
      return urdf;
    };
    Drive& d = drives_[j];
    d.effort = pick(specific.effort, joint.effort, fallback.effort);
    d.velocity = pick(specific.velocity, joint.velocity, fallback.velocity);
    d.stiffness = std::max(0.0, pick(specific.stiffness, 0.0, fallback.stiffness));
    if (joint.mimic_master >= 0) continue;  // a mimic joint moves with its master
    if (!(d.effort > 0.0) || !(d.velocity > 0.0)) {
      throw Error("joint '" + joint.name + "' has no " + (d.effort > 0.0 ? "velocity" : "effort") +
                  " limit (the URDF gives 0): set joints." + joint.name + " or joints.default " +
                  "{effort, velocity} in the hand yaml");
    }
  }
}

double HandSim::clampToLimits(int j, double value, bool& clamped) const {
  const HandJoint& joint = description_.joints[j];
  const double out = std::clamp(value, joint.lower, joint.upper);
  clamped = out != value;
  return out;
}

void HandSim::forwardKinematics() {
  link_poses_[0] = base_pose_;
  for (size_t l = 1; l < description_.links.size(); ++l) {
    const int j = description_.links[l].parent_joint;
    const HandJoint& joint = description_.joints[j];
    Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
    if (joint.type == HandJoint::Type::kPrismatic) {
      motion.translation() = joint.axis * q_[j];
    } else if (joint.movable()) {
      motion.linear() = Eigen::AngleAxisd(q_[j], joint.axis).toRotationMatrix();
    }
    link_poses_[l] = link_poses_[joint.parent_link] * joint.origin * motion;
  }
}

Eigen::Isometry3d HandSim::gelInLink(int sensor) const {
  return config_.hand.sensors[sensor].digit_in_link * gelInDigit();
}

Eigen::Isometry3d HandSim::gelInWorld(int sensor) const {
  return link_poses_[sensor_links_[sensor]] * gelInLink(sensor);
}

Eigen::Isometry3d HandSim::objectInWorld() const {
  return toEigen(world_->object->getWorldTransform()) * object_in_body_;
}

double HandSim::jointPosition(const std::string& name) const {
  const int j = description_.jointIndex(name);
  if (j < 0) throw Error("no joint '" + name + "' in the hand");
  return q_[j];
}

void HandSim::checkMounts() {
  // TACTO's DIGIT link mesh includes the gel: its front over the pad should lie at, or a little
  // behind, the gel surface. A gel far in front of its link, or one the link pokes through,
  // is a gel pose that does not match the mesh.
  checks_.assign(sensor_links_.size(), SensorMountCheck{});
  for (size_t s = 0; s < sensor_links_.size(); ++s) {
    const HandLink& link = description_.links[sensor_links_[s]];
    const Eigen::Isometry3d link_in_gel = gelInLink(static_cast<int>(s)).inverse();
    double front = -std::numeric_limits<double>::infinity();
    for (const HandCollision& c : link.collisions) {
      if (c.kind != HandCollision::Kind::kMesh) continue;
      for (const Eigen::Vector3d& v : c.mesh_vertices) {
        const Eigen::Vector3d p = link_in_gel * (c.origin * v);
        if (std::abs(p.x()) <= config_.gel_width_m / 2 &&
            std::abs(p.y()) <= config_.gel_height_m / 2) {
          front = std::max(front, p.z());
        }
      }
    }
    SensorMountCheck& check = checks_[s];
    if (!std::isfinite(front)) {
      check.gel_in_front_of_mesh_m = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    check.gel_in_front_of_mesh_m = -front;
    if (-front < -0.5e-3 || -front > config_.gel_thickness_m) {
      std::ostringstream message;
      message << "sensor '" << config_.hand.sensors[s].name << "': the gel surface lies "
              << -front * 1e3 << " mm in front of link '" << link.name
              << "''s collision mesh over the pad (expected 0 to the gel's thickness, "
              << config_.gel_thickness_m * 1e3 << " mm): check its gel pose in rviz";
      warnings_.push_back(message.str());
    }
  }
}

void HandSim::makeCollision() {
  // The hull's hollows are measured against the first gel's normal, with the object and the
  // hand as constructed. (A convex decomposition takes HACD a good part of a second: episodes
  // that reset the hand must not redo it.)
  const Eigen::Vector3d centre = object_.mesh.bounds().center().cast<double>();
  Eigen::Vector3d gel_axis = Eigen::Vector3d::UnitY();
  if (!sensor_links_.empty()) {
    gel_axis =
        (config_.object_pose.linear().transpose() * gelInWorld(0).linear().col(2)).normalized();
  }
  ObjectCollisionShapes shapes = makeObjectCollision(
      object_, config_.object.collision, centre, config_.gel_law.points().back().first, gel_axis);
  object_shapes_ = std::move(shapes.shapes);
  contact_parts_ = std::move(shapes.contact_parts);
  contact_capsule_ = shapes.contact_capsule;
  collision_ = shapes.collision;
}

void HandSim::buildWorld() {
  world_ = std::make_unique<World>();
  World& w = *world_;
  const PhysicsOptions& p = config_.physics;
  w.world.setGravity(btVector3(0, 0, -p.gravity_m_s2));
  btContactSolverInfo& solver = w.world.getSolverInfo();
  solver.m_numIterations = p.solver_iterations;
  solver.m_frictionERP = p.friction_erp;
  solver.m_leastSquaresResidualThreshold =
      static_cast<btScalar>(p.solver_tolerance_m_s * p.solver_tolerance_m_s);
  solver.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;

  w.shapes.push_back(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0));
  w.floor = std::make_unique<btRigidBody>(
      btRigidBody::btRigidBodyConstructionInfo(0, nullptr, w.shapes.back().get()));
  w.floor->setFriction(0.5);
  w.world.addRigidBody(w.floor.get(), btBroadphaseProxy::StaticFilter, kObjectGroup);

  // Links: kinematic compounds of their collision elements.
  w.links.resize(description_.links.size());
  for (size_t l = 0; l < description_.links.size(); ++l) {
    const HandLink& link = description_.links[l];
    if (link.collisions.empty()) continue;
    auto compound = std::make_unique<btCompoundShape>();
    for (const HandCollision& c : link.collisions) {
      std::unique_ptr<btCollisionShape> shape;
      switch (c.kind) {
        case HandCollision::Kind::kBox:
          shape = std::make_unique<btBoxShape>(toBt(c.size / 2));
          break;
        case HandCollision::Kind::kCylinder:
          shape =
              std::make_unique<btCylinderShapeZ>(btVector3(c.size.x(), c.size.x(), c.size.y() / 2));
          break;
        case HandCollision::Kind::kSphere:
          shape = std::make_unique<btSphereShape>(c.size.x());
          break;
        case HandCollision::Kind::kMesh:
          shape = bulletHull(c.mesh_vertices);
          break;
      }
      if (c.kind != HandCollision::Kind::kMesh) {
        shape->setMargin(std::min<double>(kBoxMargin, 0.25 * c.size.head<2>().maxCoeff()));
      }
      compound->addChildShape(toBt(c.origin), shape.get());
      w.shapes.push_back(std::move(shape));
    }
    btRigidBody::btRigidBodyConstructionInfo info(0, nullptr, compound.get());
    info.m_friction = config_.object.friction;
    info.m_restitution = 0;
    auto body = std::make_unique<btRigidBody>(info);
    body->setCollisionFlags(body->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
    body->setActivationState(DISABLE_DEACTIVATION);
    w.shapes.push_back(std::move(compound));
    // A DIGIT's link meets the object through its soft gel only.
    const bool sensor_link =
        std::count(sensor_links_.begin(), sensor_links_.end(), static_cast<int>(l)) > 0;
    w.world.addRigidBody(body.get(), kLinkGroup, sensor_link ? 0 : kObjectGroup);
    w.links[l] = std::move(body);
  }

  // Gels: the package's compliant contact, added before the object (whose body attach() takes).
  GelPadOptions pads =
      gelPadOptionsOf(config_, static_cast<double>(object_.mesh.bounds().sizes().minCoeff()) / 2.0);
  // A hand's gel can have the object behind it (behind its finger, across the palm), where two
  // facing gels (the built-in gripper's) never do: a part reaching further behind the gel's
  // surface than twice its thickness is on the sensor's other side, not pressed into its gel.
  pads.behind_gel_m = 2.0 * config_.gel_thickness_m;
  w.gels = std::make_unique<GelPadContacts>(
      w.world, w.dispatcher, static_cast<int>(sensor_links_.size()), pads, kGelGroup);

  // Object: dynamic, its body at its bounds' centre.
  btCollisionShape* shape = object_shapes_.back().get();
  btVector3 inertia(0, 0, 0);
  shape->calculateLocalInertia(config_.object.mass_kg, inertia);
  btRigidBody::btRigidBodyConstructionInfo info(config_.object.mass_kg, nullptr, shape, inertia);
  info.m_friction = 1.0;
  info.m_restitution = 0;
  w.object = std::make_unique<btRigidBody>(info);
  w.object->setActivationState(DISABLE_DEACTIVATION);
  w.object->setCollisionFlags(w.object->getCollisionFlags() |
                              btCollisionObject::CF_HAS_FRICTION_ANCHOR);
  w.object->setWorldTransform(toBt(config_.object_pose * object_in_body_.inverse()));
  w.world.addRigidBody(w.object.get(), kObjectGroup, btBroadphaseProxy::StaticFilter | kLinkGroup);

  w.gels->attach(*w.object, GelContactGeometry{&contact_parts_, &contact_capsule_});
  contacts_.assign(sensor_links_.size(), GelContactState{});
  placeBodies();
  for (size_t s = 0; s < sensor_links_.size(); ++s) {
    contacts_[s].object_in_gel = gelInWorld(static_cast<int>(s)).inverse() * objectInWorld();
  }
}

void HandSim::placeBodies() {
  World& w = *world_;
  for (size_t l = 0; l < w.links.size(); ++l) {
    if (!w.links[l]) continue;
    w.links[l]->setWorldTransform(toBt(link_poses_[l]));
    w.links[l]->setInterpolationWorldTransform(w.links[l]->getWorldTransform());
  }
  for (int s = 0; s < w.gels->count(); ++s) w.gels->place(s, gelInWorld(s));
}

std::vector<int> HandSim::validateNames(const std::vector<std::string>& names) const {
  std::vector<int> joints;
  for (const std::string& name : names) {
    const int j = description_.jointIndex(name);
    if (j < 0) {
      std::string valid;
      for (const std::string& n : actuated_names_) valid += (valid.empty() ? "" : ", ") + n;
      throw Error("unknown joint '" + name + "'; the hand's actuated joints: " + valid);
    }
    if (!description_.joints[j].movable()) throw Error("joint '" + name + "' is fixed");
    if (description_.joints[j].mimic_master >= 0) {
      throw Error("joint '" + name + "' mimics '" +
                  description_.joints[description_.joints[j].mimic_master].name +
                  "': command its master");
    }
    if (std::count(joints.begin(), joints.end(), j))
      throw Error("joint '" + name + "' is named twice");
    joints.push_back(j);
  }
  return joints;
}

std::vector<std::string> HandSim::setJointTargets(const std::vector<std::string>& names,
                                                  const std::vector<double>& positions) {
  const std::vector<int> joints = validateNames(names);
  if (positions.size() != names.size()) {
    throw Error("joint targets: " + std::to_string(names.size()) + " names but " +
                std::to_string(positions.size()) + " positions");
  }
  for (size_t i = 0; i < positions.size(); ++i) {
    if (!std::isfinite(positions[i])) throw Error("joint '" + names[i] + "': target is not finite");
  }
  std::vector<std::string> clamped_names;
  for (size_t i = 0; i < joints.size(); ++i) {
    bool clamped = false;
    target_[joints[i]] = clampToLimits(joints[i], positions[i], clamped);
    if (clamped) clamped_names.push_back(names[i]);
  }
  following_trajectory_ = false;
  return clamped_names;
}

std::vector<std::string> HandSim::setTrajectory(const JointTrajectoryCommand& t) {
  const std::vector<int> joints = validateNames(t.joint_names);
  if (t.times_s.empty() || t.times_s.size() != t.positions.size()) {
    throw Error("joint trajectory: " + std::to_string(t.times_s.size()) + " times for " +
                std::to_string(t.positions.size()) + " points (at least one point needed)");
  }
  double previous = 0.0;
  for (size_t p = 0; p < t.times_s.size(); ++p) {
    const double time = t.times_s[p];
    if (!std::isfinite(time) || time < 0.0 || (p > 0 && time <= previous)) {
      std::ostringstream message;
      message << "joint trajectory: point " << p << "'s time_from_start " << time << " s is not "
              << (time < 0.0 || !std::isfinite(time) ? "finite and >= 0"
                                                     : "after the previous point's");
      throw Error(message.str());
    }
    previous = time;
    if (t.positions[p].size() != joints.size()) {
      throw Error("joint trajectory: point " + std::to_string(p) + " has " +
                  std::to_string(t.positions[p].size()) + " positions for " +
                  std::to_string(joints.size()) + " joints");
    }
    for (size_t i = 0; i < joints.size(); ++i) {
      if (!std::isfinite(t.positions[p][i])) {
        throw Error("joint trajectory: point " + std::to_string(p) + ", joint '" +
                    t.joint_names[i] + "': position is not finite");
      }
    }
  }
  Trajectory trajectory;
  trajectory.joints = joints;
  trajectory.times_s = t.times_s;
  trajectory.start_s = ticks_ * tickSeconds();
  std::vector<std::string> clamped_names;
  for (size_t i = 0; i < joints.size(); ++i) trajectory.start.push_back(target_[joints[i]]);
  for (const std::vector<double>& point : t.positions) {
    std::vector<double> clamped_point(point.size());
    for (size_t i = 0; i < joints.size(); ++i) {
      bool clamped = false;
      clamped_point[i] = clampToLimits(joints[i], point[i], clamped);
      if (clamped && !std::count(clamped_names.begin(), clamped_names.end(), t.joint_names[i])) {
        clamped_names.push_back(t.joint_names[i]);
      }
    }
    trajectory.positions.push_back(clamped_point);
  }
  trajectory_ = std::move(trajectory);
  following_trajectory_ = true;
  return clamped_names;
}

void HandSim::setOpening(double opening) {
  const HandConfig& h = config_.hand;
  if (h.gripper_joints.empty()) {
    throw Error("this hand has no parallel-gripper joints (gripper.joints in its hand yaml)");
  }
  if (!(opening >= 0.0 && opening <= 1.0)) {
    std::ostringstream message;
    message << "gripper opening " << opening << " is out of range; valid: [0, 1] (0 = closed)";
    throw Error(message.str());
  }
  setJointTargets(h.gripper_joints, gripperJointPositions(opening));
}

std::vector<double> HandSim::gripperJointPositions(double opening) const {
  const HandConfig& h = config_.hand;
  std::vector<double> positions;
  for (size_t i = 0; i < h.gripper_joints.size(); ++i) {
    positions.push_back(h.gripper_closed[i] + opening * (h.gripper_open[i] - h.gripper_closed[i]));
  }
  return positions;
}

void HandSim::setBasePose(const Eigen::Isometry3d& base_in_world, double duration_s) {
  if (!isPose(base_in_world)) throw Error("base pose is not a finite rigid pose");
  if (!(duration_s >= 0.0 && duration_s <= 3600.0))
    throw Error("base motion duration must be in [0, 3600] s");
  base_from_ = base_pose_;
  base_to_ = base_in_world;
  base_tick_ = 0;
  base_ticks_ = static_cast<int>(std::lround(duration_s / tickSeconds()));
  if (base_ticks_ == 0) base_pose_ = base_in_world;
}

void HandSim::advanceBase() {
  if (base_tick_ >= base_ticks_) return;
  const double s = static_cast<double>(++base_tick_) / base_ticks_;
  const Eigen::Quaterniond from(base_from_.linear()), to(base_to_.linear());
  base_pose_ = Eigen::Isometry3d::Identity();
  base_pose_.linear() = from.slerp(s, to).toRotationMatrix();
  base_pose_.translation() = (1.0 - s) * base_from_.translation() + s * base_to_.translation();
}

void HandSim::resetObject(const Eigen::Isometry3d& object_in_world, bool gravity) {
  if (!isPose(object_in_world)) throw Error("object pose is not a finite rigid pose");
  btRigidBody& object = *world_->object;
  object.setWorldTransform(toBt(object_in_world * object_in_body_.inverse()));
  object.setInterpolationWorldTransform(object.getWorldTransform());
  object.setLinearVelocity(btVector3(0, 0, 0));
  object.setAngularVelocity(btVector3(0, 0, 0));
  object.clearForces();
  world_->gels->clearContacts();
  setObjectGravity(gravity);
}

void HandSim::reset(const Eigen::Isometry3d* object_in_world) {
  if (object_in_world && !isPose(*object_in_world))
    throw Error("object pose is not a finite rigid pose");
  restart(object_in_world, {}, {});
}

void HandSim::reset(const Eigen::Isometry3d& object_in_world,
                    const std::vector<std::string>& joint_names,
                    const std::vector<double>& joint_positions) {
  if (!isPose(object_in_world)) throw Error("object pose is not a finite rigid pose");
  const std::vector<int> joints = validateNames(joint_names);
  if (joint_positions.size() != joint_names.size()) {
    throw Error("joint positions: " + std::to_string(joint_names.size()) + " names but " +
                std::to_string(joint_positions.size()) + " positions");
  }
  for (size_t i = 0; i < joint_positions.size(); ++i) {
    if (!std::isfinite(joint_positions[i]))
      throw Error("joint '" + joint_names[i] + "': position is not finite");
  }
  restart(&object_in_world, joints, joint_positions);
}

void HandSim::restart(const Eigen::Isometry3d* object_in_world, const std::vector<int>& joints,
                      const std::vector<double>& positions) {
  if (object_in_world) config_.object_pose = *object_in_world;
  q_ = initial_q_;
  for (size_t i = 0; i < joints.size(); ++i) {
    bool clamped = false;
    q_[joints[i]] = clampToLimits(joints[i], positions[i], clamped);
  }
  for (size_t j = 0; j < q_.size(); ++j) {
    const HandJoint& joint = description_.joints[j];
    if (joint.mimic_master >= 0) {
      q_[j] = joint.mimic_multiplier * q_[joint.mimic_master] + joint.mimic_offset;
    }
  }
  drive_q_ = q_;
  target_ = q_;
  std::fill(load_.begin(), load_.end(), 0.0);
  std::fill(contact_stiffness_.begin(), contact_stiffness_.end(), 0.0);
  following_trajectory_ = false;
  base_pose_ = config_.hand.base_pose;
  base_tick_ = base_ticks_ = 0;
  forwardKinematics();
  buildWorld();
}

bool HandSim::objectReachesIntoGel(int sensor) const {
  for (const std::vector<GelContactPoint>& part : world_->gels->objectPointsIn(sensor)) {
    if (!part.empty()) return true;
  }
  return false;
}

void HandSim::setObjectGravity(bool on) {
  world_->object->setGravity(on ? world_->world.getGravity() : btVector3(0, 0, 0));
}

void HandSim::advanceTrajectory() {
  if (!following_trajectory_) return;
  const Trajectory& t = trajectory_;
  // The target at the end of the tick about to run.
  const double now = (ticks_ + 1) * tickSeconds() - t.start_s;
  // The segment the time is in: from the start (time 0) or the previous point to the next.
  size_t next = 0;
  while (next < t.times_s.size() && t.times_s[next] < now) ++next;
  for (size_t i = 0; i < t.joints.size(); ++i) {
    double value;
    if (next == t.times_s.size()) {
      value = t.positions.back()[i];
    } else {
      const double t0 = next == 0 ? 0.0 : t.times_s[next - 1];
      const double p0 = next == 0 ? t.start[i] : t.positions[next - 1][i];
      const double s = t.times_s[next] > t0 ? (now - t0) / (t.times_s[next] - t0) : 1.0;
      value = p0 + std::clamp(s, 0.0, 1.0) * (t.positions[next][i] - p0);
    }
    target_[t.joints[i]] = value;
  }
  if (next == t.times_s.size()) following_trajectory_ = false;
}

void HandSim::moveJoints(double dt) {
  for (int j : actuated_) {
    const Drive& d = drives_[j];
    // The load the drive feels: its own joint's, and its mimic joints' through their ratio.
    double load = load_[j], k_contact = contact_stiffness_[j];
    for (size_t m = 0; m < description_.joints.size(); ++m) {
      const HandJoint& mimic = description_.joints[m];
      if (mimic.mimic_master != j) continue;
      load += mimic.mimic_multiplier * load_[m];
      k_contact += mimic.mimic_multiplier * mimic.mimic_multiplier * contact_stiffness_[m];
    }
    const double max_move = d.velocity * dt;
    double move = std::clamp(target_[j] - drive_q_[j], -max_move, max_move);
    // A drive pushes against its load with at most its effort: it advances into the load only
    // as far as the contact's stiffness lets the load grow to the effort, and yields where the
    // load exceeds it (one Newton step a tick, as the drive's stiffness below). Against a rigid
    // contact (no gel on the way) it stops.
    const double into = load < 0.0 ? 1.0 : -1.0;  // the direction that pushes into the load
    const double excess = std::abs(load) - d.effort;
    const bool pushing = move * into > 0.0;
    if (excess >= 0.0) {
      const double yield =
          k_contact > 0.0 ? std::clamp(-into * excess / k_contact, -max_move, max_move) : 0.0;
      if (pushing || std::abs(yield) > std::abs(move)) move = yield;
    } else if (pushing && k_contact > 0.0) {
      move = into * std::min(std::abs(move), -excess / k_contact);
    }
    drive_q_[j] += move;
    bool clamped = false;
    drive_q_[j] = clampToLimits(j, drive_q_[j], clamped);
    if (d.stiffness > 0.0) {
      // In series with a spring of stiffness k: at rest q = drive + load / k.
      const double residual = drive_q_[j] + load / d.stiffness - q_[j];
      q_[j] += std::clamp(residual * d.stiffness / (d.stiffness + k_contact), -max_move, max_move);
    } else {
      q_[j] = drive_q_[j];
    }
  }
  for (size_t m = 0; m < description_.joints.size(); ++m) {
    const HandJoint& joint = description_.joints[m];
    if (joint.mimic_master >= 0) {
      q_[m] = joint.mimic_multiplier * q_[joint.mimic_master] + joint.mimic_offset;
      target_[m] = joint.mimic_multiplier * target_[joint.mimic_master] + joint.mimic_offset;
    }
  }
  forwardKinematics();
  placeBodies();
}

void HandSim::addLoad(int link, const Eigen::Vector3d& point, const Eigen::Vector3d& force,
                      const Eigen::Vector3d& normal, double normal_stiffness) {
  for (int j : link_joints_[link]) {
    const HandJoint& joint = description_.joints[j];
    const Eigen::Isometry3d& frame = link_poses_[joint.child_link];
    const Eigen::Vector3d axis = frame.linear() * joint.axis;
    // The point's motion per unit of the joint's coordinate.
    const Eigen::Vector3d motion = joint.type == HandJoint::Type::kPrismatic
                                       ? axis
                                       : Eigen::Vector3d(axis.cross(point - frame.translation()));
    load_[j] += motion.dot(force);
    if (normal_stiffness > 0.0) {
      const double along = motion.dot(normal);
      contact_stiffness_[j] += normal_stiffness * along * along;
    }
  }
}

void HandSim::measureContacts(double dt) {
  std::fill(load_.begin(), load_.end(), 0.0);
  std::fill(contact_stiffness_.begin(), contact_stiffness_.end(), 0.0);
  // Each gel contact point loads the joints that carry its link: the gel is pushed back into
  // itself and dragged by friction.
  world_->gels->measure(
      dt, objectInWorld(), contacts_,
      [&](int s, const Eigen::Vector3d& on_gel, double normal_n,
          const Eigen::Vector3d& friction_n) {
        const Eigen::Vector3d out_of_gel = world_->gels->gelInWorld(s).linear().col(2);
        addLoad(sensor_links_[s], on_gel, -out_of_gel * normal_n + friction_n, out_of_gel, 0.0);
      });
  // The gel's stiffness as the drive sees it, at the patch's centre: the law's tangent.
  for (size_t s = 0; s < contacts_.size(); ++s) {
    const double depth = contacts_[s].penetration_m;
    if (depth <= 0.0) continue;
    const Eigen::Isometry3d& gel_in_world = world_->gels->gelInWorld(static_cast<int>(s));
    addLoad(sensor_links_[s], gel_in_world.translation(), Eigen::Vector3d::Zero(),
            gel_in_world.linear().col(2),
            config_.gel_law.tangentStiffness(std::min(depth, config_.gel_thickness_m)));
  }
  // Rigid links against the object: Bullet's own manifolds.
  btDispatcher& dispatcher = world_->dispatcher;
  const btCollisionObject* object = world_->object.get();
  for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
    const btPersistentManifold* manifold = dispatcher.getManifoldByIndexInternal(m);
    const bool object_is_b = manifold->getBody1() == object;
    if (!object_is_b && manifold->getBody0() != object) continue;
    const btCollisionObject* other = object_is_b ? manifold->getBody0() : manifold->getBody1();
    int link = -1;
    for (size_t l = 0; l < world_->links.size(); ++l) {
      if (world_->links[l].get() == other) link = static_cast<int>(l);
    }
    if (link < 0) continue;
    for (int c = 0; c < manifold->getNumContacts(); ++c) {
      const btManifoldPoint& point = manifold->getContactPoint(c);
      // The normal points from B to A; a positive impulse pushes A along it.
      Eigen::Vector3d on_a =
          toEigen(point.m_normalWorldOnB) * point.getAppliedImpulse() / dt +
          (toEigen(point.m_lateralFrictionDir1) * point.m_appliedImpulseLateral1 +
           toEigen(point.m_lateralFrictionDir2) * point.m_appliedImpulseLateral2) /
              dt;
      const Eigen::Vector3d on_link = object_is_b ? on_a : Eigen::Vector3d(-on_a);
      addLoad(link, toEigen(object_is_b ? point.m_positionWorldOnA : point.m_positionWorldOnB),
              on_link, Eigen::Vector3d::Zero(), 0.0);
    }
  }
}

void HandSim::step(int ticks) {
  const int substeps = config_.physics.substeps;
  const double dt = tickSeconds() / substeps;
  for (int t = 0; t < ticks; ++t) {
    advanceTrajectory();
    advanceBase();
    for (int s = 0; s < substeps; ++s) {
      moveJoints(dt);
      world_->gels->updateContacts();
      world_->gels->updateStiffness();
      world_->world.stepSimulation(dt, 0, dt);
      measureContacts(dt);
    }
    ++ticks_;
  }
}

}  // namespace norm2tex
