// rostest of contact_sim with a real master and the real node (see contact_sim.test and
// contact_sim_sync.test): waits on conditions with deadlines, never sleeps to synchronise.
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/gripper_sim.hpp"
#include "norm2tex/EpisodeInfo.h"
#include "norm2tex/EpisodeState.h"
#include "norm2tex/GripperCommand.h"
#include "norm2tex/Reset.h"
#include "norm2tex/Step.h"
#include "norm2tex/TactileContact.h"
#include "run_node.hpp"
#include "wait_for.hpp"

namespace {

using norm2tex::waitFor;

struct Listener {
  ros::NodeHandle nh;
  tf2_ros::Buffer buffer{ros::Duration(30.0)};
  tf2_ros::TransformListener tf{buffer, nh};
  std::array<norm2tex::TactileContact::ConstPtr, 2> contacts;
  sensor_msgs::JointState::ConstPtr joints;
  rosgraph_msgs::Clock::ConstPtr clock;
  int clock_count = 0;
  norm2tex::EpisodeInfo::ConstPtr episode;
  ros::Subscriber subs[5] = {
      nh.subscribe<norm2tex::TactileContact>("/digit_left/contact", 10,
                                             [this](const auto& m) { contacts[0] = m; }),
      nh.subscribe<norm2tex::TactileContact>("/digit_right/contact", 10,
                                             [this](const auto& m) { contacts[1] = m; }),
      nh.subscribe<sensor_msgs::JointState>("/joint_states", 10,
                                            [this](const auto& m) { joints = m; }),
      nh.subscribe<rosgraph_msgs::Clock>("/clock", 100,
                                         [this](const auto& m) {
                                           clock = m;
                                           ++clock_count;
                                         }),
      nh.subscribe<norm2tex::EpisodeInfo>("/episode", 1, [this](const auto& m) { episode = m; })};
};

int runContactSim(const std::string& args, std::string& output) {
  return norm2tex::test::runNodeUntilExit(NORM2TEX_CONTACT_SIM_EXECUTABLE, args, output);
}

TEST(RealTime, TfJointStatesAndContactsPublishWithOneStamp) {
  Listener l;
  ASSERT_TRUE(waitFor(
      [&] {
        return l.buffer.canTransform("digit_left_gel", "object", ros::Time(0)) &&
               l.buffer.canTransform("digit_right_gel", "object", ros::Time(0));
      },
      20.0))
      << "TF object -> digit_*_gel never resolved";
  // The left gel's latest stamp resolves for the right gel too: one stamp per frame.
  const geometry_msgs::TransformStamped left =
      l.buffer.lookupTransform("digit_left_gel", "object", ros::Time(0));
  const geometry_msgs::TransformStamped right =
      l.buffer.lookupTransform("digit_right_gel", "object", left.header.stamp);
  EXPECT_EQ(left.header.stamp, right.header.stamp);
  EXPECT_GT(left.header.stamp, ros::Time(0));
  // The cube sits 15 mm minus the grasp indentation (1 mm) above each gel.
  EXPECT_NEAR(left.transform.translation.z, 0.014, 0.2e-3);
  EXPECT_NEAR(right.transform.translation.z, 0.014, 0.2e-3);
  // Every frame of the chain exists.
  for (const char* frame : {"gripper_base", "finger_left", "finger_right"}) {
    EXPECT_TRUE(l.buffer.canTransform("world", frame, ros::Time(0))) << frame;
  }

  ASSERT_TRUE(waitFor([&] { return l.joints && l.contacts[0] && l.contacts[1]; }, 10.0));
  ASSERT_EQ(l.joints->name.size(), 2u);
  EXPECT_EQ(l.joints->name[0], "finger_left_joint");
  EXPECT_EQ(l.joints->name[1], "finger_right_joint");
  EXPECT_NEAR(l.joints->position[0], 0.014, 0.05e-3);  // 28 mm gap at opening 0.7
  for (int i = 0; i < 2; ++i) {
    const norm2tex::TactileContact& c = *l.contacts[i];
    EXPECT_EQ(c.sensor, i == 0 ? "digit_left" : "digit_right");
    EXPECT_EQ(c.header.frame_id, i == 0 ? "digit_left_gel" : "digit_right_gel");
    EXPECT_TRUE(c.in_contact);
    EXPECT_NEAR(c.max_indentation, 1e-3, 0.02e-3);
    EXPECT_NEAR(c.normal_force, 12.85, 0.5);             // the gel law at 1 mm
    EXPECT_NEAR(c.shear_force.y, 0.1 * 9.81 / 2, 0.05);  // each gel carries half the cube
    // The cube face covers the gel pad, which is the shipped sensor's imaged area.
    const norm2tex::SensorModel sensor =
        norm2tex::loadSensorModel(NORM2TEX_SOURCE_DIR "/config/digit.yaml");
    EXPECT_NEAR(c.contact_area, sensor.gelWidthMm() * sensor.gelHeightMm() * 1e-6, 1e-6);
  }
}

// The gel frames never move on their fingers: they are on /tf_static (latched, once), not among
// the 60 Hz /tf. And a real-time contact_sim without simulated time does not advertise a /clock
// it never publishes.
TEST(RealTime, FixedGelTransformsAreStaticAndNoSilentClock) {
  ros::NodeHandle nh;
  std::vector<geometry_msgs::TransformStamped> statics;
  std::set<std::string> tf_children;
  int tf_messages = 0;
  ros::Subscriber static_sub = nh.subscribe<tf2_msgs::TFMessage>(
      "/tf_static", 10, [&](const auto& m) {
        statics.insert(statics.end(), m->transforms.begin(), m->transforms.end());
      });
  ros::Subscriber tf_sub = nh.subscribe<tf2_msgs::TFMessage>("/tf", 100, [&](const auto& m) {
    ++tf_messages;
    for (const auto& t : m->transforms) tf_children.insert(t.child_frame_id);
  });
  // Half a second of frames, and the latched static transforms.
  ASSERT_TRUE(waitFor([&] { return tf_messages >= 30 && statics.size() >= 2; }, 20.0))
      << tf_messages << " /tf messages, " << statics.size() << " static transforms";
  EXPECT_EQ(statics.size(), 2u);
  for (const auto& t : statics) {
    const bool left = t.child_frame_id == "digit_left_gel";
    EXPECT_TRUE(left || t.child_frame_id == "digit_right_gel") << t.child_frame_id;
    EXPECT_EQ(t.header.frame_id, left ? "finger_left" : "finger_right");
    const Eigen::Isometry3d expected = norm2tex::GripperSim::gelInFinger(
        left ? norm2tex::Finger::kLeft : norm2tex::Finger::kRight);
    EXPECT_NEAR(t.transform.translation.x, expected.translation().x(), 1e-9);
    EXPECT_NEAR(t.transform.translation.y, expected.translation().y(), 1e-9);
    EXPECT_NEAR(t.transform.translation.z, expected.translation().z(), 1e-9);
    const Eigen::Quaterniond q(expected.linear());
    EXPECT_NEAR(std::abs(t.transform.rotation.w * q.w() + t.transform.rotation.x * q.x() +
                         t.transform.rotation.y * q.y() + t.transform.rotation.z * q.z()),
                1.0, 1e-9)
        << t.child_frame_id;
  }
  for (const char* moving : {"gripper_base", "finger_left", "finger_right", "object"}) {
    EXPECT_EQ(tf_children.count(moving), 1u) << moving << " is not on /tf";
  }
  EXPECT_EQ(tf_children.count("digit_left_gel"), 0u);
  EXPECT_EQ(tf_children.count("digit_right_gel"), 0u);

  // contact_sim advertised /tf before it would have advertised /clock, and the master knows
  // every advertised topic at once: no /clock means none is advertised.
  ros::master::V_TopicInfo topics;
  ASSERT_TRUE(ros::master::getTopics(topics));
  for (const ros::master::TopicInfo& topic : topics) EXPECT_NE(topic.name, "/clock");
}

TEST(RealTime, OpeningTheGripperDropsTheCubeAndBadCommandsChangeNothing) {
  Listener l;
  norm2tex::EpisodeState::ConstPtr state;
  ros::Subscriber state_sub = l.nh.subscribe<norm2tex::EpisodeState>(
      "/episode_state", 10, [&](const auto& m) { state = m; });
  ros::Publisher command = l.nh.advertise<norm2tex::GripperCommand>("/gripper/command", 10, true);
  ASSERT_TRUE(waitFor([&] { return l.joints && command.getNumSubscribers() > 0; }, 20.0));
  // Latched: the episode's state reaches a late subscriber. Held, not dropped.
  ASSERT_TRUE(waitFor([&] { return state && l.episode; }, 20.0));
  EXPECT_FALSE(state->dropped);
  EXPECT_EQ(state->episode, l.episode->episode);
  const double held = l.joints->position[0];
  norm2tex::GripperCommand bad;
  bad.mode = norm2tex::GripperCommand::ABSOLUTE;
  bad.opening = std::nan("");
  command.publish(bad);
  bad.opening = 1.5;
  command.publish(bad);
  bad.mode = 7;
  bad.opening = 0.5;
  command.publish(bad);
  // Half a second of frames later the fingers have not moved.
  const ros::Time since = l.joints->header.stamp;
  ASSERT_TRUE(waitFor([&] { return (l.joints->header.stamp - since).toSec() > 0.5; }, 10.0));
  EXPECT_DOUBLE_EQ(l.joints->position[0], held);

  norm2tex::GripperCommand open;
  open.mode = norm2tex::GripperCommand::ABSOLUTE;
  open.opening = 1.0;
  command.publish(open);
  EXPECT_TRUE(
      waitFor([&] { return !l.contacts[0]->in_contact && !l.contacts[1]->in_contact; }, 20.0))
      << "the cube never left the gels";
  EXPECT_TRUE(waitFor([&] { return l.joints->position[0] > 0.0199; }, 20.0));
  // Real time has no ~step to return `dropped`: /episode_state says it, stamped with the frame.
  EXPECT_TRUE(waitFor([&] { return state->dropped; }, 20.0)) << "/episode_state never said dropped";
  EXPECT_EQ(state->episode, l.episode->episode);
  EXPECT_GT(state->header.stamp, l.episode->header.stamp);
}

TEST(BadInput, StartUpErrorsExitNonZeroNamingTheCause) {
  struct Case {
    std::string args, expected;
  } cases[] = {
      {"_scene:=/nonexistent/scene.yaml", "/nonexistent/scene.yaml"},
      {"_material:=unobtainium", "wood"},
      {"_mode:=turbo", "real_time, synchronous"},
      {"_physics_rate:=5.0", "~physics_rate"},
      {"_sensor:=/nonexistent/digit.yaml", "/nonexistent/digit.yaml"},
      {"_window:=0", "~window"},
  };
  for (const Case& c : cases) {
    std::string output;
    EXPECT_EQ(runContactSim(c.args, output), 1) << c.args << ":\n" << output;
    EXPECT_NE(output.find(c.expected), std::string::npos) << c.args << ":\n" << output;
  }
}

TEST(Synchronous, StepsAdvanceClockAndTfByExactlyTheirFramesAndNothingElse) {
  Listener l;
  ros::ServiceClient step = l.nh.serviceClient<norm2tex::Step>("/contact_sim/step");
  ASSERT_TRUE(step.waitForExistence(ros::Duration(30.0)));
  norm2tex::Step srv;
  ros::Time last;
  // Topic connections form asynchronously: step single frames until this listener's /clock and
  // TF subscriptions deliver one (a condition with a deadline, not a sleep).
  ASSERT_TRUE(waitFor(
      [&] {
        srv.request.frames = 1;
        if (!step.call(srv)) return false;
        last = srv.response.stamp;
        return waitFor(
            [&] {
              return l.clock && l.clock->clock == last &&
                     l.buffer.canTransform("digit_left_gel", "object", last);
            },
            0.2);
      },
      20.0));
  const std::uint64_t period_ns = 16666667;  // 60 Hz
  for (std::uint32_t frames : {1u, 1u, 3u, 10u}) {
    srv.request.frames = frames;
    ASSERT_TRUE(step.call(srv));
    EXPECT_EQ(srv.response.stamp.toNSec() - last.toNSec(), frames * period_ns);
    last = srv.response.stamp;
    ASSERT_TRUE(waitFor(
        [&] {
          return l.clock->clock == last && l.buffer.canTransform("digit_left_gel", "object", last);
        },
        10.0))
        << "/clock or TF never reached the step's stamp";
    EXPECT_FALSE(srv.response.dropped);
  }
  // Between calls nothing moves: no new clock tick in 0.3 s of wall time. (This waits for an
  // absence, which no condition can signal; nothing is synchronised by it.)
  const int ticks = l.clock_count;
  ros::WallDuration(0.3).sleep();
  ros::spinOnce();
  EXPECT_EQ(l.clock_count, ticks);
  EXPECT_EQ(l.clock->clock, last);

  // A command inside a step applies; a NaN command fails the call and changes nothing.
  const double before = srv.response.opening;
  srv.request.frames = 30;
  srv.request.set_command = true;
  srv.request.command.mode = norm2tex::GripperCommand::DELTA;
  srv.request.command.opening = 0.005;
  ASSERT_TRUE(step.call(srv));
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_NEAR(srv.response.opening, before + 0.005, 1e-6);
  // Refusals come back to the caller with the reason, and change nothing.
  srv.request.command.opening = std::nan("");
  ASSERT_TRUE(step.call(srv));
  EXPECT_FALSE(srv.response.success);
  EXPECT_NE(srv.response.message.find("[-1, 1]"), std::string::npos) << srv.response.message;
  srv.request.set_command = false;
  srv.request.frames = 1;
  ASSERT_TRUE(step.call(srv));
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_NEAR(srv.response.opening, before + 0.005, 1e-6);
  EXPECT_EQ(srv.response.stamp.toNSec() - last.toNSec(), 31 * period_ns);
  srv.request.frames = 0;
  ASSERT_TRUE(step.call(srv));
  EXPECT_FALSE(srv.response.success);
  EXPECT_NE(srv.response.message.find("frames = 0"), std::string::npos) << srv.response.message;
  EXPECT_NE(srv.response.message.find("[1, 100000]"), std::string::npos) << srv.response.message;
}

TEST(Synchronous, ResetPlacesTheObjectAndPublishesTheEpisode) {
  Listener l;
  ros::ServiceClient reset = l.nh.serviceClient<norm2tex::Reset>("/contact_sim/reset");
  ASSERT_TRUE(reset.waitForExistence(ros::Duration(30.0)));
  norm2tex::Reset srv;
  srv.request.seed = 11;
  srv.request.height_offset = 0.012;
  ASSERT_TRUE(reset.call(srv));
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_DOUBLE_EQ(srv.response.info.height_offset, 0.012);
  EXPECT_EQ(srv.response.info.material, "fabric");
  EXPECT_EQ(srv.response.info.object, "cube");
  EXPECT_EQ(srv.response.info.seed, 11);
  EXPECT_EQ(srv.response.info.scenario, "grasp");
  EXPECT_GT(srv.response.info.beta, 0.0);
  ASSERT_TRUE(waitFor([&] { return l.episode && l.episode->seed == 11; }, 10.0));  // latched
  EXPECT_EQ(l.episode->episode, srv.response.info.episode);
  ros::ServiceClient step = l.nh.serviceClient<norm2tex::Step>("/contact_sim/step");
  norm2tex::Step one;
  one.request.frames = 1;
  ASSERT_TRUE(waitFor(
      [&] {
        return step.call(one) &&
               waitFor(
                   [&] {
                     return l.buffer.canTransform("digit_left_gel", "object", one.response.stamp);
                   },
                   0.2);
      },
      20.0));
  const geometry_msgs::TransformStamped pose =
      l.buffer.lookupTransform("digit_left_gel", "object", one.response.stamp);
  EXPECT_NEAR(pose.transform.translation.y, -0.012, 0.2e-3);  // 12 mm up = image -y
  // A random offset stays in the scene's range [0, 25] mm.
  srv.request.height_offset = std::nan("");
  ASSERT_TRUE(reset.call(srv));
  EXPECT_GE(srv.response.info.height_offset, 0.0);
  EXPECT_LE(srv.response.info.height_offset, 0.025);
  const std::uint32_t episode = srv.response.info.episode;
  // Offsets outside the scene's [0, 25] mm are refused with the range, not run or relabelled;
  // so is a negative seed. No episode starts.
  for (double offset : {0.5, 0.03, -0.5, -0.001}) {
    srv.request.seed = 1;
    srv.request.height_offset = offset;
    ASSERT_TRUE(reset.call(srv)) << offset;
    EXPECT_FALSE(srv.response.success) << offset;
    EXPECT_NE(srv.response.message.find("height offset"), std::string::npos)
        << srv.response.message;
    EXPECT_NE(srv.response.message.find("[0, 0.025]"), std::string::npos) << srv.response.message;
  }
  srv.request.seed = -1;
  srv.request.height_offset = 0.01;
  ASSERT_TRUE(reset.call(srv));
  EXPECT_FALSE(srv.response.success);
  EXPECT_NE(srv.response.message.find("seed -1"), std::string::npos) << srv.response.message;
  EXPECT_NE(srv.response.message.find(">= 0"), std::string::npos) << srv.response.message;
  srv.request.seed = 2;
  ASSERT_TRUE(reset.call(srv));
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.info.episode, episode + 1);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "contact_sim_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
