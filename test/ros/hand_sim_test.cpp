// rostest of hand_sim.launch with a real master (hand_sim.test: TACTO's WSG-50 over a cube,
// synchronous): lock-step images per sensor, a grasp by JointTrajectory, a lift by base poses sent
// with ~step, the robot's state as a simulator publishes it, refusals. Waits on conditions with
// deadlines, never sleeps.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <limits>
#include <map>
#include <optional>
#include <string>

#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/JointState.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <trajectory_msgs/JointTrajectory.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "norm2tex/EpisodeInfo.h"
#include "norm2tex/GripperCommand.h"
#include "norm2tex/HandReset.h"
#include "norm2tex/HandStep.h"
#include "dataset_export.hpp"
#include "wait_for.hpp"

namespace {

using norm2tex::waitFor;

struct Hand {
  ros::NodeHandle nh;
  tf2_ros::Buffer buffer{ros::Duration(30.0)};
  tf2_ros::TransformListener tf{buffer, nh};
  std::map<std::string, int> images;
  sensor_msgs::JointState::ConstPtr joints;
  ros::Subscriber left = nh.subscribe<sensor_msgs::Image>(
      "/digit_left/image_raw", 1000, [this](const auto&) { ++images["digit_left"]; });
  ros::Subscriber right = nh.subscribe<sensor_msgs::Image>(
      "/digit_right/image_raw", 1000, [this](const auto&) { ++images["digit_right"]; });
  ros::Subscriber joint_sub = nh.subscribe<sensor_msgs::JointState>(
      "/joint_states", 10, [this](const auto& m) { joints = m; });
  ros::Publisher trajectory =
      nh.advertise<trajectory_msgs::JointTrajectory>("/hand_sim/joint_command", 1);
  ros::ServiceClient step = nh.serviceClient<norm2tex::HandStep>("/hand_sim/step");
  ros::ServiceClient reset = nh.serviceClient<norm2tex::HandReset>("/hand_sim/reset");

