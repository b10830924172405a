#include "contact_sim.hpp"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <sstream>

#include <ros/package.h>
#include <chrono>

#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "conversions.hpp"
#include "markers.hpp"
#include "norm2tex/SimFrame.h"
#include "norm2tex/TactileContact.h"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/memory_reuse.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/render/object_texture.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/contact_shear_load.hpp"
#include "norm2tex/sim/hand_sim.hpp"
#include "norm2tex/sim/tactile_gripper_batch.hpp"
#include "params.hpp"

namespace norm2tex {
namespace {

// One set of command values (norm2tex/envs/commands.py, docs/ros.md "One table"): the core's
// batch modes are the message's.
static_assert(static_cast<int>(OpeningCommand::kAbsolute) == GripperCommand::ABSOLUTE &&
                  static_cast<int>(OpeningCommand::kDelta) == GripperCommand::DELTA,
              "OpeningCommand and GripperCommand.msg must share their values");

using ros_params::badParameter;
using ros_params::materialConfigPath;
using ros_params::packageFile;
using ros_params::readParam;
using ros_params::text;

const char* const kSensorNames[2] = {"digit_left", "digit_right"};
const char* const kGelFrames[2] = {"digit_left_gel", "digit_right_gel"};
const char* const kFingerFrames[2] = {"finger_left", "finger_right"};

/// The gripper's state at the current frame, into a ~step or ~reset response (same field names).
template <typename Response>
void fillState(const GripperSim& sim, std::int64_t frame, Response& response) {
  response.frame = static_cast<std::uint64_t>(frame);
  response.opening = sim.opening();
  response.dropped = sim.dropped();
  for (int i = 0; i < 2; ++i) {
    const GelContactState& state = sim.contact(static_cast<Finger>(i));
    response.in_contact[i] = state.in_contact;
    response.normal_force[i] = state.normal_force_n;
    response.penetration[i] = state.penetration_m;
    response.too_deep[i] = state.too_deep;
  }
}

}  // namespace

ContactSimParams readContactSimParams(const ros::NodeHandle& pnh) {
  ContactSimParams p;
  readSimNodeParams(pnh, p);
  int seed = 0;
  readParam(pnh, "seed", seed, 0);
  if (seed < 0) badParameter("seed", text(seed), ">= 0");
  p.seed = seed;
  readParam(pnh, "height_offset", p.height_offset, std::nan(""));
  readParam(pnh, "variant", p.variant, 0);
  if (p.variant < 0) badParameter("variant", text(p.variant), ">= 0");
  readParam<std::string>(pnh, "scenario", p.scenario, p.scenario);
  readParam(pnh, "window", p.window, p.window);
  if (p.window < 1 || p.window > 64) badParameter("window", text(p.window), "[1, 64] frames");
  readParam<std::string>(pnh, "trace_file", p.trace_file, "");
  return p;
}

ContactSim::ContactSim(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : params_(readContactSimParams(private_nh)),
      trace_(params_.trace_file, {"woke", "physics", "tf", "frame"}),
      nh_(nh),
      private_nh_(private_nh) {
  keepFreedMemoryForReuse();  // frames, bags and textures reuse memory, not fault it in
  SimNodeScene scene = makeSimNodeScene(params_);
  // The labels say what the renderers draw: a material's beta, or a texture file's default.
  beta_mm_ = scene.beta_mm;
  const double friction = scene.friction;
  const SensorModel& sensor = scene.sensor;
  GripperSimConfig& config = scene.config;
  ticks_per_frame_ = scene.ticks_per_frame;
  frame_period_ns_ = scene.frame_period_ns;
  sim_ = std::make_unique<GripperSim>(config);
  {
    // For clients (the Python RosBackend), before the services appear: the offsets ~reset
    // accepts, [low, high] m.
    const auto [low, high] = sim_->heightOffsetRange();
    private_nh_.setParam("height_offset_range", std::vector<double>{low, high});
  }
  for (int i = 0; i < 2; ++i) meters_[i] = std::make_unique<ContactPatchMeter>(sensor);

  const bool use_sim_time = ros::Time::isSimTime();
  if (params_.synchronous && !use_sim_time) {
    throw Error(
        "~mode = synchronous needs /use_sim_time = true (simulated time advances only "
        "through ~step); set it before the nodes start, as gripper_sim.launch does");
  }
  owns_clock_ = use_sim_time;

  tf_pub_ = nh_.advertise<tf2_msgs::TFMessage>("/tf", 100);
  // Only the clock's owner advertises /clock: a silent publisher would let a node that waits for
  // simulated time believe a clock is there.
  if (owns_clock_) clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 10);
  frame_pub_ = private_nh_.advertise<SimFrame>("frame", 100);
  markers_pub_ = private_nh_.advertise<visualization_msgs::MarkerArray>("markers", 2);
  object_marker_pub_ = private_nh_.advertise<visualization_msgs::Marker>("object_marker", 1, true);
  joints_pub_ = nh_.advertise<sensor_msgs::JointState>("joint_states", 10);
  episode_pub_ = nh_.advertise<EpisodeInfo>("episode", 1, /*latch=*/true);
  episode_state_pub_ = nh_.advertise<EpisodeState>("episode_state", 1, /*latch=*/true);
  for (int i = 0; i < 2; ++i) {
    contact_pub_[i] = nh_.advertise<TactileContact>(std::string(kSensorNames[i]) + "/contact", 10);
  }
  startEpisode(params_.seed, params_.height_offset);
  publishStaticTransforms();

  lock_step_ = std::make_unique<LockStep>(
      private_nh_, params_.synchronous ? params_.renderers : std::vector<std::string>(),
      params_.render_timeout, params_.ready_timeout, "contact_sim", params_.window);
  command_sub_ = nh_.subscribe("gripper/command", 10, &ContactSim::onCommand, this);
  // ~reset and ~step block while the renderers work: they get a thread of their own, so that in
  // a nodelet manager they never hold a worker thread a renderer's queue is pinned to.
  ros::NodeHandle service_nh(private_nh_);
  service_nh.setCallbackQueue(&service_queue_);
  reset_srv_ = service_nh.advertiseService("reset", &ContactSim::onReset, this);
  if (params_.synchronous) {
    step_srv_ = service_nh.advertiseService("step", &ContactSim::onStep, this);
  }
  service_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &service_queue_);
  service_spinner_->start();
  object_marker_pub_.publish(ros_conversions::objectMarker(sim_->object().mesh, ros::Time(0)));
  {
    // The services already run: the first frame is published under the same lock.
    std::lock_guard<std::mutex> lock(mutex_);
    // Synchronous renderers get their first frame with the first step (or reset); publishing
    // one now would wait for renderers that may not have started yet.
    if (!params_.synchronous || params_.renderers.empty()) publishFrame();
  }
  // Last: the clock's ticks may only come once everything above is in place.
  if (!params_.synchronous) {
    clock_ = std::make_unique<WallClockGrid>(
        frame_period_ns_,
        [this](const ros::WallTime& tick, std::int64_t woke_ns) { onTick(tick, woke_ns); },
        trace_.enabled());
  }
  ROS_INFO(
      "contact_sim: %s mode, scene %s, material %s (friction %.2f), physics %.0f Hz "
      "(%d ticks per %.1f Hz frame), object '%s' %s",
      params_.synchronous ? "synchronous" : "real-time", params_.scene.c_str(),
      params_.material.c_str(), friction, config.physics.rate_hz, ticks_per_frame_,
      params_.frame_rate, config.object.name.c_str(), config.object.mesh.c_str());
  const ObjectCollision& collision = sim_->collision();
  ROS_INFO(
      "contact_sim: the object collides as %s (%d part%s; its hull bridges hollows %.2f mm "
      "deep where the gels reach)",
      collision.kind.c_str(), collision.parts, collision.parts == 1 ? "" : "s",
      collision.hull_deviation_m * 1e3);
  const auto [low, high] = sim_->heightOffsetRange();
  if (low > config.episode.height_offset_low_m || high < config.episode.height_offset_high_m) {
    ROS_INFO(
        "contact_sim: height offsets %.1f-%.1f mm (the scene's %.1f-%.1f mm where the "
        "object's sides meet the gel pads)",
        low * 1e3, high * 1e3, config.episode.height_offset_low_m * 1e3,
        config.episode.height_offset_high_m * 1e3);
  }
}

