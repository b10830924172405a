#pragma once
// Conversions between the core's types and ROS messages: free functions, no state.

#include <cstdint>
#include <optional>
#include <string>

#include <geometry_msgs/Transform.h>
#include <ros/time.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "norm2tex/SimFrame.h"
#include "norm2tex/TactileContact.h"
#include "norm2tex/TactileMarkers.h"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/shear/shear_field.hpp"
#include "norm2tex/sim/contact_patch.hpp"
#include "norm2tex/sim/gripper_sim.hpp"

namespace norm2tex {
namespace ros_conversions {

geometry_msgs::Transform toTransformMsg(const Eigen::Isometry3d& pose);
Eigen::Isometry3d fromTransformMsg(const geometry_msgs::Transform& msg);

/// Nanoseconds (the simulation's clock) to ros::Time, exactly; throws Error when negative or
/// past ros::Time's range.
ros::Time toRosTime(std::int64_t nanoseconds);

/// The contact message of one gel: forces, moment and penetration from the physics, area,
/// centroid and slip from the rendered contact patch. `header` carries the frame's stamp and the
/// gel frame.
TactileContact toContactMsg(const std_msgs::Header& header, const std::string& sensor,
                            const GelContactState& state, const ContactPatch& patch);

/// Adds one gel to a SimFrame: its name, normal force, shear force and twisting moment.
void addSensorLoad(SimFrame& frame, const std::string& sensor, const GelContactState& state);

/// The tangential load a SimFrame gives for `sensor` (ShearLoad, with the frame's friction when
/// it gives one > 0), or none when it names no shear force and moment for it.
std::optional<ShearLoad> shearLoadIn(const SimFrame& frame, const std::string& sensor);

/// The markers of a rendered frame: `rows` x `cols` (the sensor model's grid), positions in
/// pixels, displacements in mm, and the contact's slip fraction. Throws Error when the frame has
/// not rows x cols markers.
TactileMarkers toMarkersMsg(const std_msgs::Header& header, int rows, int cols,
                            const ShearFrame& frame);

/// An image message holding a copy of `image`: CV_8UC3 as "bgr8", CV_8UC1 as "mono8", CV_32FC1
/// as "32FC1", CV_32FC2 as "32FC2"; throws Error for any other type.
sensor_msgs::ImagePtr toImageMsg(const std_msgs::Header& header, const cv::Mat& image);

/// The pixels of an image message (a copy): "bgr8"/"rgb8" as CV_8UC3 BGR, "mono8" as CV_8UC1,
/// "32FC1" as CV_32FC1, "32FC2" as CV_32FC2. Throws Error naming the encoding for any other, and
/// for a message whose step or data size does not match its width, height and encoding (a
/// truncated message).
cv::Mat fromImageMsg(const sensor_msgs::Image& msg);

/// The sensor's pinhole intrinsics (no distortion), as a DIGIT driver would publish them.
sensor_msgs::CameraInfo toCameraInfo(const std_msgs::Header& header, const SensorModel& model);

}  // namespace ros_conversions
}  // namespace norm2tex