  Hand() {
    // The renderers bake the wood texture first: the services come once hand_sim is up.
    EXPECT_TRUE(step.waitForExistence(ros::Duration(120.0)));
    EXPECT_TRUE(
        waitFor([&] { return left.getNumPublishers() > 0 && right.getNumPublishers() > 0; }, 60.0));
  }
  /// `frames` frames; with `base`, the hand's root is moved there by this step's request.
  norm2tex::HandStep::Response stepFrames(unsigned frames,
                                          const std::optional<geometry_msgs::Pose>& base = {}) {
    norm2tex::HandStep srv;
    srv.request.frames = frames;
    srv.request.set_base_pose = base.has_value();
    if (base) srv.request.base_pose = *base;
    EXPECT_TRUE(step.call(srv));
    EXPECT_TRUE(srv.response.success) << srv.response.message;
    return srv.response;
  }
  /// The hand's root in the world at a frame's stamp.
  geometry_msgs::Transform base(const ros::Time& stamp) {
    return buffer.lookupTransform("world", "gripper_base_link", stamp, ros::Duration(10.0))
        .transform;
  }
  void send(const trajectory_msgs::JointTrajectory& t) {
    ASSERT_TRUE(waitFor([&] { return trajectory.getNumSubscribers() > 0; }, 30.0));
    trajectory.publish(t);
  }
};

trajectory_msgs::JointTrajectory closing(double left, double right, double seconds) {
  trajectory_msgs::JointTrajectory t;
  t.joint_names = {"base_joint_gripper_left", "base_joint_gripper_right"};
  trajectory_msgs::JointTrajectoryPoint point;
  point.positions = {left, right};
  point.time_from_start = ros::Duration(seconds);
  t.points.push_back(point);
  return t;
}

TEST(HandSimRealTime, FourSensorsPublishAnImageOfEveryFrameAtSixtyHertz) {
  // Real time: the stamps of each sensor's images must be the frames' grid, 1/60 s apart, with
  // none missing, for two seconds of frames (counted, not timed).
  ros::NodeHandle nh;
  const std::vector<std::string> sensors = {"digit_index", "digit_middle", "digit_ring",
                                            "digit_thumb"};
  std::map<std::string, std::vector<ros::Time>> stamps;
  std::vector<ros::Subscriber> subs;
  for (const std::string& sensor : sensors) {
    subs.push_back(
        nh.subscribe<sensor_msgs::Image>("/" + sensor + "/image_raw", 1000,
                                         [&stamps, sensor](const sensor_msgs::Image::ConstPtr& m) {
                                           stamps[sensor].push_back(m->header.stamp);
                                         }));
  }
  constexpr size_t kFrames = 120;
  ASSERT_TRUE(waitFor(
      [&] {
        for (const std::string& sensor : sensors) {
          if (stamps[sensor].size() < kFrames) return false;
        }
        return true;
      },
      60.0));
  for (const std::string& sensor : sensors) {
    const std::vector<ros::Time>& s = stamps[sensor];
    int gaps = 0;
    for (size_t i = 1; i < kFrames; ++i) {
      const double step = (s[i] - s[i - 1]).toSec();
      if (std::abs(step - 1.0 / 60.0) > 1e-6) ++gaps;
    }
    EXPECT_EQ(gaps, 0) << sensor << ": frames missing or out of order";
  }
  // All four render the same frames: the latest of their first stamps is in every list.
  ros::Time first;
  for (const std::string& sensor : sensors) first = std::max(first, stamps[sensor].front());
  for (const std::string& sensor : sensors) {
    EXPECT_NE(std::find(stamps[sensor].begin(), stamps[sensor].end(), first), stamps[sensor].end())
        << sensor;
  }
}

TEST(HandSimRecord, TheRecorderWritesEverySensorsImagesThenLeavesTheHandRunning) {
  Hand hand;
  std::string dir;
  ASSERT_TRUE(hand.nh.getParam("/dataset_recorder/output_dir", dir));
  std::vector<ros::Time> stamps;
  for (int i = 0; i < 4; ++i) stamps.push_back(hand.stepFrames(2).stamp);  // 8 frames
  // The recorder had its 10 images (5 frames x 2 sensors) mid-way: it closed its bag and wrote
  // its manifest, and left the lock-step: further steps are answered by the renderers alone.
  const std::string manifest = dir + "/hand_shard0.yaml";
  ASSERT_TRUE(waitFor([&] { return std::filesystem::exists(manifest); }, 30.0));
  const auto after = hand.stepFrames(5);
  EXPECT_EQ(after.missing_images, 0u);
  std::map<std::string, std::vector<ros::Time>> images;
  std::string material;  // the labels the exporter names the images with
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".bag") continue;
    rosbag::Bag bag(entry.path().string(), rosbag::bagmode::Read);
    for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
      if (const auto info = m.instantiate<norm2tex::EpisodeInfo>()) material = info->material;
      if (m.getTopic().find("/image_raw") == std::string::npos) continue;
      if (const auto image = m.instantiate<sensor_msgs::Image>()) {
        images[m.getTopic()].push_back(image->header.stamp);
      }
    }
  }
  EXPECT_EQ(material, "wood");
  ASSERT_EQ(images.size(), 2u);
  for (const auto& [topic, topic_stamps] : images) {
    EXPECT_EQ(topic_stamps.size(), 5u) << topic;
    // The first five frames, each once: frames 2, 4 were the ends of the first two steps.
    ASSERT_GE(topic_stamps.size(), 4u);
    EXPECT_EQ(topic_stamps[1], stamps[0]) << topic;
    EXPECT_EQ(topic_stamps[3], stamps[1]) << topic;
  }

  // norm2tex_export takes a hand's recording as the gripper's: a row per image, each sensor's.
  std::vector<std::string> bags;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() == ".bag") bags.push_back(entry.path().string());
  }
  std::sort(bags.begin(), bags.end());
  norm2tex::ExportOptions options;
  options.out_dir = dir + "/export";
  const norm2tex::ExportSummary summary = norm2tex::exportDataset(bags, options);
  EXPECT_EQ(summary.frames, 10u);
  EXPECT_EQ(summary.frames_per_material.at("wood"), 10u);
  std::ifstream labels(options.out_dir + "/labels.csv");
  std::string line;
  std::getline(labels, line);  // the header: raw,diff,depth,material,variant,sensor,stamp,...
  std::map<std::string, int> rows_per_sensor;
  while (std::getline(labels, line)) {
    std::vector<std::string> fields;
    std::stringstream row(line);
    for (std::string field; std::getline(row, field, ',');) fields.push_back(field);
    ASSERT_GE(fields.size(), 7u) << line;
    ++rows_per_sensor[fields[5]];
    EXPECT_TRUE(std::filesystem::exists(options.out_dir + "/" + fields[0])) << line;
  }
  EXPECT_EQ(rows_per_sensor, (std::map<std::string, int>{{"digit_left", 5}, {"digit_right", 5}}));
  std::filesystem::remove_all(dir);
}

