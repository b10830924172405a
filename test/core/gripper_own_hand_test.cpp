// GripperSim on a two-finger hand of your own (scene gripper.hand): TACTO's WSG-50 with two
// DIGITs (test/fixtures/robots/wsg50), measured from its URDF, holding and dropping a cube as
// the built-in gripper does; the built-in gripper given as a hand yaml against the built-in one;
// and the hands GripperSim must refuse, each with its reason.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "norm2tex/common/error.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/gripper_sim.hpp"
#include "norm2tex/sim/hand_sim.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

const std::string kWsg = std::string(NORM2TEX_SOURCE_DIR) + "/test/fixtures/robots/wsg50";
const std::string kHands = std::string(NORM2TEX_SOURCE_DIR) + "/config/hands";

void write(const std::string& path, const std::string& text) {
  std::ofstream file(path);
  file << text;
}

GripperSimConfig handScene(const std::string& hand_yaml) {
  GripperSimConfig config;
  config.gripper.hand_yaml = hand_yaml;
  setGelFromSensor(makeDigitSensorModel(), config);
  return config;
}

// The WSG-50 hand yaml with `replace` put in place of `original` (a line of it).
std::string wsgVariant(const std::string& name, const std::string& original,
                       const std::string& replacement) {
  std::ifstream in(kWsg + "/wsg50_hand.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t at = text.find(original);
  EXPECT_NE(at, std::string::npos) << original;
  if (at != std::string::npos) text.replace(at, original.size(), replacement);
  // In a temporary folder, its URDF and meshes the fixture's.
  for (const auto& [relative, absolute] :
       {std::pair<std::string, std::string>{"urdf: wsg50_digit.urdf",
                                            "urdf: " + kWsg + "/wsg50_digit.urdf"},
        {"{wsg50: .}", "{wsg50: " + kWsg + "}"}}) {
    text.replace(text.find(relative), relative.size(), absolute);
  }
  const std::string path = testing::TempDir() + "/" + name + ".yaml";
  write(path, text);
  return path;
}

std::string errorOf(const GripperSimConfig& config) {
  try {
    GripperSim sim(config);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// The weight the gels carry: their shear forces (on the gel, by the object) along world -z.
double carriedN(const GripperSim& sim) {
  double carried = 0.0;
  for (const Finger finger : {Finger::kLeft, Finger::kRight}) {
    const Eigen::Vector3d shear_world =
        sim.gelInWorld(finger).linear() * sim.contact(finger).shear_force_n;
    carried += -shear_world.z();
  }
  return carried;
}

TEST(GripperOwnHandTest, MeasuresTheWsg50sStrokeAndGripFrameFromItsUrdf) {
  GripperSim sim(handScene(kWsg + "/wsg50_hand.yaml"));
  EXPECT_TRUE(sim.hasOwnHand());
  const GripperOptions& g = sim.config().gripper;
  // gripper.closed puts the gel surfaces together (+-16 mm), open at +-55 mm: 2 x 39 mm.
  EXPECT_NEAR(g.min_gap_m, 0.0, 0.2e-3);
  EXPECT_NEAR(g.max_gap_m, 0.078, 0.2e-3);
  // Its drives (joints.default): 10 N and 20 mm/s per finger, rigid.
  EXPECT_DOUBLE_EQ(g.max_force_n, 10.0);
  EXPECT_DOUBLE_EQ(g.max_speed_m_s, 0.02);
  EXPECT_DOUBLE_EQ(g.stiffness_n_per_m, 0.0);
  // The gels 118 mm above the base at 50 mm; the grip axis horizontal (the fingers' prismatic
  // axis, the base's x), from the right gel to the left.
  const Eigen::Isometry3d grip = sim.gripInWorld();
  EXPECT_NEAR(grip.translation().z(), 0.168, 1e-3);
  EXPECT_NEAR(g.base_height_m, grip.translation().z(), 1e-15);
  EXPECT_NEAR(std::abs(grip.linear().col(1).x()), 1.0, 1e-6);
  EXPECT_GT((sim.gelInWorld(Finger::kLeft).translation() -
             sim.gelInWorld(Finger::kRight).translation()).dot(grip.linear().col(1)), 0.07);
  EXPECT_TRUE(grip.linear().col(2).isApprox(Eigen::Vector3d::UnitZ(), 1e-9));
  EXPECT_NEAR(grip.linear().determinant(), 1.0, 1e-12);
  // Open, the gap is the measured one, and a command arrives where gapForOpening says.
  EXPECT_NEAR(2 * sim.fingerPosition(), sim.gapForOpening(1.0), 1e-9);
  sim.setOpening(0.5);
  sim.step(2000);  // 19.5 mm per finger at 20 mm/s
  EXPECT_NEAR(sim.opening(), 0.5, 1e-6);
  EXPECT_NEAR(2 * sim.fingerPosition(), 0.039, 0.2e-3);
}

TEST(GripperOwnHandTest, Wsg50GraspsHoldsAndDropsACubeAsTheGelLawSays) {
  const GripperSimConfig config = handScene(kWsg + "/wsg50_hand.yaml");
  GripperSim sim(config);
  const EpisodeStart start = sim.reset(3, 0.005);
  EXPECT_EQ(start.episode, 1u);
  EXPECT_DOUBLE_EQ(start.height_offset_m, 0.005);
  for (const Finger finger : {Finger::kLeft, Finger::kRight}) {
    const GelContactState& c = sim.contact(finger);
    ASSERT_TRUE(c.in_contact);
    // The scene's 1 mm asks 12.8 N of each gel (the gel law); the WSG-50's drives give 10 N:
    // the fingers stop where each gel carries that, at the law's depth for 10 N (0.84 mm).
    ASSERT_GT(config.gel_law.force(config.episode.grasp_indentation_m), 10.0);
    EXPECT_NEAR(c.normal_force_n, 10.0, 0.05 * 10.0);
    EXPECT_NEAR(c.penetration_m, config.gel_law.indentation(10.0), 0.02e-3);
    // The cube's centre 5 mm above the gel centre, across the gel: 15 mm - d in front of it.
    EXPECT_NEAR(c.object_in_gel.translation().z(), 0.015 - c.penetration_m, 0.1e-3);
  }
  // Centred between the fingers, 5 mm up in the grip frame.
  const Eigen::Vector3d in_grip = sim.gripInWorld().inverse() * sim.objectInWorld().translation();
  EXPECT_NEAR(in_grip.y(), 0.0, 0.1e-3);
  EXPECT_NEAR(in_grip.z(), 0.005, 0.3e-3);
  // Held: the gels carry its weight and it stays for 2 s.
  const Eigen::Vector3d before = sim.objectInWorld().translation();
  sim.step(2000);
  EXPECT_LT((sim.objectInWorld().translation() - before).norm(), 0.2e-3);
  EXPECT_NEAR(carriedN(sim), config.object.mass_kg * 9.81, 0.02 * config.object.mass_kg * 9.81);
  EXPECT_FALSE(sim.dropped());
  // Opened, it falls below the pads and the latch says so.
  sim.setOpening(1.0);
  int ticks = 0;
  while (!sim.dropped() && ticks < 3000) {
    sim.step(1);
    ++ticks;
  }
  EXPECT_TRUE(sim.dropped());
  EXPECT_FALSE(sim.contact(Finger::kLeft).in_contact);
  // A new episode clears it, with the same seed the same grasp.
  GripperSim again(config);
  const EpisodeStart start_again = again.reset(3, 0.005);
  EXPECT_EQ(start_again.grasp_opening, start.grasp_opening);
}

TEST(GripperOwnHandTest, UpsideDownWsg50KeepsTheGripFramesUpWithTheWorld) {
  // wsg50_top_grasp.yaml: the hand rolled half a turn, its fingers pointing at the floor.
  GripperSimConfig config = handScene(kWsg + "/wsg50_top_grasp.yaml");
  config.episode.height_offset_low_m = 0.0;
  config.episode.height_offset_high_m = 0.0;
  GripperSim sim(config);
  const Eigen::Isometry3d grip = sim.gripInWorld();
  EXPECT_TRUE(grip.linear().col(2).isApprox(Eigen::Vector3d::UnitZ(), 1e-9));
  EXPECT_NEAR(grip.translation().z(), 0.015, 1e-3);  // where a 30 mm cube on the floor is
  // The left finger is still at +y of the grip frame: its gel faces -y.
  EXPECT_GT(sim.gelInWorld(Finger::kLeft).linear().col(2).dot(-grip.linear().col(1)),
            std::cos(1.0 * M_PI / 180.0));
  sim.reset(1, 0.0);
  EXPECT_TRUE(sim.contact(Finger::kLeft).in_contact);
  EXPECT_TRUE(sim.contact(Finger::kRight).in_contact);
}

TEST(GripperOwnHandTest, BuiltInGripperAsAHandYamlHoldsTheCubeWhereTheBuiltInOneDoes) {
  // config/hands/parallel_gripper.yaml is the built-in gripper; its URDF's drive (70 N on both
  // fingers, 20 mm/s) is the default scene's (35 N per gel): the same grasp to within the
  // rounding of its yaml's quarter-turn mounts.
  GripperSimConfig builtin_config;
  setGelFromSensor(makeDigitSensorModel(), builtin_config);
  GripperSim builtin(builtin_config);
  GripperSim as_hand(handScene(kHands + "/parallel_gripper.yaml"));
  const GripperOptions& g = as_hand.config().gripper;
  EXPECT_NEAR(g.min_gap_m, builtin.config().gripper.min_gap_m, 1e-12);
  EXPECT_NEAR(g.max_gap_m, builtin.config().gripper.max_gap_m, 1e-12);
  EXPECT_NEAR(g.base_height_m, builtin.config().gripper.base_height_m, 1e-12);
  EXPECT_DOUBLE_EQ(g.max_force_n, builtin.config().gripper.max_force_n);  // one drive, 2 fingers
  builtin.reset(5, 0.004);
  as_hand.reset(5, 0.004);
  builtin.step(500);
  as_hand.step(500);
  EXPECT_LT((builtin.objectInWorld().translation() - as_hand.objectInWorld().translation()).norm(),
            1e-6);
  EXPECT_NEAR(builtin.fingerPosition(), as_hand.fingerPosition(), 1e-6);
  for (const Finger finger : {Finger::kLeft, Finger::kRight}) {
    EXPECT_NEAR(builtin.contact(finger).normal_force_n, as_hand.contact(finger).normal_force_n,
                1e-3 * builtin.contact(finger).normal_force_n);
    EXPECT_TRUE(builtin.gelInWorld(finger).isApprox(as_hand.gelInWorld(finger), 1e-9));
  }
}

TEST(GripperOwnHandTest, HandsThatAreNotParallelGrippersAreRefusedWithTheirReason) {
  const std::string one_sensor = wsgVariant(
      "test_one_sensor", "  - name: digit_right\n    link: finger_right_tip\n", "");
  EXPECT_NE(errorOf(handScene(one_sensor)).find("two DIGITs"), std::string::npos)
      << errorOf(handScene(one_sensor));
  const std::string no_gripper = wsgVariant(
      "test_no_gripper",
      "gripper:\n  joints: [base_joint_gripper_left, base_joint_gripper_right]\n"
      "  closed: [-0.016, 0.016]   # the gel surfaces meet\n  open: [-0.055, 0.055]\n",
      "");
  EXPECT_NE(errorOf(handScene(no_gripper)).find("no gripper.joints"), std::string::npos)
      << errorOf(handScene(no_gripper));
  // The right DIGIT turned a quarter about its camera axis... and then away from the left one.
  const std::string turned = wsgVariant("test_turned", "    link: finger_right_tip\n",
                                        "    link: finger_right_tip\n"
                                        "    gel: [0.022, 0, 0.015, 0, 0, 1.5707963267948966]\n");
  EXPECT_NE(errorOf(handScene(turned)).find("do not face each other"), std::string::npos)
      << errorOf(handScene(turned));
  // Only the left finger closes: the gels' midpoint moves.
  const std::string lopsided = wsgVariant("test_lopsided", "  closed: [-0.016, 0.016]",
                                          "  closed: [-0.016, 0.055]");
  EXPECT_NE(errorOf(handScene(lopsided)).find("centred"), std::string::npos)
      << errorOf(handScene(lopsided));
  // Closing past the point where the gels meet.
  const std::string overlap = wsgVariant("test_overlap", "  closed: [-0.016, 0.016]",
                                         "  closed: [-0.012, 0.012]");
  EXPECT_NE(errorOf(handScene(overlap)).find("overlap by 8"), std::string::npos)
      << errorOf(handScene(overlap));
  // Fingers pointing sideways, the grip axis (the base's x) vertical.
  const std::string vertical =
      wsgVariant("test_vertical", "  base_pose: [0, 0, 0.05, 0, 0, 0]",
                 "  base_pose: [0, 0, 0.3, 0, 1.5707963267948966, 0]");
  EXPECT_NE(errorOf(handScene(vertical)).find("degrees from vertical"), std::string::npos)
      << errorOf(handScene(vertical));
  // The Allegro's fingers turn on revolute joints.
  const std::string allegro = std::string(NORM2TEX_SOURCE_DIR) +
                              "/test/fixtures/robots/allegro_hand_description/allegro_hand.yaml";
  const std::string allegro_error = errorOf(handScene(allegro));
  EXPECT_TRUE(allegro_error.find("two DIGITs") != std::string::npos ||
              allegro_error.find("not prismatic") != std::string::npos)
      << allegro_error;
  // A hand that is not there.
  EXPECT_NE(errorOf(handScene(kWsg + "/no_such_hand.yaml")).find("no_such_hand.yaml"),
            std::string::npos);
  for (const std::string& path : {one_sensor, no_gripper, turned, lopsided, overlap, vertical}) {
    std::remove(path.c_str());
  }
}

TEST(GripperOwnHandTest, SceneYamlNamesTheHandBesideItAndRefusesTheBuiltInsKeysWithIt) {
  const std::string dir = testing::TempDir();
  const std::string scene = dir + "/own_hand_scene.yaml";
  // Relative to the scene yaml's folder.
  const std::string relative =
      std::filesystem::relative(kWsg + "/wsg50_hand.yaml", dir).string();
  write(scene, "gripper:\n  hand: " + relative + "\nobject:\n  mesh: box:30x30x30\n");
  const GripperSimConfig config = loadGripperSimConfig(scene);
  EXPECT_EQ(std::filesystem::canonical(config.gripper.hand_yaml),
            std::filesystem::canonical(kWsg + "/wsg50_hand.yaml"));
  write(scene, "gripper:\n  hand: " + relative + "\n  max_gap_mm: 80\n");
  try {
    loadGripperSimConfig(scene);
    ADD_FAILURE() << "a hand with gripper.max_gap_mm was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("gripper.max_gap_mm is given with gripper.hand"),
              std::string::npos)
        << e.what();
  }
  write(scene, "gripper:\n  hand: ''\n");
  EXPECT_THROW(loadGripperSimConfig(scene), Error);
}

}  // namespace
}  // namespace norm2tex
