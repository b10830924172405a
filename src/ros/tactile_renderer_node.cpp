// tactile_renderer: one simulated DIGIT's images as a ROS node (see TactileRendererRos).
#include <iostream>

#include <ros/ros.h>

#include "norm2tex/common/error.hpp"
#include "tactile_renderer_ros.hpp"

int main(int argc, char** argv) {
  ros::init(argc, argv, "tactile_renderer");
  try {
    norm2tex::TactileRendererRos renderer(ros::NodeHandle(), ros::NodeHandle("~"));
    ros::spin();
  } catch (const norm2tex::Error& e) {
    // Also on stderr: rosconsole may be routed elsewhere (rostest, log-only configs).
    ROS_FATAL("%s: %s", ros::this_node::getName().c_str(), e.what());
    std::cerr << ros::this_node::getName() << ": " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