TEST(HandSimRos, EveryFrameGivesExactlyOneImagePerSensorAndTheHandGraspsByTrajectory) {
  Hand hand;
  // The simulator's robot: its description, every link on TF, the gels on their links.
  std::string description;
  ASSERT_TRUE(hand.nh.getParam("/robot_description", description));
  EXPECT_NE(description.find("<robot name=\"wsg50_digit\">"), std::string::npos);

  const auto first = hand.stepFrames(30);
  EXPECT_EQ(first.missing_images, 0u);
  // Each ~step returns once every image of its frames is out: exactly 30 per sensor.
  ASSERT_TRUE(waitFor(
      [&] { return hand.images["digit_left"] >= 30 && hand.images["digit_right"] >= 30; }, 10.0));
  EXPECT_EQ(hand.images["digit_left"], 30);
  EXPECT_EQ(hand.images["digit_right"], 30);
  ASSERT_EQ(first.state.sensors, (std::vector<std::string>{"digit_left", "digit_right"}));
  EXPECT_FALSE(first.state.in_contact[0] || first.state.in_contact[1]);
  EXPECT_TRUE(hand.buffer.canTransform("world", "digit_left_gel", first.stamp, ros::Duration(5.0)));
  EXPECT_TRUE(hand.buffer.canTransform("finger_right_tip", "digit_right_gel", ros::Time(0),
                                       ros::Duration(5.0)));
  ASSERT_TRUE(waitFor([&] { return hand.joints != nullptr; }, 5.0));
  EXPECT_EQ(hand.joints->name.size(), 2u);

  // Close both fingers past the cube within 2 s: each drive stops at its 10 N effort.
  hand.send(closing(-0.016, 0.016, 2.0));
  const auto held = hand.stepFrames(150);
  EXPECT_TRUE(held.state.in_contact[0] && held.state.in_contact[1]);
  EXPECT_NEAR(held.state.normal_force[0], 10.0, 0.5);
  EXPECT_NEAR(held.state.normal_force[1], 10.0, 0.5);
  EXPECT_GT(held.state.penetration[0], 0.5e-3);
  ASSERT_TRUE(waitFor(
      [&] { return hand.images["digit_left"] == 180 && hand.images["digit_right"] == 180; }, 10.0));
  // The gel frame sees the cube's face at the indentation the physics reports.
  const geometry_msgs::TransformStamped cube =
      hand.buffer.lookupTransform("digit_left_gel", "object", held.stamp, ros::Duration(5.0));
  EXPECT_NEAR(cube.transform.translation.z, 0.015 - held.state.penetration[0], 0.2e-3);

  // Refused with the reason and nothing changed: an unknown joint; then a reset opens the hand.
  trajectory_msgs::JointTrajectory wrong = closing(-0.05, 0.05, 0.5);
  wrong.joint_names[1] = "thumb";
  hand.send(wrong);
  const auto still = hand.stepFrames(30);
  EXPECT_NEAR(still.state.normal_force[0], 10.0, 0.5);
  norm2tex::HandReset reset;
  ASSERT_TRUE(hand.reset.call(reset));
  EXPECT_TRUE(reset.response.success) << reset.response.message;
  const auto open = hand.stepFrames(1);
  EXPECT_FALSE(open.state.in_contact[0] || open.state.in_contact[1]);
  // The parallel GripperCommand of a two-finger hand closes it; a base pose with each ~step, one
  // per frame, lifts it, and the cube with it.
  ros::Publisher gripper = hand.nh.advertise<norm2tex::GripperCommand>("/gripper/command", 1);
  ros::Publisher base = hand.nh.advertise<geometry_msgs::PoseStamped>("/hand_sim/base_pose", 1);
  ASSERT_TRUE(waitFor(
      [&] { return gripper.getNumSubscribers() > 0 && base.getNumSubscribers() > 0; }, 30.0));
  norm2tex::GripperCommand command;
  command.mode = norm2tex::GripperCommand::ABSOLUTE;
  command.opening = 0.0;
  gripper.publish(command);
  // The command is taken before the next ~step: hand_sim handles it as it arrives.
  ASSERT_TRUE(waitFor(
      [&] {
        return hand.stepFrames(1).state.in_contact == std::vector<std::uint8_t>{1, 1};
      },
      30.0));
  hand.stepFrames(60);
  const double cube_before =
      hand.buffer.lookupTransform("world", "object", hand.stepFrames(1).stamp, ros::Duration(10.0))
          .transform.translation.z;
  geometry_msgs::Pose pose;
  pose.orientation.x = 1.0;  // the hand upside down: 180 degrees about x
  for (int k = 1; k <= 30; ++k) {
    pose.position.z = 0.133 + 0.001 * k;
    const auto moved = hand.stepFrames(1, pose);
    // Each pose is reached over its own step's frame: the root is there at that frame's stamp.
    ASSERT_NEAR(hand.base(moved.stamp).translation.z, pose.position.z, 1e-9) << "pose " << k;
  }
  const auto lifted = hand.stepFrames(10);
  EXPECT_TRUE(lifted.state.in_contact[0] && lifted.state.in_contact[1]);
  EXPECT_NEAR(hand.base(lifted.stamp).translation.z, 0.163, 1e-9);
  const geometry_msgs::TransformStamped cube_in_world =
      hand.buffer.lookupTransform("world", "object", lifted.stamp, ros::Duration(10.0));
  // Held, the cube rises with the hand's 30 mm (it slips in the gels by nanometres).
  EXPECT_NEAR(cube_in_world.transform.translation.z - cube_before, 0.030, 0.1e-3);

  // ~base_pose streams poses to a hand that runs on: it is not ordered with ~step, so the base
  // reaches the pose at some step after the message arrives.
  geometry_msgs::PoseStamped streamed;
  streamed.header.frame_id = "world";
  streamed.pose = pose;
  streamed.pose.position.z = 0.164;
  base.publish(streamed);
  ASSERT_TRUE(waitFor(
      [&] { return hand.base(hand.stepFrames(1).stamp).translation.z > 0.164 - 1e-9; }, 60.0));

  norm2tex::HandStep zero;
  zero.request.frames = 0;
  ASSERT_TRUE(hand.step.call(zero));
  EXPECT_FALSE(zero.response.success);
  EXPECT_NE(zero.response.message.find("frames = 0 refused"), std::string::npos);
}

