// rostests of what users bring through gripper_sim.launch: their own normal map instead of a
// procedural material (own_texture.test), the physics' friction without a material
// (own_friction.test), and their own mesh (own_mesh.test). Conditions are awaited with
// deadlines.
#include <cstdio>
#include <map>
#include <string>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "norm2tex/EpisodeInfo.h"
#include "norm2tex/EpisodeState.h"
#include "norm2tex/GripperCommand.h"
#include "norm2tex/Reset.h"
#include "norm2tex/Step.h"
#include "norm2tex/TactileContact.h"
#include "wait_for.hpp"

namespace {

using norm2tex::waitFor;

cv::Mat view(const sensor_msgs::Image& msg) {
  const int type = msg.encoding == "bgr8" ? CV_8UC3 : CV_8UC1;
  return cv::Mat(static_cast<int>(msg.height), static_cast<int>(msg.width), type,
                 const_cast<std::uint8_t*>(msg.data.data()), msg.step);
}

TEST(OwnTexture, ANormalMapWithoutMaterialTexturesTheContactAndLabelsTheEpisode) {
  ros::NodeHandle nh;
  std::map<std::string, std::map<ros::Time, sensor_msgs::Image::ConstPtr>> image, mask;
  std::vector<ros::Subscriber> subs;
  for (const std::string s : {"digit_left", "digit_left_bare"}) {
    subs.push_back(nh.subscribe<sensor_msgs::Image>(
        s + "/image_raw", 100, [&, s](const auto& m) { image[s][m->header.stamp] = m; }));
    subs.push_back(nh.subscribe<sensor_msgs::Image>(
        s + "/contact_mask", 100, [&, s](const auto& m) { mask[s][m->header.stamp] = m; }));
  }
  ros::ServiceClient reset = nh.serviceClient<norm2tex::Reset>("/contact_sim/reset");
  ros::ServiceClient step = nh.serviceClient<norm2tex::Step>("/contact_sim/step");
  ASSERT_TRUE(step.waitForExistence(ros::Duration(60.0)));
  ASSERT_TRUE(waitFor(
      [&] {
        for (const ros::Subscriber& sub : subs) {
          if (sub.getNumPublishers() == 0) return false;
        }
        return true;
      },
      60.0));
  norm2tex::Reset episode;
  episode.request.seed = 2;
  episode.request.height_offset = 0.010;
  ASSERT_TRUE(reset.call(episode));
  ASSERT_TRUE(episode.response.success) << episode.response.message;
  EXPECT_EQ(episode.response.info.material, "none");
  EXPECT_DOUBLE_EQ(episode.response.info.beta, 0.3);  // the given beta, not a material's
  norm2tex::Step one;
  one.request.frames = 1;
  ASSERT_TRUE(step.call(one));
  ASSERT_TRUE(one.response.success) << one.response.message;
  EXPECT_EQ(one.response.missing_images, 0u);
  const ros::Time t = one.response.stamp;
  ASSERT_TRUE(waitFor(
      [&] {
        return image["digit_left"].count(t) && image["digit_left_bare"].count(t) &&
               mask["digit_left"].count(t) && mask["digit_left_bare"].count(t);
      },
      10.0));
  const cv::Mat contact = view(*mask["digit_left"][t]);
  // Same geometry, so the same contact; inside it the normal map's relief shows.
  EXPECT_EQ(cv::norm(contact, view(*mask["digit_left_bare"][t]), cv::NORM_INF), 0.0);
  ASSERT_GT(cv::countNonZero(contact), 5000);
  cv::Mat diff;
  cv::absdiff(view(*image["digit_left"][t]), view(*image["digit_left_bare"][t]), diff);
  const cv::Scalar inside = cv::mean(diff, contact);
  EXPECT_GT((inside[0] + inside[1] + inside[2]) / 3.0, 1.0);

  std::string normal_map;
  if (nh.getParam("/own_texture_test/normal_map", normal_map)) std::remove(normal_map.c_str());
}

TEST(OwnFriction, WithoutAMaterialTheGivenFrictionIsThePhysics) {
  ros::NodeHandle nh;
  ros::ServiceClient reset = nh.serviceClient<norm2tex::Reset>("/contact_sim/reset");
  ros::ServiceClient step = nh.serviceClient<norm2tex::Step>("/contact_sim/step");
  ASSERT_TRUE(step.waitForExistence(ros::Duration(60.0)));
  norm2tex::Reset episode;
  episode.request.seed = 1;
  episode.request.height_offset = 0.010;
  ASSERT_TRUE(reset.call(episode));
  ASSERT_TRUE(episode.response.success) << episode.response.message;
  EXPECT_EQ(episode.response.info.material, "none");
  // The cube slides out under its own weight: dropped within 2 s of simulated time.
  norm2tex::Step srv;
  srv.request.frames = 12;
  for (int i = 0; i < 10 && !srv.response.dropped; ++i) {
    ASSERT_TRUE(step.call(srv));
    ASSERT_TRUE(srv.response.success) << srv.response.message;
  }
  EXPECT_TRUE(srv.response.dropped);
}

TEST(OwnMesh, AUsersCylinderIsHeldStillAtEveryOffsetOfTheScene) {
  // Once thrown 0.29 / 2.8 / 0.08 m at these offsets, through its right gel.
  ros::NodeHandle nh;
  std::map<std::string, std::map<ros::Time, norm2tex::TactileContact::ConstPtr>> contact;
  std::vector<ros::Subscriber> subs;
  for (const std::string s : {"digit_left", "digit_right"}) {
    subs.push_back(nh.subscribe<norm2tex::TactileContact>(
        s + "/contact", 100, [&, s](const auto& m) { contact[s][m->header.stamp] = m; }));
  }
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  ros::ServiceClient reset = nh.serviceClient<norm2tex::Reset>("/contact_sim/reset");
  ros::ServiceClient step = nh.serviceClient<norm2tex::Step>("/contact_sim/step");
  ASSERT_TRUE(step.waitForExistence(ros::Duration(60.0)));
  ASSERT_TRUE(waitFor([&] { return subs[0].getNumPublishers() && subs[1].getNumPublishers(); },
                      60.0));
  const auto objectAt = [&](const ros::Time& t) {
    // (Simulated time stands still between steps: wait on the wall clock.)
    EXPECT_TRUE(waitFor([&] { return buffer.canTransform("world", "object", t); }, 10.0));
    const auto& p = buffer.lookupTransform("world", "object", t).transform.translation;
    return Eigen::Vector3d(p.x, p.y, p.z);
  };
  const auto frame = [&](int frames) {
    norm2tex::Step srv;
    srv.request.frames = frames;
    EXPECT_TRUE(step.call(srv));
    EXPECT_TRUE(srv.response.success) << srv.response.message;
    return srv.response.stamp;
  };
  for (double offset : {0.0, 0.0125, 0.025}) {
    norm2tex::Reset episode;
    episode.request.seed = 0;
    episode.request.height_offset = offset;
    ASSERT_TRUE(reset.call(episode));
    ASSERT_TRUE(episode.response.success) << episode.response.message;
    const Eigen::Vector3d start = objectAt(frame(1));
    const ros::Time t = frame(60);  // one second
    const Eigen::Vector3d held = objectAt(t);
    EXPECT_LT((held - start).norm(), 0.2e-3) << offset;
    // Where the episode put it: centred between the gels, the offset above their centres.
    EXPECT_NEAR(held.z(), 0.200 + offset, 0.3e-3) << offset;
    EXPECT_NEAR(held.x(), 0.0, 0.3e-3) << offset;
    EXPECT_NEAR(held.y(), 0.0, 0.3e-3) << offset;
    ASSERT_TRUE(waitFor(
        [&] { return contact["digit_left"].count(t) && contact["digit_right"].count(t); }, 10.0));
    const auto& left = *contact["digit_left"][t];
    const auto& right = *contact["digit_right"][t];
    EXPECT_TRUE(left.in_contact && right.in_contact) << offset;
    EXPECT_NEAR(left.normal_force, right.normal_force, 0.1 * left.normal_force) << offset;
    for (const auto* c : {&left, &right}) {
      EXPECT_NEAR(c->max_indentation, 1e-3, 0.1e-3) << offset;  // the scene's grip, adapted
      EXPECT_FALSE(c->too_deep);
    }
  }
  // Squeezed to the gripper's force limit (35 N, 2.03 mm): deeper than the gel law's table
  // (2 mm), which the contact says at the frame and the episode's state keeps.
  norm2tex::EpisodeState::ConstPtr state;
  ros::Subscriber state_sub = nh.subscribe<norm2tex::EpisodeState>(
      "/episode_state", 10, [&](const auto& m) { state = m; });
  ros::Publisher command = nh.advertise<norm2tex::GripperCommand>("/gripper/command", 1);
  ASSERT_TRUE(waitFor([&] { return command.getNumSubscribers() > 0 && state; }, 10.0));
  EXPECT_FALSE(state->too_deep);
  norm2tex::GripperCommand squeeze;
  squeeze.mode = norm2tex::GripperCommand::ABSOLUTE;
  squeeze.opening = 0.0;
  command.publish(squeeze);
  ros::Time t;
  for (int i = 0; i < 20 && !(state && state->too_deep); ++i) {
    t = frame(6);
    waitFor([&] { return state && state->header.stamp == t; }, 1.0);  // changed at this frame?
  }
  ASSERT_TRUE(state && state->too_deep) << "/episode_state never said too_deep";
  ASSERT_TRUE(waitFor([&] { return contact["digit_left"].count(t) > 0; }, 10.0));
  EXPECT_TRUE(contact["digit_left"][t]->too_deep);
  EXPECT_GT(contact["digit_left"][t]->max_indentation, 2e-3);
  std::string mesh;
  if (nh.getParam("/own_mesh_test/mesh", mesh)) std::remove(mesh.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "own_objects_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
