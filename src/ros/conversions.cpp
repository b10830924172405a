#include "conversions.hpp"

#include <opencv2/imgproc.hpp>

#include <cstring>
#include <limits>

#include <boost/make_shared.hpp>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace ros_conversions {

geometry_msgs::Transform toTransformMsg(const Eigen::Isometry3d& pose) {
  geometry_msgs::Transform msg;
  msg.translation.x = pose.translation().x();
  msg.translation.y = pose.translation().y();
  msg.translation.z = pose.translation().z();
  const Eigen::Quaterniond q(pose.rotation());
  msg.rotation.x = q.x();
  msg.rotation.y = q.y();
  msg.rotation.z = q.z();
  msg.rotation.w = q.w();
  return msg;
}

Eigen::Isometry3d fromTransformMsg(const geometry_msgs::Transform& msg) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(msg.translation.x, msg.translation.y, msg.translation.z);
  pose.linear() = Eigen::Quaterniond(msg.rotation.w, msg.rotation.x, msg.rotation.y, msg.rotation.z)
                      .normalized()
                      .toRotationMatrix();
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
  return msg;
}

sensor_msgs::ImagePtr toImageMsg(const std_msgs::Header& header, const cv::Mat& image) {
  auto msg = boost::make_shared<sensor_msgs::Image>();
  msg->header = header;
  switch (image.type()) {
    case CV_8UC3:
      msg->encoding = "bgr8";
      break;
    case CV_8UC1:
      msg->encoding = "mono8";
      break;
    case CV_32FC1:
      msg->encoding = "32FC1";
      break;
    default:
      throw Error("image type " + std::to_string(image.type()) +
                  " has no sensor_msgs encoding here; valid: CV_8UC3, CV_8UC1, CV_32FC1");
  }
  msg->height = static_cast<std::uint32_t>(image.rows);
  msg->width = static_cast<std::uint32_t>(image.cols);
  msg->is_bigendian = false;
  msg->step = static_cast<std::uint32_t>(image.cols * image.elemSize());
  msg->data.resize(static_cast<std::size_t>(msg->step) * image.rows);
  for (int r = 0; r < image.rows; ++r) {
    std::memcpy(&msg->data[static_cast<std::size_t>(r) * msg->step], image.ptr(r), msg->step);
  }
  return msg;
}

cv::Mat fromImageMsg(const sensor_msgs::Image& msg) {
  int type = -1;
  if (msg.encoding == "bgr8" || msg.encoding == "rgb8") type = CV_8UC3;
  if (msg.encoding == "mono8") type = CV_8UC1;
  if (msg.encoding == "32FC1") type = CV_32FC1;
  if (type < 0) {
    throw Error("image encoding '" + msg.encoding +
                "' is not supported here; valid: bgr8, rgb8, mono8, 32FC1");
  }
  if (msg.is_bigendian && type == CV_32FC1) {
    throw Error("big-endian 32FC1 images are not supported");
  }
  const std::size_t row_bytes = static_cast<std::size_t>(msg.width) * CV_ELEM_SIZE(type);
  if (msg.width == 0 || msg.height == 0 || msg.step < row_bytes ||
      msg.data.size() < static_cast<std::size_t>(msg.step) * msg.height) {
    throw Error("image message of " + std::to_string(msg.width) + " x " +
                std::to_string(msg.height) + " " + msg.encoding + " with step " +
                std::to_string(msg.step) + " holds " + std::to_string(msg.data.size()) +
                " bytes: truncated or inconsistent");
  }
  cv::Mat image(static_cast<int>(msg.height), static_cast<int>(msg.width), type);
  for (int r = 0; r < image.rows; ++r) {
    std::memcpy(image.ptr(r), &msg.data[static_cast<std::size_t>(r) * msg.step], row_bytes);
  }
  if (msg.encoding == "rgb8") cv::cvtColor(image, image, cv::COLOR_RGB2BGR);
  return image;
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
