#pragma once
// rviz markers of the simulated gripper: free functions from the core's state to messages.

#include <string>

#include <ros/time.h>
#include <visualization_msgs/MarkerArray.h>

#include "norm2tex/sim/gripper_sim.hpp"

namespace norm2tex {
namespace ros_conversions {

/// The object's render mesh (frame "object", a TRIANGLE_LIST; built once, it is large), the two
/// gel pads (CUBE, in their gel frames) and the fingers behind them, and per gel an ARROW of the
/// force the object presses into it with (1 N = 5 mm long; hidden without contact). Namespace
/// "norm2tex"; ids stable so rviz replaces them.
visualization_msgs::Marker objectMarker(const TexturedMesh& mesh, const ros::Time& stamp);
visualization_msgs::MarkerArray gripperMarkers(const GripperSim& sim, const ros::Time& stamp);

}  // namespace ros_conversions
}  // namespace norm2tex