void ContactSim::publishStaticTransforms() {
  std::vector<geometry_msgs::TransformStamped> transforms;
  for (int i = 0; i < 2; ++i) {
    geometry_msgs::TransformStamped t;
    t.header.stamp = frameStamp();
    t.header.frame_id = kFingerFrames[i];
    t.child_frame_id = kGelFrames[i];
    t.transform = ros_conversions::toTransformMsg(sim_->gelInFingerFrame(static_cast<Finger>(i)));
    transforms.push_back(t);
  }
  static_tf_ = std::make_unique<tf2_ros::StaticTransformBroadcaster>();
  static_tf_->sendTransform(transforms);
}

ros::Time ContactSim::frameStamp() const {
  return time_base_ + (ros_conversions::toRosTime(frame_ * frame_period_ns_) - ros::Time(0));
}

EpisodeInfo ContactSim::startEpisode(std::int64_t seed, double height_offset) {
  const EpisodeStart start =
      sim_->reset(static_cast<std::uint64_t>(seed),
                  std::isnan(height_offset) ? std::nullopt : std::optional<double>(height_offset));
  // Pad the settle to whole frames: every frame stays on the physics clock's grid.
  const std::int64_t ticks = sim_->ticks();
  sim_->step(static_cast<int>((ticks_per_frame_ - ticks % ticks_per_frame_) % ticks_per_frame_));
  frame_ = sim_->ticks() / ticks_per_frame_;
  wall_anchor_ = ros::WallTime();  // real time restarts from here
  if (!owns_clock_) {
    // Wall-clock stamps: simulated time maps onto now (a reset's settling time is skipped);
    // the timer's first frame re-anchors it, so stamps sit on the timer's grid.
    anchor_to_wall_ = true;
    time_base_ =
        ros::Time::now() - (ros_conversions::toRosTime(frame_ * frame_period_ns_) - ros::Time(0));
  } else {
    rosgraph_msgs::Clock clock;
    clock.clock = frameStamp();
    clock_pub_.publish(clock);
  }
  EpisodeInfo info;
  info.header.stamp = frameStamp();
  info.header.frame_id = "world";
  info.episode = ++episode_;
  info.object = sim_->config().object.name;
  info.material = params_.material;
  info.variant = static_cast<std::uint32_t>(params_.variant);
  info.beta = beta_mm_;
  info.seed = seed;
  info.scenario = params_.scenario;
  info.height_offset = start.height_offset_m;
  info.num_shards = 1;
  episode_pub_.publish(info);
  episode_state_.header = info.header;
  episode_state_.episode = info.episode;
  episode_state_.dropped = sim_->dropped();
  episode_state_.too_deep = tooDeep();
  episode_state_pub_.publish(episode_state_);
  return info;
}

