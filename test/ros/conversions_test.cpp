// Conversions between core types and ROS messages (no master needed).
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "conversions.hpp"
#include "markers.hpp"
#include "norm2tex/common/error.hpp"
#include "../core/test_helpers.hpp"

namespace norm2tex {
namespace {

TEST(ConversionsTest, TransformRoundTripKeepsThePose) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0.01, -0.2, 3.0);
  const geometry_msgs::Transform msg = ros_conversions::toTransformMsg(pose);
  EXPECT_DOUBLE_EQ(msg.translation.y, -0.2);
  const double norm = std::sqrt(msg.rotation.x * msg.rotation.x + msg.rotation.y * msg.rotation.y +
                                msg.rotation.z * msg.rotation.z + msg.rotation.w * msg.rotation.w);
  EXPECT_NEAR(norm, 1.0, 1e-12);
  EXPECT_TRUE(ros_conversions::fromTransformMsg(msg).isApprox(pose, 1e-12));
}

/// Expects the message's quaternion to be (x, y, z, w) up to its sign (q and -q are one rotation).
void expectQuaternion(const geometry_msgs::Quaternion& q, double x, double y, double z, double w) {
  const double sign = (q.x * x + q.y * y + q.z * z + q.w * w) < 0.0 ? -1.0 : 1.0;
  EXPECT_NEAR(sign * q.x, x, 1e-12);
  EXPECT_NEAR(sign * q.y, y, 1e-12);
  EXPECT_NEAR(sign * q.z, z, 1e-12);
  EXPECT_NEAR(sign * q.w, w, 1e-12);
}

