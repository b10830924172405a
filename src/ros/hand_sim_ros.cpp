#include "hand_sim_ros.hpp"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <sstream>

#include <rosgraph_msgs/Clock.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_msgs/TFMessage.h>

#include "conversions.hpp"
#include "markers.hpp"
#include "norm2tex/EpisodeInfo.h"
#include "norm2tex/SimFrame.h"
#include "norm2tex/TactileContact.h"
#include "norm2tex/common/error.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/contact_shear_load.hpp"
#include "params.hpp"

namespace norm2tex {
namespace {

using ros_params::badParameter;
using ros_params::materialConfigPath;
using ros_params::packageFile;
using ros_params::readParam;
using ros_params::text;

/// A message's pose; throws Error for one whose position or quaternion is not finite or whose
/// quaternion is not unit length (within 1e-3: a hand-typed one), naming `what` and the values.
Eigen::Isometry3d fromPoseMsg(const geometry_msgs::Pose& pose, const std::string& what) {
  const Eigen::Quaterniond q(pose.orientation.w, pose.orientation.x, pose.orientation.y,
                             pose.orientation.z);
  const Eigen::Vector3d p(pose.position.x, pose.position.y, pose.position.z);
  if (!p.allFinite()) {
    std::ostringstream out;
    out << what << ": position (" << p.x() << ", " << p.y() << ", " << p.z() << ") is not finite";
    throw Error(out.str());
  }
  if (!q.coeffs().allFinite() || std::abs(q.norm() - 1.0) > 1e-3) {
    std::ostringstream out;
    out << what << ": orientation (x " << q.x() << ", y " << q.y() << ", z " << q.z() << ", w "
        << q.w() << ") is not a unit quaternion";
    if (q.coeffs().allFinite()) out << " (length " << q.norm() << ")";
    out << "; no rotation is (x 0, y 0, z 0, w 1)";
    throw Error(out.str());
  }
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = q.normalized().toRotationMatrix();
  out.translation() = p;
  return out;
}

}  // namespace

HandSimParams readHandSimParams(const ros::NodeHandle& pnh) {
  HandSimParams p;
  readSimNodeParams(pnh, p);
  readParam<std::string>(pnh, "hand", p.hand, "");
  if (p.hand.empty()) badParameter("hand", "''", "a hand yaml (docs/hands.md)");
  readParam(pnh, "object_pose", p.object_pose, p.object_pose);
  if (p.object_pose.size() != 6 || !std::all_of(p.object_pose.begin(), p.object_pose.end(),
                                                [](double v) { return std::isfinite(v); })) {
    badParameter("object_pose", std::to_string(p.object_pose.size()) + " values",
                 "[x, y, z, roll, pitch, yaw], finite, m and rad");
  }
  p.renderers_given = pnh.hasParam("renderers");
  return p;
}

HandSimRos::HandSimRos(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : params_(readHandSimParams(private_nh)), nh_(nh), private_nh_(private_nh) {
  const SimNodeScene scene = makeSimNodeScene(params_);
  beta_mm_ = scene.beta_mm;
  HandSimConfig config = makeHandSimConfig(params_.hand, scene.config);
  config.object_pose = poseFromXyzRpy(params_.object_pose);
  ticks_per_frame_ = scene.ticks_per_frame;
  frame_period_ns_ = scene.frame_period_ns;
  const SensorModel& sensor = scene.sensor;
  sim_ = std::make_unique<HandSim>(config);
  for (const std::string& warning : sim_->warnings()) ROS_WARN("hand_sim: %s", warning.c_str());
  if (!params_.renderers_given) {
    for (int s = 0; s < sim_->sensorCount(); ++s) params_.renderers.push_back(sim_->sensor(s).name);
  }
  for (int s = 0; s < sim_->sensorCount(); ++s) {
    meters_.push_back(std::make_unique<ContactPatchMeter>(sensor));
  }

  owns_clock_ = ros::Time::isSimTime();
  if (params_.synchronous && !owns_clock_) {
    throw Error(
        "~mode = synchronous needs /use_sim_time = true (simulated time advances only "
        "through ~step); set it before the nodes start, as hand_sim.launch does");
  }
  if (!owns_clock_) time_base_ = ros::Time::now();
  // As Gazebo does: the simulator is the source of the robot's description.
  nh_.setParam("robot_description", sim_->description().resolved_urdf_xml);
  {
    // For clients: the sensors in the yaml's order and the joints a command may name.
    std::vector<std::string> sensors;
    for (int s = 0; s < sim_->sensorCount(); ++s) sensors.push_back(sim_->sensor(s).name);
    private_nh_.setParam("sensors", sensors);
    private_nh_.setParam("actuated_joints", sim_->actuatedJoints());
  }

  tf_pub_ = nh_.advertise<tf2_msgs::TFMessage>("/tf", 100);
  if (owns_clock_) clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 10);
  frame_pub_ = private_nh_.advertise<SimFrame>("frame", 100);
  joints_pub_ = nh_.advertise<sensor_msgs::JointState>("joint_states", 10);
  for (int s = 0; s < sim_->sensorCount(); ++s) {
    contact_pubs_.push_back(nh_.advertise<TactileContact>(sim_->sensor(s).name + "/contact", 10));
  }
  object_marker_pub_ = private_nh_.advertise<visualization_msgs::Marker>("object_marker", 1, true);
  object_marker_pub_.publish(ros_conversions::objectMarker(sim_->object().mesh, ros::Time(0)));
  episode_pub_ = nh_.advertise<EpisodeInfo>("episode", 1, /*latch=*/true);
  publishEpisode();
  publishStaticTransforms();
  lock_step_ = std::make_unique<LockStep>(
      private_nh_, params_.synchronous ? params_.renderers : std::vector<std::string>(),
      params_.render_timeout, params_.ready_timeout, "hand_sim", 1);
  trajectory_sub_ = private_nh_.subscribe("joint_command", 10, &HandSimRos::onTrajectory, this);
  targets_sub_ = private_nh_.subscribe("joint_targets", 10, &HandSimRos::onTargets, this);
  base_sub_ = private_nh_.subscribe("base_pose", 10, &HandSimRos::onBasePose, this);
  if (!config.hand.gripper_joints.empty()) {
    gripper_sub_ = nh_.subscribe("gripper/command", 10, &HandSimRos::onGripperCommand, this);
  }
  ros::NodeHandle service_nh(private_nh_);
  service_nh.setCallbackQueue(&service_queue_);
  reset_srv_ = service_nh.advertiseService("reset", &HandSimRos::onReset, this);
  if (params_.synchronous)
    step_srv_ = service_nh.advertiseService("step", &HandSimRos::onStep, this);
  service_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &service_queue_);
  service_spinner_->start();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!params_.synchronous || params_.renderers.empty()) publishFrame();
  }
  if (!params_.synchronous) {
    clock_ = std::make_unique<WallClockGrid>(
        frame_period_ns_,
        [this](const ros::WallTime& scheduled, std::int64_t) { onTick(scheduled); });
  }
  ROS_INFO(
      "hand_sim: %s mode, hand '%s' (%zu links, %zu actuated joints, %d sensors) from %s, "
      "object '%s', physics %.0f Hz (%d ticks per %.1f Hz frame)",
      params_.synchronous ? "synchronous" : "real-time", sim_->description().name.c_str(),
      sim_->description().links.size(), sim_->actuatedJoints().size(), sim_->sensorCount(),
      params_.hand.c_str(), config.object.mesh.c_str(), config.physics.rate_hz, ticks_per_frame_,
      params_.frame_rate);
}

