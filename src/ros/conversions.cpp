#include "conversions.hpp"

#include <limits>

#include <cv_bridge/cv_bridge.h>
#include <sensor_msgs/image_encodings.h>
#include <tf2_eigen/tf2_eigen.h>

#include "norm2tex/common/error.hpp"
#include "norm2tex/sim/contact_shear_load.hpp"

namespace norm2tex {
namespace ros_conversions {

geometry_msgs::Transform toTransformMsg(const Eigen::Isometry3d& pose) {
  return tf2::eigenToTransform(pose).transform;
}

Eigen::Isometry3d fromTransformMsg(const geometry_msgs::Transform& msg) {
  // tf2_eigen's fields, and the quaternion normalised before it becomes a matrix (which
  // tf2::transformToEigen does not do): quaternions composed along a TF chain drift off unit
  // length, and the renderer's pose must stay a rotation.
  Eigen::Vector3d translation;
  tf2::fromMsg(msg.translation, translation);
  Eigen::Quaterniond rotation;
  tf2::fromMsg(msg.rotation, rotation);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = translation;
  pose.linear() = rotation.normalized().toRotationMatrix();
  return pose;
}

ros::Time toRosTime(std::int64_t nanoseconds) {
  constexpr std::int64_t kMax =
      static_cast<std::int64_t>(std::numeric_limits<std::uint32_t>::max()) * 1000000000LL;
  if (nanoseconds < 0 || nanoseconds > kMax) {
    throw Error("time " + std::to_string(nanoseconds) + " ns is outside ros::Time's range");
  }
  ros::Time time;
  time.fromNSec(static_cast<std::uint64_t>(nanoseconds));
  return time;
}

TactileContact toContactMsg(const std_msgs::Header& header, const std::string& sensor,
                            const GelContactState& state, const ContactPatch& patch) {
  TactileContact msg;
  msg.header = header;
  msg.sensor = sensor;
  msg.in_contact = state.in_contact;
  msg.normal_force = state.normal_force_n;
  msg.shear_force.x = state.shear_force_n.x();
  msg.shear_force.y = state.shear_force_n.y();
  msg.shear_force.z = state.shear_force_n.z();
  msg.max_indentation = state.penetration_m;
  msg.too_deep = state.too_deep;
  msg.contact_area = patch.area_m2;
  msg.centroid.x = patch.centroid_m.x();
  msg.centroid.y = patch.centroid_m.y();
  msg.centroid.z = 0.0;
  msg.twist_moment = state.twist_moment_nm;
  msg.slip_fraction = patch.slip_fraction;
  return msg;
}

void addSensorLoad(SimFrame& frame, const std::string& sensor, const GelContactState& state) {
  frame.sensors.push_back(sensor);
  frame.normal_force.push_back(state.normal_force_n);
  geometry_msgs::Vector3 shear;
  tf2::toMsg(state.shear_force_n, shear);
  frame.shear_force.push_back(shear);
  frame.twist_moment.push_back(state.twist_moment_nm);
}

std::optional<ShearLoad> shearLoadIn(const SimFrame& frame, const std::string& sensor) {
  // Sources of older versions (and probe_sim, which has no tangential load) name no shear: the
  // arrays are shorter than `sensors`.
  for (std::size_t i = 0; i < frame.sensors.size(); ++i) {
    if (frame.sensors[i] != sensor) continue;
    if (i >= frame.shear_force.size() || i >= frame.twist_moment.size()) return std::nullopt;
    return shearLoadOf(Eigen::Vector2d(frame.shear_force[i].x, frame.shear_force[i].y),
                       frame.twist_moment[i], frame.friction);
  }
  return std::nullopt;
}

TactileMarkers toMarkersMsg(const std_msgs::Header& header, int rows, int cols,
                            const ShearFrame& frame) {
  if (rows < 0 || cols < 0 || frame.markers.size() != static_cast<std::size_t>(rows) * cols) {
    throw Error("markers: " + std::to_string(frame.markers.size()) + " markers for a grid of " +
                std::to_string(rows) + " x " + std::to_string(cols));
  }
  TactileMarkers msg;
  msg.header = header;
  msg.rows = static_cast<std::uint32_t>(rows);
  msg.cols = static_cast<std::uint32_t>(cols);
  msg.rest_px.resize(frame.markers.size());
  msg.current_px.resize(frame.markers.size());
  msg.displacement_mm.resize(frame.markers.size());
  for (std::size_t i = 0; i < frame.markers.size(); ++i) {
    const Marker& m = frame.markers[i];
    msg.rest_px[i].x = m.rest_px.x;
    msg.rest_px[i].y = m.rest_px.y;
    msg.current_px[i].x = m.current_px.x;
    msg.current_px[i].y = m.current_px.y;
    msg.displacement_mm[i].x = m.displacement_mm.x;
    msg.displacement_mm[i].y = m.displacement_mm.y;
  }
  msg.slip_fraction = frame.slipFraction();
  return msg;
}

sensor_msgs::ImagePtr toImageMsg(const std_msgs::Header& header, const cv::Mat& image) {
  std::string encoding;
  switch (image.type()) {
    case CV_8UC3:
      encoding = sensor_msgs::image_encodings::BGR8;
      break;
    case CV_8UC1:
      encoding = sensor_msgs::image_encodings::MONO8;
      break;
    case CV_32FC1:
      encoding = sensor_msgs::image_encodings::TYPE_32FC1;
      break;
    case CV_32FC2:
      encoding = sensor_msgs::image_encodings::TYPE_32FC2;
      break;
    default:
      throw Error("image type " + std::to_string(image.type()) +
                  " has no sensor_msgs encoding here; valid: CV_8UC3, CV_8UC1, CV_32FC1, "
                  "CV_32FC2");
  }
  // One copy of the pixels (row by row for a view into a larger matrix).
  return cv_bridge::CvImage(header, encoding, image).toImageMsg();
}

cv::Mat fromImageMsg(const sensor_msgs::Image& msg) {
  int type = -1;
  if (msg.encoding == "bgr8" || msg.encoding == "rgb8") type = CV_8UC3;
  if (msg.encoding == "mono8") type = CV_8UC1;
  if (msg.encoding == "32FC1") type = CV_32FC1;
  if (msg.encoding == "32FC2") type = CV_32FC2;
  if (type < 0) {
    throw Error("image encoding '" + msg.encoding +
                "' is not supported here; valid: bgr8, rgb8, mono8, 32FC1, 32FC2");
  }
  if (msg.is_bigendian && CV_MAT_DEPTH(type) == CV_32F) {
    throw Error("big-endian " + msg.encoding + " images are not supported");
  }
  // Checked here, naming the sizes (cv_bridge refuses such a message with less to go on).
  const std::size_t row_bytes = static_cast<std::size_t>(msg.width) * CV_ELEM_SIZE(type);
  if (msg.width == 0 || msg.height == 0 || msg.step < row_bytes ||
      msg.data.size() != static_cast<std::size_t>(msg.step) * msg.height) {
    throw Error("image message of " + std::to_string(msg.width) + " x " +
                std::to_string(msg.height) + " " + msg.encoding + " with step " +
                std::to_string(msg.step) + " holds " + std::to_string(msg.data.size()) +
                " bytes: truncated or inconsistent");
  }
  // A copy without the rows' padding; rgb8 (other drivers) arrives as BGR.
  try {
    return cv_bridge::toCvCopy(msg,
                               type == CV_8UC3 ? sensor_msgs::image_encodings::BGR8 : msg.encoding)
        ->image;
  } catch (const cv_bridge::Exception& e) {
    throw Error("image message of encoding '" + msg.encoding + "': " + e.what());
  }
}

sensor_msgs::CameraInfo toCameraInfo(const std_msgs::Header& header, const SensorModel& model) {
  sensor_msgs::CameraInfo info;
  info.header = header;
  info.height = static_cast<std::uint32_t>(model.rows);
  info.width = static_cast<std::uint32_t>(model.cols);
  info.distortion_model = "plumb_bob";
  info.D = {0.0, 0.0, 0.0, 0.0, 0.0};
  info.K = {model.fx, 0.0, model.cx, 0.0, model.fy, model.cy, 0.0, 0.0, 1.0};
  info.R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  info.P = {model.fx, 0.0, model.cx, 0.0, 0.0, model.fy, model.cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  return info;
}

}  // namespace ros_conversions
}  // namespace norm2tex
