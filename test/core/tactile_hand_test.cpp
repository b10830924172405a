// TactileHand: any hand's DIGITs rendered a frame at a time. Each sensor draws what a renderer
// given the physics' pose draws, its gel's image changes where the object presses it and not
// elsewhere, the same commands give the same frames, and every mounted sensor gets its image.
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "norm2tex/sim/hand_sim.hpp"
#include "norm2tex/sim/tactile_hand.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

const std::string kRobots = std::string(NORM2TEX_SOURCE_DIR) + "/test/fixtures/robots";

bool sameImage(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

// The WSG-50 upside down over the floor (wsg50_top_grasp.yaml): its gel centres 15 mm above
// the floor, the fingers closing along x. The object rests on the floor between them, or `y`
// to the side. (Out of reach to the side, not along the grip axis: HandSim takes an object
// anywhere behind a gel's surface within the pad's outline as pressed into that gel.)
HandSimConfig topGrasp(const std::string& object, double half_height_m, double y = 0.0) {
  HandSimConfig config;
  config.hand = loadHandConfig(kRobots + "/wsg50/wsg50_top_grasp.yaml");
  config.object.mesh = object;
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.0, y, half_height_m));
  return config;
}

/// Mean |frame - background| over the pixels of `mask` (all channels), grey levels.
double meanAbsDiff(const cv::Mat3b& image, const cv::Mat3b& background, const cv::Mat1b& mask) {
  cv::Mat diff;
  cv::absdiff(image, background, diff);
  const cv::Scalar mean = cv::mean(diff, mask);
  return (mean[0] + mean[1] + mean[2]) / 3.0;
}

TEST(TactileHand, RendersEachSensorAtThePhysicsPoseOnWholeFrames) {
  const SensorModel sensor = makeDigitSensorModel();
  TactileHandOptions options;  // no material: textureless
  options.noise_seed = 3;
  TactileHand hand(topGrasp("box:30x30x30", 0.015), sensor, options);
  EXPECT_EQ(hand.sensorCount(), 2);
  EXPECT_EQ(hand.ticksPerFrame(), 17);
  EXPECT_EQ(hand.sim().ticks() % 17, 0);
  EXPECT_EQ(hand.sensorIndex("digit_right"), 1);
  test::expectError([&] { hand.sensorIndex("digit_middle"); },
                    {"sensor 'digit_middle'", "digit_left, digit_right"});
  test::expectError([&] { hand.frame(2); }, {"sensor index 2", "[0, 1]"});
  test::expectError([&] { hand.step(0); }, {"step frames = 0"});
  hand.sim().setOpening(0.0);
  hand.step(90);  // 1.5 s: the fingers close 24 mm at 20 mm/s, then press
  EXPECT_EQ(hand.sim().ticks() % 17, 0);
  EXPECT_EQ(hand.frameIndex(), hand.sim().ticks() / 17);

  TactileRenderer renderer(sensor);
  renderer.setObject(std::make_shared<TexturedMesh>(hand.sim().object().mesh));
  for (int s = 0; s < 2; ++s) {
    const Eigen::Isometry3d pose = hand.objectInGel(s);
    EXPECT_TRUE(pose.isApprox(hand.sim().gelInWorld(s).inverse() * hand.sim().objectInWorld(), 1e-12));
    // The physics' own contact pose: the object's penetration is the gel's indentation.
    EXPECT_TRUE(pose.isApprox(hand.sim().contact(s).object_in_gel, 1e-9));
    const TactileFrame& expected = renderer.render(pose, 3 * 1000003 + hand.frameIndex(),
                                                   hand.sim().contact(s).normal_force_n);
    EXPECT_TRUE(sameImage(hand.frame(s).image, expected.image)) << hand.sensorName(s);
  }
}

TEST(TactileHand, Wsg50ClosedOnABarShowsItWhereTheGelsArePressedAndNowhereElse) {
  const SensorModel sensor = makeDigitSensorModel();  // synthetic background: noise per frame
  TactileHandOptions options;
  options.noise_seed = 5;
  // A 40 x 10 x 10 mm bar lying on the floor across the fingers: it presses a 10 mm band at
  // one end of each gel pad (the pad is 19 x 26 mm, its centre 15 mm above the floor).
  TactileHand hand(topGrasp("box:40x10x10", 0.005), sensor, options);
  // The same hand with the bar out of reach: what the sensors show untouched (noise).
  TactileHand empty(topGrasp("box:40x10x10", 0.005, 0.5), sensor, options);
  for (TactileHand* h : {&hand, &empty}) {
    h->sim().setOpening(0.0);
    h->step(90);
  }
  for (int s = 0; s < 2; ++s) {
    const cv::Mat3b& background = hand.background(s);
    const cv::Mat1b all(background.size(), 255);
    // Untouched: no contact, the frame is the background up to the noise.
    ASSERT_FALSE(empty.sim().contact(s).in_contact);
    EXPECT_EQ(cv::countNonZero(empty.frame(s).contact_mask), 0);
    const double noise = meanAbsDiff(empty.frame(s).image, background, all);

    const GelContactState& c = hand.sim().contact(s);
    ASSERT_TRUE(c.in_contact) << hand.sensorName(s);
    const cv::Mat1b& pressed = hand.frame(s).contact_mask;
    const int area = cv::countNonZero(pressed);
    // Away from the press (the gel's smoothing spreads a press over a few pixels around it).
    cv::Mat1b near;
    cv::dilate(pressed, near, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(61, 61)));
    const cv::Mat1b away = ~near;
    const double inside = meanAbsDiff(hand.frame(s).image, background, pressed);
    const double outside = meanAbsDiff(hand.frame(s).image, background, away);
    std::printf("%s: %.3f mm, %.2f N; pressed %d px (%.0f %% of the image): |diff| %.2f; away "
                "(%d px) %.2f; untouched %.2f\n",
                hand.sensorName(s).c_str(), c.penetration_m * 1e3, c.normal_force_n, area,
                100.0 * area / background.total(), inside, cv::countNonZero(away), outside, noise);
    EXPECT_GT(area, 0.1 * background.total());
    EXPECT_LT(area, 0.6 * background.total());
    EXPECT_GT(cv::countNonZero(away), 0.2 * background.total());
    EXPECT_GT(inside, 5.0 * noise);
    EXPECT_LT(outside, 1.2 * noise);
  }
}