HandSimRos::~HandSimRos() {
  if (clock_) clock_->requestStop();
  if (lock_step_) lock_step_->cancel();
  clock_.reset();
  service_queue_.disable();
  if (service_spinner_) service_spinner_->stop();
}

ros::Time HandSimRos::frameStamp() const {
  return time_base_ + (ros_conversions::toRosTime(frame_ * frame_period_ns_) - ros::Time(0));
}

void HandSimRos::publishEpisode() {
  EpisodeInfo info;
  info.header.stamp = frameStamp();
  info.header.frame_id = "world";
  info.episode = ++episode_;
  info.object = sim_->config().object.name;
  info.material = params_.material;
  info.beta = beta_mm_;
  info.scenario = "hand";
  info.num_shards = 1;
  episode_pub_.publish(info);
}

void HandSimRos::publishStaticTransforms() {
  // Fixed joints and each gel on its link never move: /tf_static, once (latched).
  std::vector<geometry_msgs::TransformStamped> transforms;
  const HandDescription& d = sim_->description();
  auto stamped = [&](const std::string& parent, const std::string& child,
                     const Eigen::Isometry3d& pose) {
    geometry_msgs::TransformStamped t;
    t.header.stamp = frameStamp();
    t.header.frame_id = parent;
    t.child_frame_id = child;
    t.transform = ros_conversions::toTransformMsg(pose);
    return t;
  };
  for (const HandJoint& joint : d.joints) {
    if (joint.movable()) continue;
    transforms.push_back(
        stamped(d.links[joint.parent_link].name, d.links[joint.child_link].name, joint.origin));
  }
  for (int s = 0; s < sim_->sensorCount(); ++s) {
    transforms.push_back(
        stamped(sim_->sensor(s).link, sim_->sensor(s).name + "_gel", sim_->gelInLink(s)));
  }
  static_tf_ = std::make_unique<tf2_ros::StaticTransformBroadcaster>();
  static_tf_->sendTransform(transforms);
}

