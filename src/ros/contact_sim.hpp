#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "frame_trace.hpp"
#include "lock_step.hpp"
#include "norm2tex/EpisodeInfo.h"
#include "norm2tex/EpisodeState.h"
#include "norm2tex/GripperCommand.h"
#include "norm2tex/Reset.h"
#include "norm2tex/Step.h"
#include "norm2tex/sim/contact_patch.hpp"
#include "norm2tex/sim/gripper_sim.hpp"
#include "sim_node_params.hpp"
#include "wall_clock_grid.hpp"

namespace norm2tex {

/// Validated private parameters of contact_sim (docs/ros.md, "contact_sim"): the simulation
/// nodes' (SimNodeParams) and these.
struct ContactSimParams : SimNodeParams {
  std::int64_t seed = 0;           ///< ~seed: seed of the first episode
  double height_offset = 0;        ///< ~height_offset [m] of the first episode, NaN = random
  int variant = 0;                 ///< ~variant: texture variant, a label for EpisodeInfo
  std::string scenario = "grasp";  ///< ~scenario: label
  /// ~window: frames of one ~step in flight at once: the physics of the next frame runs while
  /// the renderers draw this one. Every ~step and ~reset still returns only once all of its
  /// frames are answered (1 = strict lock-step within a step too).
  int window = 2;
  /// ~trace_file: real time, write when each frame's stages were reached to this CSV at
  /// shutdown (scripts/ros_benchmark --trace); "" = none.
  std::string trace_file;
};

/// Reads and validates the private parameters; throws Error naming the parameter and its valid
/// range (or the file) at fault.
ContactSimParams readContactSimParams(const ros::NodeHandle& private_nh);

/// The contact_sim node's work, shared by the node and the nodelet: owns a GripperSim and
/// publishes every sensor frame over tf2, /joint_states, /digit_*/contact and /clock, and the
/// episode's labels and state on /episode and /episode_state.
class ContactSim {
 public:
  /// Throws Error (bad parameter, unreadable scene/mesh/material) before advertising anything.
  ContactSim(ros::NodeHandle nh, ros::NodeHandle private_nh);
  ~ContactSim();
  ContactSim(const ContactSim&) = delete;
  ContactSim& operator=(const ContactSim&) = delete;

 private:
  void onCommand(const GripperCommand::ConstPtr& msg);
  bool onReset(Reset::Request& request, Reset::Response& response);
  bool onStep(Step::Request& request, Step::Response& response);
  /// Real time: a frame period's tick of the clock (WallClockGrid); `woke_ns`: when the clock
  /// thread woke for it (for the trace).
  void onTick(const ros::WallTime& tick, std::int64_t woke_ns);

  /// Applies a command; false (and a throttled warning, nothing changed) when it is invalid.
  bool applyCommand(const GripperCommand& command);
  /// Applies a command; throws Error naming what is wrong (and changes nothing) when invalid.
  void applyCommandOrThrow(const GripperCommand& command);
  EpisodeInfo startEpisode(std::int64_t seed, double height_offset);
  /// The fixed finger -> gel transforms, once, on /tf_static.
  void publishStaticTransforms();
  /// Publishes /episode_state when the episode's state (a drop) differs from the last published.
  void publishStateChange(const ros::Time& stamp);
  /// Either gel holds the object deeper than the gel law's table reaches.
  bool tooDeep() const;
  /// Advances one sensor frame of physics and publishes it.
  void advanceFrame(std::int64_t woke_ns = 0);
  /// Before the first acknowledged frame: until every renderer listens on /tf (bounded).
  void waitForTfSubscribers();
  /// Publishes the current frame; in synchronous mode with ~renderers, waits for their answers.
  /// Returns how many of them published no image; throws Error when one did not answer in time.
  std::uint32_t publishFrame();
  ros::Time frameStamp() const;

  ContactSimParams params_;
  /// Real time, ~trace_file: the stages of each frame (the clock thread woke, its physics done,
  /// its TF sent, its SimFrame sent).
  enum TraceStage : std::size_t { kTraceWoke, kTracePhysics, kTraceTf, kTraceFrame };
  FrameTrace trace_;
  std::unique_ptr<GripperSim> sim_;
  std::unique_ptr<ContactPatchMeter> meters_[2];
  int ticks_per_frame_ = 17;
  std::int64_t frame_period_ns_ = 0;
  std::int64_t frame_ = 0;  ///< sensor frames since start (the simulated clock)
  ros::Time time_base_;     ///< added to simulated time: 0 with use_sim_time, else wall
  bool owns_clock_ = false;
  bool tf_connected_ = false;  ///< every renderer's TF listener was seen connected to /tf
  /// Real time with wall stamps: re-anchor simulated time on the wall clock at the next frame.
  bool anchor_to_wall_ = false;
  ros::WallTime wall_anchor_;  ///< real time: when frame anchor_frame_ + 1 was due
  std::int64_t anchor_frame_ = 0;
  ros::WallTime tick_;  ///< real time: the scheduled time of the timer tick being handled
  double beta_mm_ = 0.0;
  /// The texture the next episode will name (a ~reset's next_material/next_variant), announced
  /// in every frame so the renderers prepare it meanwhile; "" = none.
  std::string next_material_;
  std::uint32_t next_variant_ = 0;
  std::uint32_t episode_ = 0;
  EpisodeState episode_state_;  ///< as last published on /episode_state

  std::mutex mutex_;  // nodelet callbacks may run on several threads
  /// ~reset and ~step's queue: declared before the servers on it, which remove themselves from
  /// it when destroyed (a destroyed queue's mutex made the manager abort at shutdown).
  ros::CallbackQueue service_queue_;
  ros::NodeHandle nh_, private_nh_;
  ros::Publisher tf_pub_, clock_pub_, joints_pub_, episode_pub_, episode_state_pub_, frame_pub_,
      contact_pub_[2];
  ros::Publisher markers_pub_, object_marker_pub_;
  /// /tf_static (latched); made once everything is valid (it advertises when constructed).
  std::unique_ptr<tf2_ros::StaticTransformBroadcaster> static_tf_;
  ros::Subscriber command_sub_;
  ros::ServiceServer reset_srv_, step_srv_;

  /// Synchronous mode with ~renderers: waits for every renderer's answer to each frame.
  std::unique_ptr<LockStep> lock_step_;

  // Last: destroyed (stopped and joined) first, while everything its callbacks use exists.
  std::unique_ptr<ros::AsyncSpinner> service_spinner_;
  /// Real time: the frame clock (a thread woken at each tick; joined by the destructor).
  std::unique_ptr<WallClockGrid> clock_;
};

}  // namespace norm2tex