TEST(HandSimRos, AStepWithABasePoseThatIsNotOneIsRefusedWithTheReasonAndChangesNothing) {
  Hand hand;
  norm2tex::HandReset reset;
  ASSERT_TRUE(hand.reset.call(reset));
  ASSERT_TRUE(reset.response.success) << reset.response.message;
  const auto before = hand.stepFrames(1);
  const geometry_msgs::Transform base_before = hand.base(before.stamp);

  const double nan = std::numeric_limits<double>::quiet_NaN();
  geometry_msgs::Pose upside_down;  // the yaml's base pose: 180 degrees about x
  upside_down.position.z = 0.133;
  upside_down.orientation.x = 1.0;
  struct Bad {
    geometry_msgs::Pose pose;
    std::string reason;
  };
  std::vector<Bad> bad(4, Bad{upside_down, ""});
  bad[0].pose.position.z = nan;
  bad[0].reason = "base_pose: position (0, 0, nan) is not finite";
  bad[1].pose.orientation = geometry_msgs::Quaternion();  // all zero: the message's default
  bad[1].reason = "base_pose: orientation (x 0, y 0, z 0, w 0) is not a unit quaternion (length 0)";
  bad[2].pose.orientation.w = 1.0;
  bad[2].reason = "is not a unit quaternion (length 1.41421)";
  bad[3].pose.orientation.w = nan;
  bad[3].reason = "base_pose: orientation (x 1, y 0, z 0, w nan) is not a unit quaternion;";
  for (const Bad& b : bad) {
    norm2tex::HandStep srv;
    srv.request.frames = 5;
    srv.request.set_base_pose = true;
    srv.request.base_pose = b.pose;
    // Valid targets in the same request: refused with it.
    srv.request.targets.name = {"base_joint_gripper_left", "base_joint_gripper_right"};
    srv.request.targets.position = {-0.016, 0.016};
    ASSERT_TRUE(hand.step.call(srv)) << b.reason;  // answered: hand_sim is still there
    EXPECT_FALSE(srv.response.success) << b.reason;
    EXPECT_NE(srv.response.message.find("~step refused, nothing changed: "), std::string::npos)
        << srv.response.message;
    EXPECT_NE(srv.response.message.find(b.reason), std::string::npos) << srv.response.message;
  }

  // Nothing changed: no frame was stepped, no target set, the root did not move.
  const auto after = hand.stepFrames(1);
  EXPECT_EQ(after.frame, before.frame + 1);
  EXPECT_EQ(after.state.joint_targets, before.state.joint_targets);
  const geometry_msgs::Transform base_after = hand.base(after.stamp);
  EXPECT_EQ(base_after.translation.z, base_before.translation.z);
  EXPECT_EQ(base_after.rotation.x, base_before.rotation.x);
  EXPECT_EQ(base_after.rotation.w, base_before.rotation.w);

  // A pose is taken by the step that carries it; without the flag, base_pose is ignored.
  geometry_msgs::Pose up = upside_down;
  up.position.z = 0.143;
  EXPECT_NEAR(hand.base(hand.stepFrames(1, up).stamp).translation.z, 0.143, 1e-9);
  norm2tex::HandStep unflagged;
  unflagged.request.frames = 1;
  unflagged.request.base_pose.position.z = nan;
  ASSERT_TRUE(hand.step.call(unflagged));
  EXPECT_TRUE(unflagged.response.success) << unflagged.response.message;
  EXPECT_NEAR(hand.base(unflagged.response.stamp).translation.z, 0.143, 1e-9);
}