std::uint32_t HandSimRos::publishFrame() {
  const ros::Time stamp = frameStamp();
  const bool acknowledge = lock_step_->waits();
  if (acknowledge) lock_step_->waitUntilReady();
  if (owns_clock_) {
    rosgraph_msgs::Clock clock;
    clock.clock = stamp;
    clock_pub_.publish(clock);
  }
  const HandDescription& d = sim_->description();
  auto stamped = [&](const std::string& parent, const std::string& child,
                     const Eigen::Isometry3d& pose) {
    geometry_msgs::TransformStamped t;
    t.header.stamp = stamp;
    t.header.frame_id = parent;
    t.child_frame_id = child;
    t.transform = ros_conversions::toTransformMsg(pose);
    return t;
  };
  tf2_msgs::TFMessage tf;
  tf.transforms.push_back(stamped("world", d.links[0].name, sim_->linkInWorld(0)));
  for (const HandJoint& joint : d.joints) {
    if (!joint.movable()) continue;
    tf.transforms.push_back(stamped(
        d.links[joint.parent_link].name, d.links[joint.child_link].name,
        sim_->linkInWorld(joint.parent_link).inverse() * sim_->linkInWorld(joint.child_link)));
  }
  tf.transforms.push_back(stamped("world", "object", sim_->objectInWorld()));
  tf_pub_.publish(tf);

  sensor_msgs::JointState joints;
  joints.header.stamp = stamp;
  for (size_t j = 0; j < d.joints.size(); ++j) {
    if (!d.joints[j].movable()) continue;
    joints.name.push_back(d.joints[j].name);
    joints.position.push_back(sim_->jointPositions()[j]);
    joints.effort.push_back(sim_->jointLoads()[j]);
  }
  joints_pub_.publish(joints);

  for (int s = 0; s < sim_->sensorCount(); ++s) {
    if (contact_pubs_[s].getNumSubscribers() == 0) continue;  // the patch costs a rasterization
    std_msgs::Header header;
    header.stamp = stamp;
    header.frame_id = sim_->sensor(s).name + "_gel";
    const GelContactState& state = sim_->contact(s);
    const ContactPatch patch =
        meters_[s]->measure(sim_->object().mesh, state.object_in_gel, state.normal_force_n,
                            shearLoadOf(state, sim_->config().object.friction));
    contact_pubs_[s].publish(
        ros_conversions::toContactMsg(header, sim_->sensor(s).name, state, patch));
  }

  SimFrame frame;
  frame.header.stamp = stamp;
  frame.header.frame_id = "world";
  frame.frame = static_cast<std::uint64_t>(frame_);
  frame.acknowledge = acknowledge;
  frame.material = params_.material;
  for (int s = 0; s < sim_->sensorCount(); ++s) {
    ros_conversions::addSensorLoad(frame, sim_->sensor(s).name, sim_->contact(s));
  }
  frame.friction = sim_->config().object.friction;
  return lock_step_->publish(frame_pub_, frame);
}

