// TactileGripper, TactileGripperBatch and ParallelFor: a gripper renders what a renderer given
// the same pose renders, follows contact_sim's clock and noise rule, a batch on threads equals
// grippers run alone, and the pool runs every job once and passes errors on.
#include <atomic>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "norm2tex/common/error.hpp"
#include "norm2tex/common/parallel_for.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "norm2tex/sim/tactile_gripper.hpp"
#include "norm2tex/sim/tactile_gripper_batch.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

std::string source(const std::string& relative) {
  return std::string(NORM2TEX_SOURCE_DIR) + "/" + relative;
}

TactileGripperOptions woodOptions() {
  TactileGripperOptions o;
  o.material_config = source("config/materials/wood.yaml");
  return o;
}

bool sameImage(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

TEST(ParallelForTest, RunsEveryJobOnceAndRethrowsTheFirstError) {
  ParallelFor pool(3);
  EXPECT_EQ(pool.threads(), 3);
  for (int round = 0; round < 50; ++round) {
    std::vector<std::atomic<int>> hits(37);
    pool.run(37, [&](int i) { hits[i]++; });
    for (const auto& h : hits) ASSERT_EQ(h.load(), 1);
  }
  std::atomic<int> ran{0};
  EXPECT_THROW(pool.run(8,
                        [&](int i) {
                          ++ran;
                          if (i == 5) throw Error("job 5 failed");
                        }),
               Error);
  EXPECT_EQ(ran.load(), 8);  // the other jobs still ran
  pool.run(0, [](int) { FAIL(); });
  int after = 0;
  pool.run(1, [&](int) { ++after; });  // usable after an error
  EXPECT_EQ(after, 1);
}

TEST(TactileGripperTest, RendersWhatARendererDrawsAtItsPoseOnContactSimsClock) {
  const SensorModel sensor = makeDigitSensorModel();  // synthetic background: noise per frame
  const GripperSimConfig scene = loadGripperSimConfig(source("config/scenes/cube.yaml"));
  TactileGripperOptions options;  // no material: textureless, friction 0.5
  options.noise_seed = 3;
  TactileGripper gripper(scene, sensor, options);
  // contact_sim's rounding: 1000 Hz asked at 60 Hz frames = 17 ticks, 1020 Hz.
  EXPECT_EQ(gripper.ticksPerFrame(), 17);
  EXPECT_NEAR(gripper.frameSeconds(), 1.0 / 60.0, 1e-12);
  EXPECT_EQ(gripper.sim().ticks() % 17, 0);  // the first episode is padded to whole frames
  gripper.sim().setOpening(0.6);
  gripper.step(5);
  EXPECT_EQ(gripper.sim().ticks() % 17, 0);

  TactileRenderer renderer(sensor);
  renderer.setObject(std::make_shared<TexturedMesh>(gripper.sim().object().mesh));
  for (const Finger finger : {Finger::kLeft, Finger::kRight}) {
    const Eigen::Isometry3d pose = gripper.objectInGel(finger);
    // The pose is the physics' own: the object's penetration is the sim's contact depth.
    EXPECT_TRUE(pose.isApprox(gripper.sim().contact(finger).object_in_gel, 1e-9));
    const TactileFrame& expected = renderer.render(pose, 3 * 1000003 + gripper.frameIndex());
    EXPECT_TRUE(sameImage(gripper.frame(finger).image, expected.image));
    EXPECT_GT(cv::countNonZero(gripper.frame(finger).contact_mask), 1000);
  }
}

TEST(TactileGripperTest, PerEpisodeNoiseRepeatsAnEpisodeWhateverCameBefore) {
  // The synthetic background: noise is drawn per frame (a captured one carries its own).
  const SensorModel sensor = makeDigitSensorModel();
  const GripperSimConfig scene = loadGripperSimConfig(source("config/scenes/cube.yaml"));
  TactileGripperOptions options = woodOptions();
  options.noise_per_episode = true;
  TactileGripper a(scene, sensor, options);
  TactileGripper b(scene, sensor, options);
  b.sim().setOpening(0.5);
  b.step(30);  // b has a history a has not
  a.reset(9, 0.01);
  b.reset(9, 0.01);
  EXPECT_NE(a.frameIndex(), b.frameIndex());
  for (int i = 0; i < 3; ++i) {
    a.step();
    b.step();
    EXPECT_TRUE(sameImage(a.frame(Finger::kLeft).image, b.frame(Finger::kLeft).image));
    EXPECT_TRUE(sameImage(a.frame(Finger::kRight).image, b.frame(Finger::kRight).image));
  }
  // Without it the noise follows the frame count since construction (the ROS rule).
  options.noise_per_episode = false;
  TactileGripper c(scene, sensor, options);
  TactileGripper d(scene, sensor, options);
  d.step(30);
  c.reset(9, 0.01);
  d.reset(9, 0.01);
  EXPECT_FALSE(sameImage(c.frame(Finger::kLeft).image, d.frame(Finger::kLeft).image));
}

TEST(TactileGripperTest, ABatchOnThreadsEqualsGrippersAlone) {
  const SensorModel sensor = loadSensorModel(source("config/digit.yaml"));
  const GripperSimConfig scene = loadGripperSimConfig(source("config/scenes/cube.yaml"));
  std::vector<TactileGripperOptions> options(3, woodOptions());
  for (int i = 0; i < 3; ++i) options[i].seed = 10 + i;
  TactileGripperBatch batch(scene, sensor, options, 2);
  std::vector<std::unique_ptr<TactileGripper>> alone;
  for (int i = 0; i < 3; ++i) alone.push_back(std::make_unique<TactileGripper>(scene, sensor, options[i]));
  batch.reset(1, 4, 0.005, 3);
  alone[1]->setVariant(3);
  alone[1]->reset(4, 0.005);
  const std::vector<OpeningCommand> modes = {OpeningCommand::kAbsolute, OpeningCommand::kDelta,
                                             OpeningCommand::kKeep};
  for (int step = 0; step < 6; ++step) {
    const std::vector<double> values = {0.55 + 0.01 * step, 0.005, 0.0};
    batch.step(modes, values, 2);
    alone[0]->sim().setOpening(values[0]);
    alone[1]->sim().addOpening(values[1]);
    for (auto& g : alone) g->step(2);
    for (int i = 0; i < 3; ++i) {
      for (const Finger f : {Finger::kLeft, Finger::kRight}) {
        ASSERT_TRUE(sameImage(batch.gripper(i).frame(f).image, alone[i]->frame(f).image))
            << "gripper " << i << " step " << step;
      }
      ASSERT_EQ(batch.gripper(i).sim().opening(), alone[i]->sim().opening());
    }
  }
  // A bad command moves nothing.
  const std::int64_t ticks = batch.gripper(0).sim().ticks();
  EXPECT_THROW(batch.step(modes, {2.0, 0.0, 0.0}), Error);
  EXPECT_THROW(batch.step(modes, {0.5, 0.0}), Error);
  EXPECT_EQ(batch.gripper(0).sim().ticks(), ticks);
}

/// The message of the Error `call` throws ("" when it throws none).
template <class Call>
std::string errorOf(Call&& call) {
  try {
    call();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(TactileGripperTest, BadOptionsAreRefusedWithTheirRange) {
  const SensorModel sensor = loadSensorModel(source("config/digit.yaml"));
  const GripperSimConfig scene = loadGripperSimConfig(source("config/scenes/cube.yaml"));
  // Each bad option is refused naming itself, its value and what is valid.
  struct Case {
    std::function<void(TactileGripperOptions&)> set;
    std::string expected;
  };
  const Case cases[] = {
      {[](TactileGripperOptions& o) { o.frame_rate_hz = 0.0; },
       "option frame_rate_hz = 0 is out of range; valid: [1, 1000] Hz and <= physics_rate_hz"},
      {[](TactileGripperOptions& o) { o.physics_rate_hz = 50.0; },
       "option physics_rate_hz = 50 is out of range; valid: [100, 100000] Hz"},
      {[](TactileGripperOptions& o) { o.variant = -1; },
       "option variant = -1 is out of range; valid: >= 0"},
      {[](TactileGripperOptions& o) { o.friction = 6.0; },
       "option friction = 6 is out of range; valid: [0, 5], or < 0 for the material's"},
      // Texture depth without a material: nothing to texture.
      {[](TactileGripperOptions& o) { o.beta_mm = 0.1; },
       "option beta_mm = 0.1 is out of range; valid: 0 or < 0 without a material"},
  };
  for (const Case& c : cases) {
    TactileGripperOptions o;
    c.set(o);
    const std::string message = errorOf([&] { TactileGripper(scene, sensor, o); });
    EXPECT_NE(message.find(c.expected), std::string::npos)
        << "expected: " << c.expected << "\ngot: " << message;
  }
  // And the calls: a variant for a gripper without a material, a step of no frames.
  TactileGripper textureless(scene, sensor, TactileGripperOptions());
  std::string message = errorOf([&] { textureless.setVariant(2); });
  EXPECT_NE(message.find("texture variant 2 refused: the gripper has no material"),
            std::string::npos)
      << message;
  message = errorOf([&] { textureless.step(0); });
  EXPECT_NE(message.find("step frames = 0 refused; valid: [1, 100000]"), std::string::npos)
      << message;
}

}  // namespace
}  // namespace norm2tex
