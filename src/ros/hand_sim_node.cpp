// hand_sim: any hand from its URDF with DIGITs on any links, as a ROS node (see HandSimRos).
#include <iostream>

#include <ros/ros.h>

#include "hand_sim_ros.hpp"
#include "norm2tex/common/error.hpp"

int main(int argc, char** argv) {
  ros::init(argc, argv, "hand_sim");
  try {
    norm2tex::HandSimRos sim(ros::NodeHandle(), ros::NodeHandle("~"));
    ros::spin();
  } catch (const norm2tex::Error& e) {
    // Also on stderr: rosconsole may be routed elsewhere (rostest, log-only configs).
    ROS_FATAL("hand_sim: %s", e.what());
    std::cerr << "hand_sim: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