TEST(ConversionsTest, GelFrameRotationSurvivesTheMessage) {
  // The components pinned, worked out by hand, so that a wrong order of x, y, z, w (even the
  // same wrong order both ways, which a round trip alone would pass) fails. The left gel's
  // rotation [[-1,0,0],[0,0,-1],[0,-1,0]] is a half turn (trace -1, so w = 0) about the axis
  // with n n^T = (R + I) / 2, n = (0, 1, -1) / sqrt(2).
  const double h = std::sqrt(0.5);
  const Eigen::Isometry3d left = GripperSim::gelInFinger(Finger::kLeft);
  const geometry_msgs::Transform left_msg = ros_conversions::toTransformMsg(left);
  expectQuaternion(left_msg.rotation, 0.0, h, -h, 0.0);
  EXPECT_TRUE(ros_conversions::fromTransformMsg(left_msg).isApprox(left, 1e-12));
  // The right gel's [[1,0,0],[0,0,1],[0,-1,0]] is a quarter turn about x, by -90 degrees:
  // (sin(-45), 0, 0, cos(-45)); its w is not 0, so it also catches w swapped with x.
  const Eigen::Isometry3d right = GripperSim::gelInFinger(Finger::kRight);
  const geometry_msgs::Transform right_msg = ros_conversions::toTransformMsg(right);
  expectQuaternion(right_msg.rotation, -h, 0.0, 0.0, h);
  EXPECT_TRUE(ros_conversions::fromTransformMsg(right_msg).isApprox(right, 1e-12));
  // And the way in: a message with only w set is the identity; with only z set, a half turn
  // about z.
  geometry_msgs::Transform msg;
  msg.rotation.w = 1.0;
  EXPECT_TRUE(
      ros_conversions::fromTransformMsg(msg).linear().isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  msg.rotation.w = 0.0;
  msg.rotation.z = 1.0;
  EXPECT_TRUE(ros_conversions::fromTransformMsg(msg).linear().isApprox(
      Eigen::Vector3d(-1.0, -1.0, 1.0).asDiagonal().toDenseMatrix(), 1e-12));
}

TEST(ConversionsTest, TimeIsExactToTheNanosecond) {
  const ros::Time t = ros_conversions::toRosTime(16666667LL * 1000 + 3);
  EXPECT_EQ(t.sec, 16u);
  EXPECT_EQ(t.nsec, 666667003u);
  EXPECT_EQ(t.toNSec(), 16666667003ull);
  EXPECT_THROW(ros_conversions::toRosTime(-1), Error);
}

TEST(ConversionsTest, ContactMessageCarriesEveryField) {
  GelContactState state;
  state.in_contact = true;
  state.normal_force_n = 12.5;
  state.shear_force_n = Eigen::Vector3d(0.1, 0.49, 0.0);
  state.penetration_m = 1e-3;
  state.too_deep = true;
  ContactPatch patch;
  patch.area_m2 = 4.9e-4;
  patch.centroid_m = Eigen::Vector2d(-0.001, 0.002);
  std_msgs::Header header;
  header.frame_id = "digit_left_gel";
  header.stamp = ros::Time(5, 7);
  const TactileContact msg = ros_conversions::toContactMsg(header, "digit_left", state, patch);
  EXPECT_EQ(msg.header.frame_id, "digit_left_gel");
  EXPECT_EQ(msg.header.stamp, ros::Time(5, 7));
  EXPECT_EQ(msg.sensor, "digit_left");
  EXPECT_TRUE(msg.in_contact);
  EXPECT_DOUBLE_EQ(msg.normal_force, 12.5);
  EXPECT_DOUBLE_EQ(msg.shear_force.y, 0.49);
  EXPECT_DOUBLE_EQ(msg.max_indentation, 1e-3);
  EXPECT_TRUE(msg.too_deep);
  EXPECT_DOUBLE_EQ(msg.contact_area, 4.9e-4);
  EXPECT_DOUBLE_EQ(msg.centroid.x, -0.001);
  EXPECT_DOUBLE_EQ(msg.centroid.y, 0.002);
  EXPECT_EQ(msg.twist_moment, 0.0);
  EXPECT_EQ(msg.slip_fraction, 0.0);
  state.twist_moment_nm = -3.5e-3;
  patch.slip_fraction = 0.25;
  const TactileContact twisted = ros_conversions::toContactMsg(header, "digit_left", state, patch);
  EXPECT_DOUBLE_EQ(twisted.twist_moment, -3.5e-3);
  EXPECT_DOUBLE_EQ(twisted.slip_fraction, 0.25);
}

TEST(ConversionsTest, AFrameCarriesEachGelsLoadToItsRenderer) {
  GelContactState left, right;
  left.normal_force_n = 5.0;
  left.shear_force_n = Eigen::Vector3d(0.1, 0.2, 0.0);
  left.twist_moment_nm = 1e-3;
  right.normal_force_n = 6.0;
  right.shear_force_n = Eigen::Vector3d(-0.3, 0.4, 0.0);
  right.twist_moment_nm = -2e-3;
  SimFrame frame;
  ros_conversions::addSensorLoad(frame, "digit_left", left);
  ros_conversions::addSensorLoad(frame, "digit_right", right);
  frame.friction = 0.45;
  ASSERT_EQ(frame.sensors.size(), 2u);
  EXPECT_EQ(frame.normal_force[1], 6.0);
  const std::optional<ShearLoad> load = ros_conversions::shearLoadIn(frame, "digit_right");
  ASSERT_TRUE(load.has_value());
  EXPECT_EQ(load->force_n, Eigen::Vector2d(-0.3, 0.4));
  EXPECT_EQ(load->torque_nm, -2e-3);
  ASSERT_TRUE(load->friction.has_value());
  EXPECT_EQ(*load->friction, 0.45);
  EXPECT_EQ(ros_conversions::shearLoadIn(frame, "digit_left")->force_n, Eigen::Vector2d(0.1, 0.2));
  // A sensor the frame does not name, or a frame without shear (an older source, probe_sim's
  // press), gives none; no friction: the sensor model's.
  EXPECT_FALSE(ros_conversions::shearLoadIn(frame, "digit_middle").has_value());
  frame.friction = 0.0;
  EXPECT_FALSE(ros_conversions::shearLoadIn(frame, "digit_left")->friction.has_value());
  frame.shear_force.clear();
  EXPECT_FALSE(ros_conversions::shearLoadIn(frame, "digit_left").has_value());
}

TEST(ConversionsTest, MarkersMessageKeepsTheGridAndItsMotion) {
  ShearFrame frame;
  frame.traction.contact_cells = 4;
  frame.traction.stick_cells = 3;
  frame.traction.slip_fraction = 0.25;
  for (int i = 0; i < 6; ++i) {
    Marker m;
    m.rest_px = {10.0f * i, 20.0f};
    m.displacement_mm = {0.01f * i, -0.02f};
    m.current_px = {10.0f * i + 0.5f, 19.5f};
    frame.markers.push_back(m);
  }
  std_msgs::Header header;
  header.frame_id = "digit_left_gel";
  header.stamp = ros::Time(2, 3);
  const TactileMarkers msg = ros_conversions::toMarkersMsg(header, 2, 3, frame);
  EXPECT_EQ(msg.header.stamp, ros::Time(2, 3));
  EXPECT_EQ(msg.header.frame_id, "digit_left_gel");
  EXPECT_EQ(msg.rows, 2u);
  EXPECT_EQ(msg.cols, 3u);
  ASSERT_EQ(msg.rest_px.size(), 6u);
  ASSERT_EQ(msg.current_px.size(), 6u);
  ASSERT_EQ(msg.displacement_mm.size(), 6u);
  EXPECT_EQ(msg.rest_px[4].x, 40.0f);
  EXPECT_EQ(msg.current_px[4].y, 19.5f);
  EXPECT_EQ(msg.displacement_mm[5].x, frame.markers[5].displacement_mm.x);
  EXPECT_EQ(msg.displacement_mm[5].y, -0.02f);
  EXPECT_EQ(msg.rest_px[0].z, 0.0f);
  EXPECT_DOUBLE_EQ(msg.slip_fraction, 0.25);
  test::expectError([&] { ros_conversions::toMarkersMsg(header, 3, 3, frame); },
                    {"6 markers", "3 x 3"});
}

TEST(ConversionsTest, ImagesKeepTheirPixelsAndEncodings) {
  std_msgs::Header header;
  header.frame_id = "digit_left_gel";
  cv::Mat3b image(320, 240, cv::Vec3b(1, 2, 3));
  image(319, 239) = cv::Vec3b(10, 20, 30);
  const sensor_msgs::ImagePtr msg = ros_conversions::toImageMsg(header, image);
  EXPECT_EQ(msg->encoding, "bgr8");
  EXPECT_EQ(msg->height, 320u);
  EXPECT_EQ(msg->width, 240u);
  EXPECT_EQ(msg->step, 720u);
  EXPECT_EQ(msg->data[0], 1);  // B first, as DIGIT drivers publish
  EXPECT_EQ(msg->data[msg->data.size() - 1], 30);
  // A view into a larger matrix (non-contiguous rows) is copied row by row.
  cv::Mat1f big(10, 10, 0.0f);
  big(3, 4) = 1.5f;
  const sensor_msgs::ImagePtr depth =
      ros_conversions::toImageMsg(header, big(cv::Rect(4, 3, 2, 2)));
  EXPECT_EQ(depth->encoding, "32FC1");
  float first = 0;
  std::memcpy(&first, depth->data.data(), sizeof first);
  EXPECT_EQ(first, 1.5f);
  EXPECT_EQ(ros_conversions::toImageMsg(header, cv::Mat1b(2, 2))->encoding, "mono8");
  EXPECT_THROW(ros_conversions::toImageMsg(header, cv::Mat1d(2, 2)), Error);
}

TEST(ConversionsTest, ImageMessagesComeBackAsTheSamePixels) {
  std_msgs::Header header;
  cv::Mat3b image(320, 240, cv::Vec3b(1, 2, 3));
  image(5, 7) = cv::Vec3b(10, 20, 30);
  const cv::Mat back = ros_conversions::fromImageMsg(*ros_conversions::toImageMsg(header, image));
  ASSERT_EQ(back.type(), CV_8UC3);
  EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0.0);
  cv::Mat1f depth(4, 3, 0.25f);
  depth(3, 2) = -1.0f;
  const cv::Mat depth_back =
      ros_conversions::fromImageMsg(*ros_conversions::toImageMsg(header, depth));
  EXPECT_EQ(cv::norm(depth_back, depth, cv::NORM_INF), 0.0);
  // The shear field: two channels, x and y, metres.
  cv::Mat2f shear(4, 3, cv::Vec2f(1e-4f, -2e-5f));
  shear(1, 2) = cv::Vec2f(-3e-4f, 5e-4f);
  const sensor_msgs::ImagePtr shear_msg = ros_conversions::toImageMsg(header, shear);
  EXPECT_EQ(shear_msg->encoding, "32FC2");
  EXPECT_EQ(shear_msg->step, 3u * 8u);
  const cv::Mat shear_back = ros_conversions::fromImageMsg(*shear_msg);
  ASSERT_EQ(shear_back.type(), CV_32FC2);
  EXPECT_EQ(cv::norm(shear_back, shear, cv::NORM_INF), 0.0);
  // rgb8 (other drivers) arrives as BGR; padded rows (step > width) are unpadded.
  sensor_msgs::Image rgb;
  rgb.encoding = "rgb8";
  rgb.width = 2;
  rgb.height = 1;
  rgb.step = 8;
  rgb.data = {10, 20, 30, 40, 50, 60, 0, 0};
  const cv::Mat3b bgr = ros_conversions::fromImageMsg(rgb);
  EXPECT_EQ(bgr(0, 0), cv::Vec3b(30, 20, 10));
  EXPECT_EQ(bgr(0, 1), cv::Vec3b(60, 50, 40));
  // Odd encodings and truncated data are errors that say so.
  rgb.encoding = "bayer_rggb8";
  test::expectError([&] { ros_conversions::fromImageMsg(rgb); }, {"bayer_rggb8", "bgr8"});
  rgb.encoding = "rgb8";
  rgb.data.resize(5);
  test::expectError([&] { ros_conversions::fromImageMsg(rgb); }, {"truncated"});
  rgb.data.resize(9);  // more than step x height: inconsistent too (cv_bridge refuses it)
  test::expectError([&] { ros_conversions::fromImageMsg(rgb); }, {"holds 9 bytes", "inconsistent"});
}

