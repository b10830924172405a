#include "probe_sim.hpp"

#include <algorithm>
#include <filesystem>

#include <rosgraph_msgs/Clock.h>
#include <tf2_msgs/TFMessage.h>

#include "conversions.hpp"
#include "markers.hpp"
#include "norm2tex/SimFrame.h"
#include "norm2tex/TactileContact.h"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/memory_reuse.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/gripper_sim_config.hpp"
#include "params.hpp"

namespace norm2tex {
namespace {

using ros_params::badParameter;
using ros_params::readParam;
using ros_params::packageFile;
using ros_params::text;

/// "all" = every shipped material (sorted); else a comma-separated list of names.
std::vector<std::string> materialList(const std::string& spec) {
  std::vector<std::string> names;
  if (spec == "all") {
    for (const auto& entry : std::filesystem::directory_iterator(packageFile("config/materials"))) {
      if (entry.path().extension() == ".yaml") names.push_back(entry.path().stem().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }
  std::string name;
  for (std::size_t i = 0; i <= spec.size(); ++i) {
    if (i == spec.size() || spec[i] == ',') {
      if (name.empty()) badParameter("material", "'" + spec + "'", "a name, a,b,c or all");
      names.push_back(name);
      name.clear();
    } else if (spec[i] != ' ') {
      name += spec[i];
    }
  }
  return names;
}

}  // namespace

ProbeSimParams readProbeSimParams(const ros::NodeHandle& pnh) {
  ProbeSimParams p;
  readParam<std::string>(pnh, "sensor_name", p.sensor_name, p.sensor_name);
  if (p.sensor_name.empty() || p.sensor_name.find(' ') != std::string::npos) {
    badParameter("sensor_name", "'" + p.sensor_name + "'", "a topic name such as digit_left");
  }
  readParam<std::string>(pnh, "sensor", p.sensor, packageFile("config/digit.yaml"));
  readParam<std::string>(pnh, "scene", p.scene, packageFile("config/scenes/cube.yaml"));
  readParam<std::string>(pnh, "mesh", p.mesh, "");
  readParam(pnh, "scale", p.scale, p.scale);
  if (!(p.scale > 0.0 && p.scale <= 1000.0)) badParameter("scale", text(p.scale), "(0, 1000]");
  std::string material = "wood";
  readParam<std::string>(pnh, "material", material, material);
  p.materials = materialList(material);
  for (const std::string& name : p.materials) ros_params::materialConfigPath(name, ", all");
  readParam(pnh, "variants", p.variants, p.variants);
  if (p.variants == 0 || p.variants > 10000) {
    badParameter("variants", text(p.variants), "[1, 10000], or < 0 for each material's count");
  }
  readParam(pnh, "samples", p.samples, p.samples);
  if (p.samples < 1) badParameter("samples", text(p.samples), ">= 1 images per material");
  int seed = 0;
  readParam(pnh, "seed", seed, seed);
  if (seed < 0) badParameter("seed", text(seed), ">= 0");
  p.seed = seed;
  readParam(pnh, "num_shards", p.num_shards, p.num_shards);
  if (p.num_shards < 1) badParameter("num_shards", text(p.num_shards), ">= 1");
  readParam(pnh, "shard", p.shard, p.shard);
  if (p.shard < 0 || p.shard >= p.num_shards) {
    badParameter("shard", text(p.shard), "[0, ~num_shards - 1]");
  }
  readParam(pnh, "press_depth_min", p.probe.press_depth_min_m, p.probe.press_depth_min_m);
  readParam(pnh, "press_depth_max", p.probe.press_depth_max_m, p.probe.press_depth_max_m);
  readParam(pnh, "slides", p.probe.slides_per_press, p.probe.slides_per_press);
  readParam(pnh, "slide_step", p.probe.slide_step_max_m, p.probe.slide_step_max_m);
  try {
    validate(p.probe);
  } catch (const Error& e) {
    throw Error(std::string(e.what()) +
                " (~press_depth_min/max, ~slides, ~slide_step set these, in metres)");
  }
  readParam(pnh, "beta", p.beta, p.beta);
  readParam(pnh, "frame_rate", p.frame_rate, p.frame_rate);
  if (!(p.frame_rate >= 1.0 && p.frame_rate <= 1000.0)) {
    badParameter("frame_rate", text(p.frame_rate), "[1, 1000] Hz");
  }
  readLockStepParams(pnh, p.renderers, p.render_timeout, p.ready_timeout);
  readParam(pnh, "autostart", p.autostart, p.autostart);
  readParam(pnh, "window", p.window, p.window);
  if (p.window < 1 || p.window > 64) badParameter("window", text(p.window), "[1, 64] frames");
  return p;
}

ProbeSim::ProbeSim(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : params_(readProbeSimParams(private_nh)), nh_(nh), private_nh_(private_nh) {
  keepFreedMemoryForReuse();  // frames, bags and textures reuse memory, not fault it in
  if (!ros::Time::isSimTime()) {
    throw Error(
        "probe_sim needs /use_sim_time = true (it is a synchronous frame source); set it before "
        "the nodes start, as record_dataset.launch does");
  }
  sensor_ = loadSensorModel(params_.sensor);
  const GripperSimConfig scene = loadGripperSimConfig(params_.scene);
  gel_law_ = scene.gel_law;
  object_ = params_.mesh.empty() ? loadObjectMesh(scene.object.mesh, scene.object.scale)
                                 : loadObjectMesh(params_.mesh, params_.scale);
  object_name_ = params_.mesh.empty() ? scene.object.name
                                      : std::filesystem::path(params_.mesh).stem().string();
  meter_ = std::make_unique<ContactPatchMeter>(sensor_);

  std::vector<std::pair<std::string, int>> plan;
  std::vector<double> material_beta;
  for (const std::string& name : params_.materials) {
    const MaterialConfig material = loadMaterialConfig(ros_params::materialConfigPath(name));
    plan.emplace_back(name, params_.variants > 0 ? params_.variants : material.variant_count);
    material_beta.push_back(params_.beta >= 0.0 ? params_.beta : material.beta_mm);
  }
  const int frames_per_press = 1 + params_.probe.slides_per_press;
  schedule_ = std::make_unique<ProbeSchedule>(plan, params_.samples, frames_per_press,
                                              static_cast<std::uint64_t>(params_.seed),
                                              params_.shard, params_.num_shards);
  for (const ProbeBlock& block : schedule_->blocks()) {
    const auto m = std::find(params_.materials.begin(), params_.materials.end(), block.material);
    block_beta_.push_back(material_beta[m - params_.materials.begin()]);
  }
  period_ns_ = std::llround(1e9 / params_.frame_rate);

  tf_pub_ = nh_.advertise<tf2_msgs::TFMessage>("/tf", 100);
  clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 10);
  episode_pub_ = nh_.advertise<EpisodeInfo>("episode", 1, /*latch=*/true);
  frame_pub_ = private_nh_.advertise<SimFrame>("frame", 100);
  contact_pub_ = nh_.advertise<TactileContact>(params_.sensor_name + "/contact", 10);
  marker_pub_ = private_nh_.advertise<visualization_msgs::Marker>("object_marker", 1, true);
  marker_pub_.publish(ros_conversions::objectMarker(object_.mesh, ros::Time(0)));
  lock_step_ = std::make_unique<LockStep>(private_nh_, params_.renderers, params_.render_timeout,
                                          params_.ready_timeout, "probe_sim", params_.window);
  ros::NodeHandle service_nh(private_nh_);
  service_nh.setCallbackQueue(&service_queue_);
  if (!params_.autostart) step_srv_ = service_nh.advertiseService("step", &ProbeSim::onStep, this);
  service_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &service_queue_);
  service_spinner_->start();
  ROS_INFO(
      "probe_sim: %zu material(s), %zu texture blocks, shard %d of %d: %lu frames in %zu "
      "presses of up to %d frames; object %s",
      params_.materials.size(), schedule_->blocks().size(), params_.shard, params_.num_shards,
      static_cast<unsigned long>(schedule_->frames()), schedule_->presses().size(),
      frames_per_press, params_.mesh.empty() ? scene.object.mesh.c_str() : params_.mesh.c_str());
  {
    rosgraph_msgs::Clock clock;
    clock.clock = stamp();
    clock_pub_.publish(clock);
  }
  started_ = ros::WallTime::now();
  if (params_.autostart) runner_ = std::thread([this] { run(); });
}

ProbeSim::~ProbeSim() {
  stop_ = true;
  if (lock_step_) lock_step_->cancel();  // the runner may be waiting for the renderers
  if (runner_.joinable()) runner_.join();
  service_queue_.disable();  // wakes its spinner at once instead of at its next 0.1 s poll
  if (service_spinner_) service_spinner_->stop();
}

ros::Time ProbeSim::stamp() const {
  return ros_conversions::toRosTime(frame_ * period_ns_ + period_ns_);  // never time 0
}

void ProbeSim::run() {
  try {
    // Nothing of the first frame may go out before every listener is connected and ready.
    lock_step_->waitUntilReady();
    while (!stop_ && ros::ok()) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!advanceFrame()) break;
    }
  } catch (const Error& e) {
    // Unloaded or shut down meanwhile: nothing failed.
    if (stop_ || !ros::ok()) return;
    ROS_ERROR("probe_sim: stopped at frame %ld of %lu: %s", static_cast<long>(frame_),
              static_cast<unsigned long>(schedule_->frames()), e.what());
  }
}