TEST(HandSimTexture, ANormalMapWithoutMaterialTexturesTheGraspAndLabelsTheEpisode) {
  // hand_sim_texture.test: normal_map:= with material:=none and beta:=0.3; digit_left_bare
  // renders digit_left's contact without texture.
  Hand hand;
  std::map<std::string, std::map<ros::Time, sensor_msgs::Image::ConstPtr>> image;
  std::vector<ros::Subscriber> subs;
  for (const std::string s : {"digit_left", "digit_left_bare"}) {
    subs.push_back(hand.nh.subscribe<sensor_msgs::Image>(
        s + "/image_raw", 100, [&, s](const auto& m) { image[s][m->header.stamp] = m; }));
  }
  norm2tex::EpisodeInfo::ConstPtr episode;
  ros::Subscriber episode_sub =
      hand.nh.subscribe<norm2tex::EpisodeInfo>("/episode", 1, [&](const auto& m) { episode = m; });
  ASSERT_TRUE(waitFor([&] { return subs[1].getNumPublishers() > 0 && episode; }, 60.0));
  EXPECT_EQ(episode->material, "none");
  EXPECT_DOUBLE_EQ(episode->beta, 0.3);  // the given beta, not a material's

  const auto view = [](const sensor_msgs::Image& m) {
    return cv::Mat(static_cast<int>(m.height), static_cast<int>(m.width), CV_8UC3,
                   const_cast<std::uint8_t*>(m.data.data()), m.step);
  };
  // |textured - bare| in grey levels at a step's stamp.
  const auto difference = [&](const ros::Time& t) {
    EXPECT_TRUE(waitFor(
        [&] { return image["digit_left"].count(t) && image["digit_left_bare"].count(t); }, 10.0));
    if (!image["digit_left"].count(t) || !image["digit_left_bare"].count(t)) return cv::Mat();
    cv::Mat diff, grey;
    cv::absdiff(view(*image["digit_left"][t]), view(*image["digit_left_bare"][t]), diff);
    cv::cvtColor(diff, grey, cv::COLOR_BGR2GRAY);
    return grey;
  };
  // Open, nothing touches: the texture is not drawn (the same background and noise seed).
  const auto open = hand.stepFrames(1);
  ASSERT_FALSE(open.state.in_contact[0]);
  const cv::Mat untouched = difference(open.stamp);
  ASSERT_FALSE(untouched.empty());
  EXPECT_EQ(cv::countNonZero(untouched), 0);

  // Held at the drives' 10 N: the cube's face presses the middle of the gel, and its relief shows.
  hand.send(closing(-0.016, 0.016, 1.0));
  const auto held = hand.stepFrames(90);
  ASSERT_TRUE(held.state.in_contact[0]);
  const cv::Mat touched = difference(held.stamp);
  ASSERT_FALSE(touched.empty());
  const cv::Rect middle(touched.cols / 4, touched.rows / 4, touched.cols / 2, touched.rows / 2);
  EXPECT_GT(cv::mean(touched(middle))[0], 1.0);

  std::string normal_map;
  if (hand.nh.getParam("/hand_texture_test/normal_map", normal_map)) {
    std::remove(normal_map.c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "hand_sim_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
