// dataset_recorder: writes the simulated gripper's tactile data into rosbags (see
// DatasetRecorder). Ctrl-C or SIGTERM closes and indexes the bag and writes the manifest.
#include <csignal>
#include <iostream>

#include <ros/callback_queue.h>
#include <ros/ros.h>

#include "dataset_recorder.hpp"
#include "launch_end.hpp"
#include "norm2tex/common/error.hpp"

namespace {
volatile std::sig_atomic_t g_stop = 0;
void requestStop(int) { g_stop = 1; }
}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "dataset_recorder", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, requestStop);
  std::signal(SIGTERM, requestStop);
  try {
    norm2tex::DatasetRecorder recorder(ros::NodeHandle(), ros::NodeHandle("~"));
    while (ros::ok() && !g_stop && !recorder.done()) {
      ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.01));
    }
    recorder.close();
    // Done as planned under roslaunch: end the whole launch as Ctrl-C would, and exit when
    // roslaunch stops this node (a required node's own exit gets a red banner, even status 0).
    if (!g_stop && recorder.error().empty() && norm2tex::endParentLaunch()) {
      const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(10.0);
      while (!g_stop && ros::WallTime::now() < deadline) ros::WallDuration(0.01).sleep();
    }
    ros::shutdown();
    if (!recorder.error().empty()) {
      std::cerr << "dataset_recorder: " << recorder.error() << std::endl;
      return 1;
    }
  } catch (const norm2tex::Error& e) {
    ROS_FATAL("dataset_recorder: %s", e.what());
    std::cerr << "dataset_recorder: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
