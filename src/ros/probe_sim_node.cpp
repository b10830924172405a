// probe_sim: the paper's probe collection as a ROS node (see ProbeSim).
#include <iostream>

#include <ros/ros.h>

#include "probe_sim.hpp"
#include "norm2tex/common/error.hpp"

int main(int argc, char** argv) {
  ros::init(argc, argv, "probe_sim");
  try {
    norm2tex::ProbeSim sim(ros::NodeHandle(), ros::NodeHandle("~"));
    ros::spin();
  } catch (const norm2tex::Error& e) {
    // Also on stderr: rosconsole may be routed elsewhere (rostest, log-only configs).
    ROS_FATAL("probe_sim: %s", e.what());
    std::cerr << "probe_sim: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