bool ContactSim::tooDeep() const {
  return sim_->contact(Finger::kLeft).too_deep || sim_->contact(Finger::kRight).too_deep;
}

void ContactSim::publishStateChange(const ros::Time& stamp) {
  const bool too_deep = episode_state_.too_deep || tooDeep();  // latched for the episode
  if (sim_->dropped() == episode_state_.dropped && too_deep == episode_state_.too_deep) return;
  if (too_deep && !episode_state_.too_deep) {
    const double deepest = std::max(sim_->contact(Finger::kLeft).penetration_m,
                                    sim_->contact(Finger::kRight).penetration_m);
    ROS_WARN(
        "contact_sim: episode %u: the object is %.2f mm into a gel, deeper than the gel "
        "law's table reaches (%.2f mm): its forces are extrapolated",
        episode_, deepest * 1e3, sim_->config().gel_law.points().back().first * 1e3);
  }
  episode_state_.header.stamp = stamp;
  episode_state_.dropped = sim_->dropped();
  episode_state_.too_deep = too_deep;
  episode_state_pub_.publish(episode_state_);
  if (episode_state_.dropped) {
    ROS_INFO("contact_sim: episode %u: the object dropped out of the gripper", episode_);
  }
}

void ContactSim::applyCommandOrThrow(const GripperCommand& command) {
  if (command.mode == GripperCommand::ABSOLUTE) {
    sim_->setOpening(command.opening);
  } else if (command.mode == GripperCommand::DELTA) {
    sim_->addOpening(command.opening);
  } else {
    throw Error("gripper command mode " + std::to_string(command.mode) +
                " is not valid; valid: 0 (ABSOLUTE), 1 (DELTA)");
  }
}

