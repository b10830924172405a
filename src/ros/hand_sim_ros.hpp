#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <geometry_msgs/PoseStamped.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <trajectory_msgs/JointTrajectory.h>

#include "lock_step.hpp"
#include "norm2tex/GripperCommand.h"
#include "norm2tex/HandReset.h"
#include "norm2tex/HandState.h"
#include "norm2tex/HandStep.h"
#include "norm2tex/sim/contact_patch.hpp"
#include "norm2tex/sim/hand_sim.hpp"
#include "sim_node_params.hpp"
#include "wall_clock_grid.hpp"

namespace norm2tex {

/// Validated private parameters of hand_sim (docs/ros.md, "hand_sim"): the simulation nodes'
/// (SimNodeParams; ~renderers absent: every sensor of the hand yaml) and these.
struct HandSimParams : SimNodeParams {
  std::string hand;  ///< ~hand: the hand yaml (docs/hands.md)
  std::vector<double> object_pose{0.0, 0.0, 0.1, 0.0, 0.0, 0.0};  ///< ~object_pose [x y z r p y]
  bool renderers_given = false;                                   ///< whether ~renderers was set
};

/// Reads and validates the private parameters; throws Error naming the one at fault.
HandSimParams readHandSimParams(const ros::NodeHandle& private_nh);

/// The hand_sim node's work: owns a HandSim (any hand from its URDF, DIGITs on any links) and
/// publishes every sensor frame: TF for every link, each gel and the object, /joint_states,
/// /<sensor>/contact, /clock and ~frame (the renderers render each sensor at its stamp); sets
/// /robot_description. Commands: ~joint_command (trajectory_msgs/JointTrajectory),
/// ~joint_targets (sensor_msgs/JointState), ~base_pose (geometry_msgs/PoseStamped in "world"),
/// gripper/command (GripperCommand, for a hand yaml with gripper joints). Services ~reset, and
/// ~step in synchronous mode (with targets and a base pose of its own, ordered with its frames
/// where a topic's message is not).
class HandSimRos {
 public:
  /// Throws Error (bad parameter, unreadable hand, URDF, mesh, scene) before advertising.
  HandSimRos(ros::NodeHandle nh, ros::NodeHandle private_nh);
  ~HandSimRos();
  HandSimRos(const HandSimRos&) = delete;
  HandSimRos& operator=(const HandSimRos&) = delete;

 private:
  void onTrajectory(const trajectory_msgs::JointTrajectory::ConstPtr& msg);
  void onTargets(const sensor_msgs::JointState::ConstPtr& msg);
  void onBasePose(const geometry_msgs::PoseStamped::ConstPtr& msg);
  void onGripperCommand(const GripperCommand::ConstPtr& msg);
  bool onReset(HandReset::Request& request, HandReset::Response& response);
  bool onStep(HandStep::Request& request, HandStep::Response& response);
  void warnClamped(const std::vector<std::string>& clamped);
  /// What the ~reset and ~step responses say of the hand at the current frame.
  HandState state() const;
  /// Real time: a frame period's tick of the clock (WallClockGrid).
  void onTick(const ros::WallTime& scheduled);
  void publishStaticTransforms();
  /// The episode's labels on /episode (latched), at start and at every ~reset: what a recording
  /// names its images with.
  void publishEpisode();
  std::uint32_t publishFrame();
  ros::Time frameStamp() const;

  HandSimParams params_;
  std::unique_ptr<HandSim> sim_;
  std::vector<std::unique_ptr<ContactPatchMeter>> meters_;
  int ticks_per_frame_ = 17;
  std::int64_t frame_period_ns_ = 0;
  std::int64_t frame_ = 0;
  ros::Time time_base_;
  bool owns_clock_ = false;
  double opening_command_ = 1.0;
  std::uint32_t episode_ = 0;
  double beta_mm_ = 0.0;  ///< the material's texture depth: a label

  std::mutex mutex_;
  ros::CallbackQueue service_queue_;
  ros::NodeHandle nh_, private_nh_;
  ros::Publisher tf_pub_, clock_pub_, joints_pub_, frame_pub_, object_marker_pub_, episode_pub_;
  std::vector<ros::Publisher> contact_pubs_;
  std::unique_ptr<tf2_ros::StaticTransformBroadcaster> static_tf_;
  ros::Subscriber trajectory_sub_, targets_sub_, base_sub_, gripper_sub_;
  ros::ServiceServer reset_srv_, step_srv_;
  std::unique_ptr<LockStep> lock_step_;
  std::unique_ptr<ros::AsyncSpinner> service_spinner_;
  std::unique_ptr<WallClockGrid> clock_;
};

}  // namespace norm2tex
