// contact_sim: the Bullet gripper simulation as a ROS node (see ContactSim).
#include <iostream>

#include <ros/ros.h>

#include "contact_sim.hpp"
#include "norm2tex/common/error.hpp"

int main(int argc, char** argv) {
  ros::init(argc, argv, "contact_sim");
  try {
    norm2tex::ContactSim sim(ros::NodeHandle(), ros::NodeHandle("~"));
    ros::spin();
  } catch (const norm2tex::Error& e) {
    // Also on stderr: rosconsole may be routed elsewhere (rostest, log-only configs).
    ROS_FATAL("contact_sim: %s", e.what());
    std::cerr << "contact_sim: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