bool ContactSim::applyCommand(const GripperCommand& command) {
  try {
    applyCommandOrThrow(command);
    return true;
  } catch (const Error& e) {
    ROS_WARN_THROTTLE(1.0, "contact_sim: command rejected, nothing changed: %s", e.what());
    return false;
  }
}

void ContactSim::onCommand(const GripperCommand::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  applyCommand(*msg);
}

bool ContactSim::onReset(Reset::Request& request, Reset::Response& response) {
  std::lock_guard<std::mutex> lock(mutex_);
  // Refusals and failures reach the caller as success = false and the reason (a service that
  // returns false sends its caller no text); the log says it too.
  if (request.seed < 0) {
    response.success = false;
    response.message = "~reset seed " + std::to_string(request.seed) + " refused; valid: >= 0";
    ROS_WARN("contact_sim: %s", response.message.c_str());
    return true;
  }
  // A new texture is checked before anything changes; it applies from the episode's first frame.
  std::string material = params_.material;
  int variant = params_.variant;
  double beta_mm = beta_mm_;
  std::string next_material;  // announced only with set_texture
  if (request.set_texture) {
    if (!request.material.empty()) material = request.material;
    variant = static_cast<int>(request.variant);
    try {
      if (material == ros_params::kNoMaterial || request.variant > 100000) {
        throw Error(
            "set_texture needs a material of config/materials/ and a variant in [0, "
            "100000]; got material '" +
            material + "', variant " + std::to_string(request.variant));
      }
      const std::string path = materialConfigPath(material);  // throws for an unknown one
      if (!request.next_material.empty()) {
        if (request.next_variant > 100000) {
          throw Error("next_variant " + std::to_string(request.next_variant) +
                      " out of range; valid: [0, 100000]");
        }
        materialConfigPath(request.next_material);  // an unknown one is refused now
        next_material = request.next_material;
      }
      if (material != params_.material && params_.beta < 0.0) {
        beta_mm = loadMaterialConfig(path).beta_mm;  // the label of what the renderers draw
      }
    } catch (const Error& e) {
      response.success = false;
      response.message = std::string("~reset refused: ") + e.what();
      ROS_WARN("contact_sim: %s", response.message.c_str());
      return true;
    }
  }
  try {
    const std::string old_material = params_.material;
    const int old_variant = params_.variant;
    const double old_beta = beta_mm_;
    const std::string old_next_material = next_material_;
    const std::uint32_t old_next_variant = next_variant_;
    params_.material = material;
    params_.variant = variant;
    beta_mm_ = beta_mm;
    next_material_ = next_material;
    next_variant_ = next_material.empty() ? 0 : request.next_variant;
    try {
      response.info = startEpisode(request.seed, request.height_offset);
    } catch (const Error&) {
      params_.material = old_material;  // refused: nothing changed
      params_.variant = old_variant;
      beta_mm_ = old_beta;
      next_material_ = old_next_material;
      next_variant_ = old_next_variant;
      throw;
    }
    response.grasp_opening = sim_->commandedOpening();
    fillState(*sim_, frame_, response);
    publishFrame();
    lock_step_->drain(frame_pub_);
  } catch (const Error& e) {
    response.success = false;
    response.message = std::string("~reset refused: ") + e.what();
    ROS_WARN("contact_sim: %s", response.message.c_str());
    return true;
  }
  response.success = true;
  return true;
}