bool ProbeSim::onStep(Step::Request& request, Step::Response& response) {
  std::lock_guard<std::mutex> lock(mutex_);
  // Refusals and failures reach the caller as success = false and the reason (a service that
  // returns false sends its caller no text), and go to the log as before.
  auto fail = [&](const std::string& message) {
    response.success = false;
    response.message = message;
    return true;
  };
  if (request.frames < 1 || request.frames > 100000 || request.set_command) {
    const std::string message =
        "~step frames = " + std::to_string(request.frames) +
        (request.set_command ? " with a gripper command" : "") +
        " refused; valid: [1, 100000] frames, no command (the probe has no gripper)";
    ROS_WARN("probe_sim: %s", message.c_str());
    return fail(message);
  }
  response.missing_images = 0;
  try {
    for (std::uint32_t i = 0; i < request.frames; ++i) {
      if (!advanceFrame()) {
        const std::string message =
            "the plan's " + std::to_string(schedule_->frames()) + " frames are done";
        ROS_WARN("probe_sim: %s", message.c_str());
        return fail(message);
      }
    }
    const std::uint32_t missing = lock_step_->drain(frame_pub_);
    response.missing_images += missing;
    missing_images_ += missing;
  } catch (const Error& e) {
    ROS_ERROR("probe_sim: ~step failed at frame %ld: %s", static_cast<long>(frame_), e.what());
    return fail("~step failed at frame " + std::to_string(frame_) + ": " + e.what());
  }
  response.stamp = ros_conversions::toRosTime((frame_ - 1) * period_ns_ + period_ns_);
  response.success = true;
  return true;
}