TEST(ConversionsTest, CameraInfoCarriesTheSensorIntrinsics) {
  const SensorModel model = makeDigitSensorModel();
  std_msgs::Header header;
  header.stamp = ros::Time(3, 0);
  const sensor_msgs::CameraInfo info = ros_conversions::toCameraInfo(header, model);
  EXPECT_EQ(info.header.stamp, ros::Time(3, 0));
  EXPECT_EQ(info.height, 320u);
  EXPECT_EQ(info.width, 240u);
  EXPECT_DOUBLE_EQ(info.K[0], model.fx);
  EXPECT_DOUBLE_EQ(info.K[2], model.cx);
  EXPECT_DOUBLE_EQ(info.K[5], model.cy);
  EXPECT_DOUBLE_EQ(info.P[5], model.fy);
  EXPECT_EQ(info.D.size(), 5u);
}

TEST(MarkersTest, ObjectMeshAndForceArrowsFollowTheSimulation) {
  GripperSimConfig config;
  setGelFromSensor(makeDigitSensorModel(), config);
  GripperSim sim(config);
  const visualization_msgs::Marker object = ros_conversions::objectMarker(sim.object().mesh, {});
  EXPECT_EQ(object.header.frame_id, "object");
  EXPECT_TRUE(object.frame_locked);  // latched once, it follows the object's TF
  EXPECT_EQ(object.points.size(), 3 * sim.object().mesh.triangles().size());
  // Open: no contact, the arrows are deleted.
  visualization_msgs::MarkerArray open = ros_conversions::gripperMarkers(sim, ros::Time(1, 0));
  ASSERT_EQ(open.markers.size(), 6u);
  for (const auto& m : open.markers) {
    if (m.type == visualization_msgs::Marker::ARROW) {
      EXPECT_EQ(m.action, visualization_msgs::Marker::DELETE);
    }
  }
  // Held: the arrow is as long as the force says (5 mm per N) and points into the gel.
  sim.reset(1, 0.0);
  const visualization_msgs::MarkerArray held = ros_conversions::gripperMarkers(sim, {});
  int arrows = 0;
  for (const auto& m : held.markers) {
    if (m.type != visualization_msgs::Marker::ARROW) continue;
    ++arrows;
    EXPECT_EQ(m.action, visualization_msgs::Marker::ADD);
    const double force = sim.contact(m.id == 30 ? Finger::kLeft : Finger::kRight).normal_force_n;
    EXPECT_NEAR(m.points[0].z - m.points[1].z, 0.005 * force, 1e-9);
    EXPECT_EQ(m.header.frame_id, m.id == 30 ? "digit_left_gel" : "digit_right_gel");
  }
  EXPECT_EQ(arrows, 2);
}

}  // namespace
}  // namespace norm2tex
