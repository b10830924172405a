#pragma once
// Conversions between the core's types and ROS messages: free functions, no state.

#include <cstdint>
#include <string>

#include <geometry_msgs/Transform.h>
#include <ros/time.h>
#include <Eigen/Geometry>

#include "norm2tex/TactileContact.h"
#include "norm2tex/sim/contact_patch.hpp"
#include "norm2tex/sim/gripper_sim.hpp"

namespace norm2tex {
namespace ros_conversions {

geometry_msgs::Transform toTransformMsg(const Eigen::Isometry3d& pose);
Eigen::Isometry3d fromTransformMsg(const geometry_msgs::Transform& msg);

/// Nanoseconds (the simulation's clock) to ros::Time, exactly; throws Error when negative or
/// past ros::Time's range.
ros::Time toRosTime(std::int64_t nanoseconds);

/// The contact message of one gel: forces and penetration from the physics, area and centroid
/// from the rendered contact patch. `header` carries the frame's stamp and the gel frame.
TactileContact toContactMsg(const std_msgs::Header& header, const std::string& sensor,
                            const GelContactState& state, const ContactPatch& patch);

}  // namespace ros_conversions
}  // namespace norm2tex