TEST(TactileHand, TheSameCommandsGiveBitIdenticalFramesAndResetStartsAgain) {
  const SensorModel sensor = makeDigitSensorModel();
  TactileHandOptions options;
  options.noise_seed = 7;
  options.noise_per_episode = true;
  const HandSimConfig config = topGrasp("box:30x30x30", 0.015);
  TactileHand a(config, sensor, options), b(config, sensor, options);
  auto run = [](TactileHand& h) {
    h.sim().setOpening(0.2);
    h.step(40);
    h.sim().setJointTargets({"base_joint_gripper_left"}, {-0.012});
    h.step(30);
  };
  run(a);
  run(b);
  for (int s = 0; s < 2; ++s) {
    EXPECT_TRUE(sameImage(a.frame(s).image, b.frame(s).image));
    EXPECT_GT(cv::countNonZero(a.frame(s).contact_mask), 0);
  }
  const cv::Mat3b first = a.frame(0).image.clone();
  // Reset: the episode again from its start gives the same frames (noise counted per episode).
  a.reset();
  EXPECT_EQ(cv::countNonZero(a.frame(0).contact_mask), 0);
  run(a);
  EXPECT_TRUE(sameImage(a.frame(0).image, first));
  // A reset with another pose: the object out of reach, nothing pressed.
  a.reset(Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.5, 0.015)));
  run(a);
  EXPECT_EQ(cv::countNonZero(a.frame(0).contact_mask), 0);
  test::expectError([&] { a.reset(Eigen::Isometry3d(Eigen::Translation3d(NAN, 0.0, 0.0))); },
                    {"not a finite rigid pose"});
}

TEST(TactileHand, TheAllegroRendersOneImagePerDigit) {
  HandSimConfig config;
  config.hand = loadHandConfig(kRobots + "/allegro_hand_description/allegro_hand.yaml");
  config.object.mesh = "sphere:10";
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.5, 0.0, 0.005));  // out of reach
  const SensorModel sensor = makeDigitSensorModel();
  TactileHandOptions options;
  options.noise_seed = -1;  // no noise: untouched frames are the background exactly
  TactileHand hand(config, sensor, options);
  ASSERT_EQ(hand.sensorCount(), 4);
  hand.sim().setJointTargets({"joint_1.0", "joint_2.0"}, {0.8, 0.6});
  hand.step(30);
  const char* names[] = {"digit_index", "digit_middle", "digit_ring", "digit_thumb"};
  for (int s = 0; s < 4; ++s) {
    EXPECT_EQ(hand.sensorName(s), names[s]);
    EXPECT_EQ(hand.frame(s).image.rows, sensor.rows);
    EXPECT_EQ(hand.frame(s).image.cols, sensor.cols);
    EXPECT_TRUE(sameImage(hand.frame(s).image, hand.background(s)));
    // Each renders its own gel's pose.
    EXPECT_TRUE(hand.objectInGel(s).isApprox(
        hand.sim().gelInWorld(s).inverse() * hand.sim().objectInWorld(), 1e-12));
  }
  // The index finger moved; its gel with it.
  EXPECT_GT((hand.objectInGel(0).translation() - hand.objectInGel(1).translation()).norm(), 0.01);
}

TEST(TactileHand, SensorsRenderedAtOnceGiveTheFramesRenderedOneAfterAnother) {
  // The Allegro palm up, four fingers closed on a ball, wood texture and noise: every sensor's
  // frame the same on one thread and on one per sensor.
  HandSimConfig config;
  config.hand = loadHandConfig(kRobots + "/allegro_hand_description/allegro_palm_up.yaml");
  config.object.mesh = "sphere:45";
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.03, 0.0, 0.17));
  const SensorModel sensor = makeDigitSensorModel();
  TactileHandOptions options;
  options.material_config = std::string(NORM2TEX_SOURCE_DIR) + "/config/materials/wood.yaml";
  options.noise_seed = 5;
  TactileHand serial(config, sensor, options);
  options.render_threads = 4;
  TactileHand parallel(config, sensor, options);
  const std::vector<std::string> fingers = {"joint_1.0", "joint_5.0", "joint_9.0", "joint_13.0"};
  const std::vector<double> closed = {0.9, 0.9, 0.9, 1.2};
  int touching = 0;
  for (TactileHand* hand : {&serial, &parallel}) {
    hand->sim().setJointTargets(fingers, closed);
    hand->step(60);
  }
  for (int s = 0; s < 4; ++s) {
    EXPECT_TRUE(sameImage(serial.frame(s).image, parallel.frame(s).image)) << s;
    touching += !sameImage(serial.frame(s).image, serial.background(s));
  }
  EXPECT_GE(touching, 1);  // a test of rendered contacts, not of blank frames

  options.render_threads = -1;
  test::expectError([&] { TactileHand bad(config, sensor, options); },
                    {"render_threads = -1", "[0, 256]"});
}

}  // namespace
}  // namespace norm2tex