bool ProbeSim::advanceFrame() {
  lock_step_->waitUntilReady();                  // at once after the first time
  if (next_in_press_ >= press_frames_.size()) {  // the next press: a new episode
    if (next_press_ >= schedule_->presses().size()) return false;
    const ProbePress& press = schedule_->presses()[next_press_++];
    const ProbeBlock& block = schedule_->blocks()[press.block];
    if (press.block != scenario_block_) {
      scenario_ = std::make_unique<ProbeScenario>(object_.mesh, params_.probe, sensor_,
                                                  block.scenario_seed);
      scenario_block_ = press.block;
      next_texture_block_ = -1;
      for (std::size_t p = next_press_; p < schedule_->presses().size(); ++p) {
        const ProbeBlock& later = schedule_->blocks()[schedule_->presses()[p].block];
        if (later.material != block.material || later.variant != block.variant) {
          next_texture_block_ = schedule_->presses()[p].block;
          break;
        }
      }
    }
    press_frames_ = scenario_->press(press.press);
    press_frames_.resize(press.frames);
    next_in_press_ = 0;
    EpisodeInfo info;
    info.header.stamp = stamp();
    info.header.frame_id = "world";
    info.episode = ++episode_;
    info.object = object_name_;
    info.material = block.material;
    info.variant = static_cast<std::uint32_t>(block.variant);
    info.beta = block_beta_[press.block];
    info.seed = static_cast<std::int64_t>(block.scenario_seed & 0x7fffffffffffffffull);
    info.scenario = "probe";
    info.shard = static_cast<std::uint32_t>(params_.shard);
    info.num_shards = static_cast<std::uint32_t>(params_.num_shards);
    info.press = press.press;
    info.press_depth = press_frames_.front().press_depth_m;
    episode_pub_.publish(info);
  }
  const ProbeFrame& probe = press_frames_[next_in_press_++];
  const ProbeBlock& block = schedule_->blocks()[scenario_block_];
  const ros::Time now = stamp();
  rosgraph_msgs::Clock clock;
  clock.clock = now;
  clock_pub_.publish(clock);

  tf2_msgs::TFMessage tf;
  auto stamped = [&](const std::string& child, const Eigen::Isometry3d& pose) {
    geometry_msgs::TransformStamped t;
    t.header.stamp = now;
    t.header.frame_id = "world";
    t.child_frame_id = child;
    t.transform = ros_conversions::toTransformMsg(pose);
    tf.transforms.push_back(t);
  };
  stamped("object", Eigen::Isometry3d::Identity());  // the object rests at the world origin
  stamped(params_.sensor_name + "_gel", probe.object_in_gel.inverse());
  tf_pub_.publish(tf);

  if (contact_pub_.getNumSubscribers() > 0) {
    std_msgs::Header header;
    header.stamp = now;
    header.frame_id = params_.sensor_name + "_gel";
    const ContactPatch patch = meter_->measure(object_.mesh, probe.object_in_gel);
    GelContactState state;
    state.in_contact = patch.pixels > 0;
    state.penetration_m = patch.max_indentation_m;
    state.normal_force_n = gel_law_.force(patch.max_indentation_m);  // held still: the law
    state.object_in_gel = probe.object_in_gel;
    contact_pub_.publish(ros_conversions::toContactMsg(header, params_.sensor_name, state, patch));
  }

  SimFrame frame;
  frame.header.stamp = now;
  frame.header.frame_id = "world";
  frame.frame = static_cast<std::uint64_t>(frame_);
  frame.episode = episode_;
  frame.acknowledge = lock_step_->waits();
  frame.material = block.material;
  frame.variant = static_cast<std::uint32_t>(block.variant);
  if (next_texture_block_ >= 0) {
    const ProbeBlock& next = schedule_->blocks()[next_texture_block_];
    frame.next_material = next.material;
    frame.next_variant = static_cast<std::uint32_t>(next.variant);
  }
  frame.last = next_press_ == schedule_->presses().size() && next_in_press_ == press_frames_.size();
  ++frame_;
  missing_images_ += lock_step_->publish(frame_pub_, frame);
  if (frame.last) {
    missing_images_ += lock_step_->drain(frame_pub_);
    const double seconds = (ros::WallTime::now() - started_).toSec();
    ROS_INFO(
        "probe_sim: done, %ld frames of %zu presses in %.1f s (%.0f frames/s), %lu images "
        "missing",
        static_cast<long>(frame_), schedule_->presses().size(), seconds, frame_ / seconds,
        static_cast<unsigned long>(missing_images_));
  }
  return true;
}

}  // namespace norm2tex
