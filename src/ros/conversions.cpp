#include "conversions.hpp"

#include <limits>

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
  msg.contact_area = patch.area_m2;
  msg.centroid.x = patch.centroid_m.x();
  msg.centroid.y = patch.centroid_m.y();
  msg.centroid.z = 0.0;
  return msg;
}

}  // namespace ros_conversions
}  // namespace norm2tex