void HandSimRos::warnClamped(const std::vector<std::string>& clamped) {
  if (clamped.empty()) return;
  std::string names;
  for (const std::string& name : clamped) names += (names.empty() ? "" : ", ") + name;
  ROS_WARN_THROTTLE(1.0, "hand_sim: targets outside the URDF limits clamped: %s", names.c_str());
}

void HandSimRos::onTrajectory(const trajectory_msgs::JointTrajectory::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  try {
    JointTrajectoryCommand command;
    command.joint_names = msg->joint_names;
    for (const trajectory_msgs::JointTrajectoryPoint& point : msg->points) {
      command.times_s.push_back(point.time_from_start.toSec());
      command.positions.push_back(point.positions);
    }
    warnClamped(sim_->setTrajectory(command));
  } catch (const Error& e) {
    ROS_WARN_THROTTLE(1.0, "hand_sim: ~joint_command refused, nothing changed: %s", e.what());
  }
}

void HandSimRos::onTargets(const sensor_msgs::JointState::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  try {
    warnClamped(sim_->setJointTargets(msg->name, msg->position));
  } catch (const Error& e) {
    ROS_WARN_THROTTLE(1.0, "hand_sim: ~joint_targets refused, nothing changed: %s", e.what());
  }
}

void HandSimRos::onBasePose(const geometry_msgs::PoseStamped::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  try {
    if (!msg->header.frame_id.empty() && msg->header.frame_id != "world") {
      throw Error("its frame_id is '" + msg->header.frame_id + "'; give it in 'world'");
    }
    // Over the next frame: poses streamed at the frame rate move the hand smoothly.
    sim_->setBasePose(fromPoseMsg(msg->pose, "~base_pose"), frame_period_ns_ * 1e-9);
  } catch (const Error& e) {
    ROS_WARN_THROTTLE(1.0, "hand_sim: ~base_pose refused, nothing changed: %s", e.what());
  }
}

void HandSimRos::onGripperCommand(const GripperCommand::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  try {
    double opening = msg->opening;
    if (msg->mode == GripperCommand::DELTA) {
      if (!(std::abs(msg->opening) <= 1.0)) throw Error("a DELTA opening must be within [-1, 1]");
      opening = std::clamp(opening_command_ + msg->opening, 0.0, 1.0);
    } else if (msg->mode != GripperCommand::ABSOLUTE) {
      throw Error("mode " + std::to_string(msg->mode) +
                  " is not valid; valid: 0 (ABSOLUTE), 1 (DELTA)");
    }
    sim_->setOpening(opening);
    opening_command_ = opening;
  } catch (const Error& e) {
    ROS_WARN_THROTTLE(1.0, "hand_sim: gripper command refused, nothing changed: %s", e.what());
  }
}

bool HandSimRos::onReset(HandReset::Request& request, HandReset::Response& response) {
  std::lock_guard<std::mutex> lock(mutex_);
  try {
    std::optional<Eigen::Isometry3d> pose;
    if (request.set_object_pose) pose = fromPoseMsg(request.object_pose, "object_pose");
    sim_->reset(pose ? &*pose : nullptr);
    // The reset's frame shows the state the reset made (the object at rest where it was put),
    // as TactileHand::reset's does, so both give the same episodes; it has a stamp of its own so
    // that stamps keep increasing.
    ++frame_;
    opening_command_ = 1.0;
    publishEpisode();
    publishFrame();
    lock_step_->drain(frame_pub_);
  } catch (const Error& e) {
    response.success = false;
    response.message = std::string("~reset refused: ") + e.what();
    ROS_WARN("hand_sim: %s", response.message.c_str());
    return true;
  }
  response.success = true;
  response.stamp = frameStamp();
  response.frame = static_cast<std::uint64_t>(frame_);
  response.state = state();
  return true;
}