bool ContactSim::onStep(Step::Request& request, Step::Response& response) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto fail = [&](const std::string& message) {
    response.success = false;
    response.message = message;
    response.opening = sim_->opening();
    response.dropped = sim_->dropped();
    return true;
  };
  if (request.frames < 1 || request.frames > 100000) {
    const std::string message =
        "~step frames = " + std::to_string(request.frames) + " refused; valid: [1, 100000]";
    ROS_WARN("contact_sim: %s", message.c_str());
    return fail(message);
  }
  if (request.set_command) {
    try {
      applyCommandOrThrow(request.command);
    } catch (const Error& e) {
      ROS_WARN("contact_sim: ~step refused, nothing changed: %s", e.what());
      return fail(std::string("~step refused, nothing changed: ") + e.what());
    }
  }
  response.missing_images = 0;
  try {
    for (std::uint32_t i = 0; i < request.frames; ++i) {
      sim_->step(ticks_per_frame_);
      ++frame_;
      response.missing_images += publishFrame();
    }
    // Returns only once every frame of the step is answered: its images are all out.
    response.missing_images += lock_step_->drain(frame_pub_);
  } catch (const Error& e) {
    ROS_ERROR("contact_sim: ~step failed at frame %ld: %s", static_cast<long>(frame_), e.what());
    return fail("~step failed at frame " + std::to_string(frame_) + ": " + e.what());
  }
  response.success = true;
  response.stamp = frameStamp();
  response.commanded_opening = sim_->commandedOpening();
  fillState(*sim_, frame_, response);
  return true;
}

ContactSim::~ContactSim() {
  if (clock_) clock_->requestStop();
  if (lock_step_) lock_step_->cancel();  // a ~step or ~reset may be waiting for the renderers
  clock_.reset();
  service_queue_.disable();  // wakes its spinner at once instead of at its next 0.1 s poll
  if (service_spinner_) service_spinner_->stop();
}

void ContactSim::onTick(const ros::WallTime& tick_time, std::int64_t woke_ns) {
  std::lock_guard<std::mutex> lock(mutex_);
  // Physics follows the wall clock: a late tick (a loaded machine) catches up by stepping the
  // frames that are due, at most a few at a time; further behind, it warns and lets them go.
  // Time is the tick's scheduled time, not when it ran: the stamps sit on the clock's grid, so
  // a tick handled late delays the images, which the latency then shows, instead of shifting
  // every later frame by a period.
  constexpr int kMaxCatchUp = 4;
  const ros::WallTime tick = tick_time;
  tick_ = tick;
  if (wall_anchor_.isZero()) {  // first tick of an episode
    wall_anchor_ = tick;
    anchor_frame_ = frame_;
  }
  // A frame is due when its tick comes; kEarlyNs absorbs the rounding of the period to whole
  // nanoseconds.
  constexpr std::int64_t kEarlyNs = 1'000'000;
  const std::int64_t due =
      anchor_frame_ + 1 + ((tick - wall_anchor_).toNSec() + kEarlyNs) / frame_period_ns_;
  int stepped = 0;
  while (frame_ < due && stepped < kMaxCatchUp) {
    advanceFrame(woke_ns);
    ++stepped;
  }
  if (frame_ < due) {
    ROS_WARN_THROTTLE(5.0, "contact_sim: %ld frames behind real time; skipping them",
                      static_cast<long>(due - frame_));
    wall_anchor_ = tick;
    anchor_frame_ = frame_ - 1;
  }
}

void ContactSim::advanceFrame(std::int64_t woke_ns) {
  sim_->step(ticks_per_frame_);
  ++frame_;
  if (anchor_to_wall_) {
    // The first frame's stamp is its tick's scheduled time (real time), or now.
    const ros::Time first = tick_.isZero() ? ros::Time::now() : ros::Time(tick_.sec, tick_.nsec);
    time_base_ = first - (ros_conversions::toRosTime(frame_ * frame_period_ns_) - ros::Time(0));
    anchor_to_wall_ = false;
  }
  if (trace_.enabled()) {
    trace_.begin(frameStamp());
    trace_.markAt(kTraceWoke, woke_ns);
    trace_.mark(kTracePhysics);
  }
  publishFrame();
  trace_.end();
}

void ContactSim::waitForTfSubscribers() {
  // A renderer answers "ready" once it is subscribed, but its TF listener's connection to this
  // /tf publisher is made asynchronously: a first frame's TF sent before it is up was lost, and
  // that frame had no images ("source_frame object does not exist"). TF is not latched, so wait
  // (once) until as many /tf subscribers as ~renderers are connected: a connection takes
  // milliseconds; a listed node that reads no TF delays the first frame by at most 5 s.
  if (tf_connected_) return;
  const double wait_s = std::min(params_.ready_timeout, 5.0);
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(wait_s);
  while (tf_pub_.getNumSubscribers() < params_.renderers.size() && ros::ok() &&
         ros::WallTime::now() < deadline) {
    ros::WallDuration(0.005).sleep();
  }
  tf_connected_ = true;  // late ones show as frames without images, with the reason
}

std::uint32_t ContactSim::publishFrame() {
  const ros::Time stamp = frameStamp();
  const bool acknowledge = lock_step_->waits();
  if (acknowledge) {
    lock_step_->waitUntilReady();
    waitForTfSubscribers();
  }
  if (owns_clock_) {
    rosgraph_msgs::Clock clock;
    clock.clock = stamp;
    clock_pub_.publish(clock);
  }
  auto stamped = [&](const std::string& parent, const std::string& child,
                     const Eigen::Isometry3d& pose) {
    geometry_msgs::TransformStamped t;
    t.header.stamp = stamp;
    t.header.frame_id = parent;
    t.child_frame_id = child;
    t.transform = ros_conversions::toTransformMsg(pose);
    return t;
  };
  std::vector<geometry_msgs::TransformStamped> transforms;
  transforms.push_back(stamped("world", "gripper_base", sim_->baseInWorld()));
  for (int i = 0; i < 2; ++i) {
    const Finger finger = static_cast<Finger>(i);
    transforms.push_back(stamped("gripper_base", kFingerFrames[i], sim_->fingerInBase(finger)));
  }
  transforms.push_back(stamped("world", "object", sim_->objectInWorld()));
  tf2_msgs::TFMessage tf;
  tf.transforms = std::move(transforms);
  tf_pub_.publish(tf);
  trace_.mark(kTraceTf);

  publishStateChange(stamp);

  sensor_msgs::JointState joints;
  joints.header.stamp = stamp;
  if (sim_->hasOwnHand()) {
    // A hand's actuated joints by their URDF names (its finger frames are its sensors' links).
    const HandSim& hand = sim_->hand();
    joints.name = hand.actuatedJoints();
    for (const std::string& name : joints.name) joints.position.push_back(hand.jointPosition(name));
  } else {
    joints.name = {"finger_left_joint", "finger_right_joint"};
    joints.position = {sim_->fingerPosition(), sim_->fingerPosition()};
  }
  joints_pub_.publish(joints);

  for (int i = 0; i < 2; ++i) {
    const GelContactState& state = sim_->contact(static_cast<Finger>(i));
    // The patch costs a rasterization: skip it when nobody listens.
    if (contact_pub_[i].getNumSubscribers() == 0) continue;
    std_msgs::Header header;
    header.stamp = stamp;
    header.frame_id = kGelFrames[i];
    const ContactPatch patch =
        meters_[i]->measure(sim_->object().mesh, state.object_in_gel, state.normal_force_n,
                            shearLoadOf(state, sim_->config().object.friction));
    contact_pub_[i].publish(ros_conversions::toContactMsg(header, kSensorNames[i], state, patch));
  }

  if (markers_pub_.getNumSubscribers() > 0) {
    markers_pub_.publish(ros_conversions::gripperMarkers(*sim_, stamp));
  }

  SimFrame frame;
  frame.header.stamp = stamp;
  frame.header.frame_id = "world";
  frame.frame = static_cast<std::uint64_t>(frame_);
  frame.episode = episode_;
  frame.acknowledge = acknowledge;
  frame.material = params_.material;
  frame.variant = static_cast<std::uint32_t>(params_.variant);
  frame.next_material = next_material_;
  frame.next_variant = next_variant_;
  for (int i = 0; i < 2; ++i) {
    ros_conversions::addSensorLoad(frame, kSensorNames[i], sim_->contact(static_cast<Finger>(i)));
  }
  frame.friction = sim_->config().object.friction;
  // Lock-step: every renderer answers this frame before the next one is simulated.
  const std::uint32_t missing = lock_step_->publish(frame_pub_, frame);
  trace_.mark(kTraceFrame);
  return missing;
}

}  // namespace norm2tex