bool HandSimRos::onStep(HandStep::Request& request, HandStep::Response& response) {
  std::lock_guard<std::mutex> lock(mutex_);
  response.success = false;
  if (request.frames < 1 || request.frames > 100000) {
    response.message =
        "~step frames = " + std::to_string(request.frames) + " refused; valid: [1, 100000]";
    ROS_WARN("hand_sim: %s", response.message.c_str());
    return true;
  }
  // Checked before anything is set: a refusal changes nothing.
  std::optional<Eigen::Isometry3d> base;
  try {
    if (request.set_base_pose) base = fromPoseMsg(request.base_pose, "base_pose");
    if (!request.targets.name.empty()) {
      warnClamped(sim_->setJointTargets(request.targets.name, request.targets.position));
    }
    // Before this step's physics, reached over its first frame as a ~base_pose message is, but
    // ordered with the frames. setBasePose takes every pose fromPoseMsg gave: once the targets
    // are set, nothing is refused.
    if (base) sim_->setBasePose(*base, frame_period_ns_ * 1e-9);
  } catch (const Error& e) {
    response.message = std::string("~step refused, nothing changed: ") + e.what();
    ROS_WARN("hand_sim: %s", response.message.c_str());
    return true;
  }
  response.missing_images = 0;
  try {
    for (std::uint32_t i = 0; i < request.frames; ++i) {
      sim_->step(ticks_per_frame_);
      ++frame_;
      response.missing_images += publishFrame();
    }
    response.missing_images += lock_step_->drain(frame_pub_);
  } catch (const Error& e) {
    ROS_ERROR("hand_sim: ~step failed at frame %ld: %s", static_cast<long>(frame_), e.what());
    response.message = "~step failed at frame " + std::to_string(frame_) + ": " + e.what();
    return true;
  }
  response.success = true;
  response.stamp = frameStamp();
  response.frame = static_cast<std::uint64_t>(frame_);
  response.state = state();
  return true;
}

HandState HandSimRos::state() const {
  HandState out;
  for (int s = 0; s < sim_->sensorCount(); ++s) {
    const GelContactState& contact = sim_->contact(s);
    out.sensors.push_back(sim_->sensor(s).name);
    out.in_contact.push_back(contact.in_contact);
    out.normal_force.push_back(contact.normal_force_n);
    geometry_msgs::Vector3 shear;
    tf2::toMsg(contact.shear_force_n, shear);
    out.shear_force.push_back(shear);
    out.penetration.push_back(contact.penetration_m);
    geometry_msgs::Point centre;
    centre.x = contact.pressure_centre_m.x();
    centre.y = contact.pressure_centre_m.y();
    out.pressure_centre.push_back(centre);
    out.twist_moment.push_back(contact.twist_moment_nm);
    out.too_deep.push_back(contact.too_deep);
    out.object_in_gel.push_back(tf2::toMsg(contact.object_in_gel));
  }
  out.joints = sim_->actuatedJoints();
  for (const std::string& name : out.joints) {
    const int j = sim_->description().jointIndex(name);
    out.joint_positions.push_back(sim_->jointPositions()[j]);
    out.joint_targets.push_back(sim_->jointTargets()[j]);
  }
  out.object_in_world = tf2::toMsg(sim_->objectInWorld());
  return out;
}

void HandSimRos::onTick(const ros::WallTime& scheduled) {
  // One frame a tick, stamped with the tick's time on the grid (wall clock): the stamps say when
  // the frame was due, whatever the start-up took, so a subscriber's latency is its own. A tick
  // that ran late is not made up: the frames it missed are skipped (their stamps with them).
  {
    std::lock_guard<std::mutex> lock(mutex_);
    sim_->step(ticks_per_frame_);
    ++frame_;
    time_base_ = ros::Time(scheduled.sec, scheduled.nsec) -
                 (ros_conversions::toRosTime(frame_ * frame_period_ns_) - ros::Time(0));
    publishFrame();
  }
  if ((ros::WallTime::now() - scheduled).toNSec() > 4 * frame_period_ns_) {
    ROS_WARN_THROTTLE(5.0, "hand_sim: behind real time; skipping frames");
  }
}

}  // namespace norm2tex
