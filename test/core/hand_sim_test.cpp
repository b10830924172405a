// Hands from URDF: the loader against real, messy descriptions (TACTO's WSG-50 and Allegro with
// DIGITs, test/fixtures/robots) and built ones, and HandSim's drives and grasps against the
// gel law.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/gripper_sim.hpp"
#include "norm2tex/sim/hand_config.hpp"
#include "norm2tex/sim/hand_description.hpp"
#include "norm2tex/sim/hand_sim.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

const std::string kRobots = std::string(NORM2TEX_SOURCE_DIR) + "/test/fixtures/robots";
const std::string kWsgYaml = kRobots + "/wsg50/wsg50_hand.yaml";
const std::string kAllegroYaml = kRobots + "/allegro_hand_description/allegro_hand.yaml";

void write(const std::string& path, const std::string& text) {
  std::ofstream file(path);
  file << text;
}

int countContaining(const std::vector<std::string>& lines, const std::string& part) {
  int n = 0;
  for (const std::string& line : lines) n += line.find(part) != std::string::npos;
  return n;
}

HandSimConfig wsgConfig(const std::string& object = "box:30x30x30") {
  HandSimConfig config;
  config.hand = loadHandConfig(kWsgYaml);
  config.object.mesh = object;
  // Between the gels: their centres are 0.118 m above the base's 0.05.
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 0.168));
  return config;
}

// ---------------------------------------------------------------- loading real descriptions --

TEST(HandDescription, LoadsTactosWsg50AsItIsWithAWordOnWhatItChanged) {
  PackagePaths paths;
  paths.explicit_paths["wsg50"] = kRobots + "/wsg50";
  paths.use_ros_package_path = false;
  const HandDescription hand = loadHandDescription(kRobots + "/wsg50/wsg50_digit.urdf", paths);
  EXPECT_EQ(hand.name, "wsg50_digit");
  ASSERT_EQ(hand.links.size(), 7u);
  EXPECT_EQ(hand.links[0].name, "gripper_base_link");
  // Parents before children.
  for (const HandJoint& joint : hand.joints) EXPECT_LT(joint.parent_link, joint.child_link);
  const int left = hand.jointIndex("base_joint_gripper_left");
  ASSERT_GE(left, 0);
  EXPECT_EQ(hand.joints[left].type, HandJoint::Type::kPrismatic);
  // The first of its two <limit> tags, as urdfdom reads it, and a warning naming the second.
  EXPECT_DOUBLE_EQ(hand.joints[left].lower, -0.055);
  EXPECT_DOUBLE_EQ(hand.joints[left].upper, -0.0027);
  EXPECT_DOUBLE_EQ(hand.joints[left].effort, 1.0);
  EXPECT_EQ(countContaining(hand.warnings, "has a second <limit>"), 2);
  EXPECT_EQ(countContaining(hand.warnings, "joint 'base_joint_gripper_left'"), 1);
  // The right finger's joint turns its frame by pi: its axis is -x.
  const int right = hand.jointIndex("base_joint_gripper_right");
  EXPECT_NEAR(hand.joints[right].axis.x(), -1.0, 1e-12);
  // Meshes in mm with scale 0.001 arrive in metres: the finger mount is 30 x 23 x 21 mm.
  const HandLink& finger = hand.links[hand.linkIndex("finger_left")];
  ASSERT_EQ(finger.collisions.size(), 1u);
  Eigen::AlignedBox3d bounds;
  for (const Eigen::Vector3d& v : finger.collisions[0].mesh_vertices) bounds.extend(v);
  EXPECT_NEAR(bounds.sizes().maxCoeff(), 0.030, 1e-4);
  // 1 kg m^2 on every link: replaced by its collision box's inertia, one warning per link.
  EXPECT_EQ(countContaining(hand.warnings, "inertia"), 7);
  for (const HandLink& link : hand.links) {
    EXPECT_TRUE(link.inertia_replaced) << link.name;
    EXPECT_LT(link.inertia.maxCoeff(), 1e-2) << link.name;
  }
  EXPECT_NE(hand.urdf_xml.find("<robot name=\"wsg50_digit\">"), std::string::npos);
  // For /robot_description: every mesh as an absolute file:// URI, nothing else changed.
  EXPECT_EQ(hand.resolved_urdf_xml.find("package://"), std::string::npos);
  EXPECT_NE(
      hand.resolved_urdf_xml.find("filename=\"file://" + kRobots + "/wsg50/DIGIT-WSG-50-V1.STL\""),
      std::string::npos);
  EXPECT_NE(hand.resolved_urdf_xml.find("<limit lower=\"-0.055\" upper=\"-0.0027\""),
            std::string::npos);
}

TEST(HandDescription, APlausibleInertiaIsKept) {
  test::ScratchDirectory dir;
  // A 0.1 kg, 20 x 20 x 40 mm box with its own solid inertia.
  write(dir.path("box.urdf"), R"(<robot name="r"><link name="a">
    <inertial><mass value="0.1"/><inertia ixx="1.667e-5" iyy="1.667e-5" izz="6.667e-6" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.02 0.02 0.04"/></geometry></collision></link></robot>)");
  const HandDescription hand = loadHandDescription(dir.path("box.urdf"), PackagePaths{});
  EXPECT_FALSE(hand.links[0].inertia_replaced);
  EXPECT_TRUE(hand.warnings.empty());
  EXPECT_DOUBLE_EQ(hand.links[0].inertia(0, 0), 1.667e-5);
}

TEST(HandDescription, LoadsTheAllegroWithSixteenRevoluteJointsAndFourDigitLinks) {
  PackagePaths paths;
  paths.explicit_paths["allegro_hand_description"] = kRobots + "/allegro_hand_description";
  const HandDescription hand = loadHandDescription(
      kRobots + "/allegro_hand_description/allegro_hand_description_left_digit.urdf", paths);
  int revolute = 0;
  for (const HandJoint& joint : hand.joints) revolute += joint.type == HandJoint::Type::kRevolute;
  EXPECT_EQ(revolute, 16);
  for (const std::string tip : {"link_3.0_tip", "link_7.0_tip", "link_11.0_tip", "link_15.0_tip"}) {
    EXPECT_GE(hand.linkIndex(tip), 0) << tip;
  }
  // Its joints give no effort or velocity: the hand yaml must.
  EXPECT_EQ(hand.joints[hand.jointIndex("joint_1.0")].effort, 0.0);
}

TEST(HandDescription, PackageUrisResolveThroughPackagePathsAndRosPackagePath) {
  const std::string urdf = kRobots + "/wsg50/wsg50_digit.urdf";
  // Through ROS_PACKAGE_PATH: a folder holding a folder named like the package.
  const char* saved = std::getenv("ROS_PACKAGE_PATH");
  const std::string saved_value = saved ? saved : "";
  setenv("ROS_PACKAGE_PATH", ("/nonexistent:" + kRobots).c_str(), 1);
  const HandDescription hand = loadHandDescription(urdf, PackagePaths{});
  EXPECT_EQ(hand.links[0].collisions[0].mesh_path, kRobots + "/wsg50/WSG50_110.stl");
  // Explicit paths are relative to the URDF's folder, and win.
  PackagePaths paths;
  paths.explicit_paths["wsg50"] = ".";
  EXPECT_EQ(resolveUri("package://wsg50/digit.STL", kRobots + "/wsg50", paths),
            kRobots + "/wsg50/digit.STL");
  // Not found: the package and every place looked in.
  setenv("ROS_PACKAGE_PATH", "/nonexistent", 1);
  test::expectError([&] { loadHandDescription(urdf, PackagePaths{}); },
                    {"package://wsg50/WSG50_110.stl", "package 'wsg50' not found",
                     "/nonexistent/wsg50", "package_paths"});
  if (saved) {
    setenv("ROS_PACKAGE_PATH", saved_value.c_str(), 1);
  } else {
    unsetenv("ROS_PACKAGE_PATH");
  }
}

// A whole robot: a two-link arm with a parallel hand at its tip, one finger mimicking the
// other, built from primitives.
const char* kArmWithHand = R"(<?xml version="1.0"?>
<robot name="arm_with_hand">
  <link name="world_base"><collision><geometry><cylinder radius="0.05" length="0.1"/></geometry></collision></link>
  <link name="upper_arm"><collision><geometry><box size="0.05 0.05 0.3"/></geometry></collision></link>
  <link name="palm"><collision><geometry><box size="0.08 0.04 0.02"/></geometry></collision></link>
  <link name="finger_a"><collision><origin xyz="0 0 0.03"/><geometry><box size="0.01 0.02 0.06"/></geometry></collision></link>
  <link name="finger_b"><collision><origin xyz="0 0 0.03"/><geometry><box size="0.01 0.02 0.06"/></geometry></collision></link>
  <joint name="shoulder" type="revolute"><parent link="world_base"/><child link="upper_arm"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="50" velocity="1"/></joint>
  <joint name="wrist" type="fixed"><parent link="upper_arm"/><child link="palm"/><origin xyz="0 0 0.3"/></joint>
  <joint name="finger_a_joint" type="prismatic"><parent link="palm"/><child link="finger_a"/>
    <origin xyz="-0.04 0 0.01"/><axis xyz="1 0 0"/><limit lower="0" upper="0.035" effort="20" velocity="0.05"/></joint>
  <joint name="finger_b_joint" type="prismatic"><parent link="palm"/><child link="finger_b"/>
    <origin xyz="0.04 0 0.01"/><axis xyz="1 0 0"/><limit lower="-0.035" upper="0" effort="20" velocity="0.05"/>
    <mimic joint="finger_a_joint" multiplier="-1" offset="0"/></joint>
  <transmission name="t"><joint name="finger_a_joint"/></transmission>
  <gazebo reference="palm"><material>Gazebo/Grey</material></gazebo>
</robot>)";

TEST(HandDescription, RootLinkKeepsOnlyTheHandOfAWholeRobot) {
  test::ScratchDirectory dir;
  write(dir.path("arm.urdf"), kArmWithHand);
  const HandDescription whole = loadHandDescription(dir.path("arm.urdf"), PackagePaths{});
  EXPECT_EQ(whole.links.size(), 5u);
  const HandDescription hand = loadHandDescription(dir.path("arm.urdf"), PackagePaths{}, "palm");
  ASSERT_EQ(hand.links.size(), 3u);
  EXPECT_EQ(hand.links[0].name, "palm");
  EXPECT_EQ(hand.jointIndex("shoulder"), -1);
  EXPECT_EQ(countContaining(hand.warnings, "2 link(s) outside root_link 'palm'"), 1);
  const HandJoint& b = hand.joints[hand.jointIndex("finger_b_joint")];
  EXPECT_EQ(b.mimic_master, hand.jointIndex("finger_a_joint"));
  EXPECT_DOUBLE_EQ(b.mimic_multiplier, -1.0);
  test::expectError(
      [&] { loadHandDescription(dir.path("arm.urdf"), PackagePaths{}, "wrist_link"); },
      {"root_link 'wrist_link'", "not a link"});
}

TEST(HandDescription, BadDescriptionsAreClearErrors) {
  test::ScratchDirectory dir;
  test::expectError([&] { loadHandDescription(dir.path("none.urdf"), PackagePaths{}); },
                    {"cannot read", "none.urdf"});
  write(dir.path("broken.urdf"), "<robot name=\"r\">\n<link name=\"a\">\n</robot>\n");
  test::expectError([&] { loadHandDescription(dir.path("broken.urdf"), PackagePaths{}); },
                    {"broken.urdf:", "not well-formed XML"});
  write(dir.path("nolink.urdf"), "<robot name=\"r\"></robot>");
  test::expectError([&] { loadHandDescription(dir.path("nolink.urdf"), PackagePaths{}); },
                    {"nolink.urdf", "invalid URDF"});
  std::string mimic = kArmWithHand;
  const std::string master = "joint=\"finger_a_joint\" multiplier";
  mimic.replace(mimic.find(master), master.size(), "joint=\"finger_c_joint\" multiplier");
  write(dir.path("mimic.urdf"), mimic);
  test::expectError([&] { loadHandDescription(dir.path("mimic.urdf"), PackagePaths{}); },
                    {"finger_b_joint", "mimics 'finger_c_joint'", "does not exist"});
  write(dir.path("mesh.urdf"), R"(<robot name="r"><link name="a"><collision><geometry>
    <mesh filename="missing.stl"/></geometry></collision></link></robot>)");
  test::expectError([&] { loadHandDescription(dir.path("mesh.urdf"), PackagePaths{}); },
                    {"link 'a'", "missing.stl", "does not exist"});
  write(dir.path("floating.urdf"), R"(<robot name="r"><link name="a"/><link name="b"/>
    <joint name="free" type="floating"><parent link="a"/><child link="b"/></joint></robot>)");
  test::expectError([&] { loadHandDescription(dir.path("floating.urdf"), PackagePaths{}); },
                    {"joint 'free' is floating"});
}

TEST(HandConfig, ReadsTheYamlAndRefusesWhatIsNotThere) {
  const HandConfig wsg = loadHandConfig(kWsgYaml);
  EXPECT_EQ(wsg.urdf_path, kRobots + "/wsg50/wsg50_digit.urdf");
  ASSERT_EQ(wsg.sensors.size(), 2u);
  EXPECT_EQ(wsg.sensors[1].link, "finger_right_tip");
  EXPECT_FALSE(wsg.sensors[0].gel_given);
  EXPECT_DOUBLE_EQ(wsg.default_drive.effort, 10.0);
  EXPECT_EQ(wsg.package_paths.explicit_paths.at("wsg50"), kRobots + "/wsg50");
  EXPECT_NEAR(wsg.base_pose.translation().z(), 0.05, 1e-15);

  test::ScratchDirectory dir;
  const std::string urdf = kRobots + "/wsg50/wsg50_digit.urdf";
  write(dir.path("typo.yaml"),
        "hand: {urdf: " + urdf + ", base_pos: [0,0,0,0,0,0]}\nsensors: [{name: a, link: b}]\n");
  test::expectError([&] { loadHandConfig(dir.path("typo.yaml")); },
                    {"typo.yaml", "hand.base_pos is not a known key", "base_pose"});
  write(dir.path("nosensors.yaml"), "hand: {urdf: " + urdf + "}\n");
  test::expectError([&] { loadHandConfig(dir.path("nosensors.yaml")); }, {"sensors is required"});
  write(dir.path("gel.yaml"),
        "hand: {urdf: " + urdf + "}\nsensors: [{name: a, link: b, gel: [0, 0, 0]}]\n");
  test::expectError([&] { loadHandConfig(dir.path("gel.yaml")); },
                    {"sensors[0].gel needs 6 numbers"});
  write(dir.path("name.yaml"), "hand: {urdf: " + urdf + "}\nsensors: [{name: a/b, link: b}]\n");
  test::expectError([&] { loadHandConfig(dir.path("name.yaml")); },
                    {"'a/b' is not a valid ROS name"});
  write(dir.path("drive.yaml"),
        "hand: {urdf: " + urdf + "}\nsensors: [{name: a, link: b}]\njoints: {j: {effort: -1}}\n");
  test::expectError([&] { loadHandConfig(dir.path("drive.yaml")); },
                    {"joints.j.effort", "valid: > 0"});
}

TEST(HandConfig, ReadsTextAsItReadsFiles) {
  // The built-in gripper's way in: yaml and URDF text, relative paths against a folder given.
  const std::string hands = std::string(NORM2TEX_SOURCE_DIR) + "/config/hands";
  const HandConfig file = loadHandConfig(hands + "/parallel_gripper.yaml");
  std::ifstream yaml_file(hands + "/parallel_gripper.yaml");
  const std::string yaml((std::istreambuf_iterator<char>(yaml_file)), {});
  const HandConfig text = parseHandConfig(yaml, "gripper text", hands);
  EXPECT_EQ(text.urdf_path, file.urdf_path);
  ASSERT_EQ(text.sensors.size(), 2u);
  EXPECT_TRUE(text.sensors[1].digit_in_link.matrix() == file.sensors[1].digit_in_link.matrix());
  test::expectError([] { parseHandConfig("hand: [", "broken text", "."); }, {"broken text"});
  std::ifstream urdf_file(file.urdf_path);
  const std::string urdf((std::istreambuf_iterator<char>(urdf_file)), {});
  const HandDescription description = parseHandDescription(urdf, "gripper urdf", hands, {});
  EXPECT_EQ(description.joints.size(), 2u);
  EXPECT_EQ(description.joints[description.jointIndex("finger_right_joint")].mimic_master,
            description.jointIndex("finger_left_joint"));
  test::expectError([] { parseHandDescription("<robot", "broken urdf", ".", {}); },
                    {"broken urdf:1", "not well-formed XML"});
}

TEST(HandSim, ResetsWithTheJointsWhereItIsTold) {
  // How GripperSim seats each episode: the fingers at the seat, the mimic finger with them.
  GripperSimConfig scene;
  setGelFromSensor(makeDigitSensorModel(), scene);
  HandSimConfig config = makeHandSimConfig(
      std::string(NORM2TEX_SOURCE_DIR) + "/config/hands/parallel_gripper.yaml", scene);
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 0.2));
  HandSim sim(config);
  const Eigen::Isometry3d pose = config.object_pose;
  const int left = sim.description().jointIndex("finger_left_joint");
  sim.reset(pose, {"finger_left_joint"}, {0.017});
  EXPECT_EQ(sim.jointPosition("finger_right_joint"), 0.017);
  EXPECT_EQ(sim.driveJointPositions()[left], 0.017);
  EXPECT_EQ(sim.jointTargets()[left], 0.017);
  EXPECT_FALSE(sim.objectReachesIntoGel(0) || sim.objectReachesIntoGel(1));
  sim.reset(pose, {"finger_left_joint"}, {0.014});  // 1 mm into each side of the 30 mm cube
  EXPECT_TRUE(sim.objectReachesIntoGel(0) && sim.objectReachesIntoGel(1));
  sim.reset(pose, {"finger_left_joint"}, {0.5});
  EXPECT_EQ(sim.jointPosition("finger_left_joint"), 0.02);  // clamped to the URDF's limit
  test::expectError([&] { sim.reset(pose, {"finger_right_joint"}, {0.01}); },
                    {"'finger_right_joint' mimics 'finger_left_joint'"});
  test::expectError([&] { sim.reset(pose, {"finger"}, {0.01}); }, {"unknown joint 'finger'"});
  test::expectError([&] { sim.reset(pose, {"finger_left_joint"}, {NAN}); }, {"not finite"});
  test::expectError([&] { sim.reset(pose, {"finger_left_joint"}, {}); },
                    {"1 names but 0 positions"});
  EXPECT_EQ(sim.jointPosition("finger_left_joint"), 0.02);  // nothing changed
  sim.step(10);
  sim.reset();
  EXPECT_EQ(sim.jointPosition("finger_left_joint"), 0.02);  // the yaml's initial position
}

TEST(HandSim, RefusesASensorOnALinkNotInTheHandAndDrivesWithoutLimits) {
  HandSimConfig config = wsgConfig();
  config.hand.sensors[1].link = "finger_right_tipp";
  test::expectError(
      [&] { HandSim sim(config); },
      {"sensor 'digit_right'", "'finger_right_tipp' is not in the hand", "finger_right_tip"});
  HandSimConfig allegro;
  allegro.hand = loadHandConfig(kAllegroYaml);
  allegro.hand.default_drive = JointDriveOptions{};
  test::expectError([&] { HandSim sim(allegro); },
                    {"joint 'joint_", "has no effort limit (the URDF gives 0)", "joints.default"});
}

// ---------------------------------------------------------------------------- the gel mount --

TEST(HandSim, TactosDigitConventionPutsEachGelOnItsMeshFacingTheOtherFinger) {
  HandSim sim(wsgConfig());
  ASSERT_EQ(sim.sensorCount(), 2);
  for (int s = 0; s < 2; ++s) {
    // TACTO's gel centre (0.022 m along the camera axis) lies 1.9 mm in front of digit.STL's
    // flat front (x = 0.0201 m): within the gel's thickness, so no warning.
    EXPECT_NEAR(sim.sensorCheck(s).gel_in_front_of_mesh_m, 0.022 - 0.02014, 0.1e-3);
  }
  EXPECT_EQ(countContaining(sim.warnings(), "in front of link"), 0);
  // The gels face each other along the grip axis, image down is world -z (the fingers point up).
  const Eigen::Isometry3d left = sim.gelInWorld(0), right = sim.gelInWorld(1);
  EXPECT_NEAR(left.linear().col(2).dot(Eigen::Vector3d::UnitX()), 1.0, 1e-9);
  EXPECT_NEAR(right.linear().col(2).dot(Eigen::Vector3d::UnitX()), -1.0, 1e-5);
  EXPECT_NEAR(left.linear().col(1).dot(-Eigen::Vector3d::UnitZ()), 1.0, 1e-9);
  // At q = -+0.040 each gel surface is 24 mm from the centre: q + 0.016 (the tip's 6 mm and the
  // gel's 22 mm), 0.118 m above the base at 0.05.
  EXPECT_NEAR(left.translation().x(), -0.024, 1e-9);
  EXPECT_NEAR(right.translation().x(), 0.024, 1e-5);
  EXPECT_NEAR(left.translation().z(), 0.168, 1e-9);
  // A gel pose that floats off its link is reported.
  HandSimConfig config = wsgConfig();
  config.hand.sensors[0].digit_in_link = Eigen::Isometry3d(Eigen::Translation3d(0.03, 0.0, 0.015));
  HandSim off(config);
  EXPECT_EQ(countContaining(off.warnings(), "sensor 'digit_left': the gel surface lies"), 1);
}

TEST(HandSim, AnObjectBehindAGelIsNotPressedIntoIt) {
  // A cube far behind the right gel, on its axis at the pads' height, weightless: the gel's
  // pad outline covers it, but it is on the sensor's other side. Nothing touches it.
  HandSimConfig config = wsgConfig();
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.3, 0.0, 0.168));
  HandSim sim(config);
  sim.resetObject(config.object_pose, false);
  sim.step(500);
  EXPECT_FALSE(sim.contact(0).in_contact || sim.contact(1).in_contact);
  EXPECT_LT((sim.objectInWorld().translation() - config.object_pose.translation()).norm(), 1e-6);
  // Just behind the surface (a press) it is pushed out, as a gel does.
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.024 - 0.015 + 0.0005, 0.0, 0.168));
  HandSim pressed(config);
  pressed.resetObject(config.object_pose, false);
  pressed.step(1);
  EXPECT_TRUE(pressed.contact(1).in_contact);
  EXPECT_GT(pressed.contact(1).penetration_m, 0.0003);  // pushed back out, from 0.5 mm
  EXPECT_LT(pressed.contact(1).penetration_m, 0.0005);
}

// ---------------------------------------------------------------- drives without contact --

TEST(HandSim, TrajectoriesEndOnTheirTargetAndLimitsClamp) {
  HandSimConfig config = wsgConfig();
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.5, 0.0, 0.015));  // out of reach
  HandSim sim(config);
  JointTrajectoryCommand t;
  t.joint_names = {"base_joint_gripper_left", "base_joint_gripper_right"};
  t.times_s = {0.5, 1.0};
  t.positions = {{-0.045, 0.035}, {-0.030, 0.050}};
  EXPECT_TRUE(sim.setTrajectory(t).empty());
  // Halfway through the first segment the target is halfway from the start.
  sim.step(250);
  EXPECT_NEAR(sim.jointTargets()[sim.description().jointIndex("base_joint_gripper_left")], -0.0425,
              1e-9);
  sim.step(1250);
  EXPECT_NEAR(sim.jointPosition("base_joint_gripper_left"), -0.030, 1e-7);
  EXPECT_NEAR(sim.jointPosition("base_joint_gripper_right"), 0.050, 1e-7);
  // The velocity limit: 20 mm/s, so 10 mm take 0.5 s.
  sim.setJointTargets({"base_joint_gripper_left"}, {-0.040});
  sim.step(250);
  EXPECT_NEAR(sim.jointPosition("base_joint_gripper_left"), -0.035, 1e-7);
  // Beyond the URDF's limits: clamped, named.
  const auto clamped = sim.setJointTargets({"base_joint_gripper_left"}, {-0.2});
  ASSERT_EQ(clamped.size(), 1u);
  EXPECT_EQ(clamped[0], "base_joint_gripper_left");
  EXPECT_DOUBLE_EQ(sim.jointTargets()[sim.description().jointIndex("base_joint_gripper_left")],
                   -0.055);
  // Refused, with the reason, nothing changed.
  test::expectError([&] { sim.setJointTargets({"guide_joint_finger_left"}, {0.0}); }, {"is fixed"});
  test::expectError([&] { sim.setJointTargets({"thumb"}, {0.0}); },
                    {"unknown joint 'thumb'", "base_joint_gripper_left"});
  test::expectError([&] { sim.setJointTargets({"base_joint_gripper_left"}, {NAN}); },
                    {"not finite"});
  t.times_s = {0.5, 0.5};
  test::expectError([&] { sim.setTrajectory(t); }, {"point 1", "not after the previous point"});
  EXPECT_DOUBLE_EQ(sim.jointTargets()[sim.description().jointIndex("base_joint_gripper_left")],
                   -0.055);
}

TEST(HandSim, AllegroJointsTrackWithinAHalfDegree) {
  HandSimConfig config;
  config.hand = loadHandConfig(kAllegroYaml);
  config.object.mesh = "sphere:10";
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.5, 0.0, 0.01));  // out of reach
  HandSim sim(config);
  EXPECT_EQ(sim.sensorCount(), 4);
  EXPECT_EQ(sim.actuatedJoints().size(), 16u);
  JointTrajectoryCommand t;
  t.joint_names = {"joint_1.0", "joint_2.0", "joint_13.0"};
  t.times_s = {0.4};
  t.positions = {{0.8, 0.6, 0.5}};
  sim.setTrajectory(t);
  sim.step(600);
  EXPECT_NEAR(sim.jointPosition("joint_1.0"), 0.8, 0.5 * M_PI / 180);
  EXPECT_NEAR(sim.jointPosition("joint_2.0"), 0.6, 0.5 * M_PI / 180);
  EXPECT_NEAR(sim.jointPosition("joint_13.0"), 0.5, 0.5 * M_PI / 180);
  // Forward kinematics: the index fingertip's gel moved with its joints; the others did not.
  HandSim still(config);
  EXPECT_GT((sim.gelInWorld(0).translation() - still.gelInWorld(0).translation()).norm(), 0.02);
  EXPECT_LT((sim.gelInWorld(1).translation() - still.gelInWorld(1).translation()).norm(), 1e-12);
}

TEST(HandSim, MimicJointsFollowTheirMaster) {
  test::ScratchDirectory dir;
  write(dir.path("arm.urdf"), kArmWithHand);
  write(dir.path("hand.yaml"),
        "hand: {urdf: arm.urdf, root_link: palm, base_pose: [0, 0, 0.3, 0, 0, 0]}\n"
        "sensors: [{name: digit_a, link: finger_a, gel: [0.005, 0, 0.03, 0, 0, 0]}]\n");
  HandSimConfig config;
  config.hand = loadHandConfig(dir.path("hand.yaml"));
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.5, 0.0, 0.015));
  HandSim sim(config);
  EXPECT_EQ(sim.actuatedJoints(), std::vector<std::string>{"finger_a_joint"});
  test::expectError([&] { sim.setJointTargets({"finger_b_joint"}, {0.0}); },
                    {"mimics 'finger_a_joint'"});
  sim.setJointTargets({"finger_a_joint"}, {0.02});
  sim.step(500);
  EXPECT_NEAR(sim.jointPosition("finger_a_joint"), 0.02, 1e-9);
  EXPECT_NEAR(sim.jointPosition("finger_b_joint"), -0.02, 1e-9);
  // The fingers are 80 - 2 x 20 = 40 mm apart.
  const HandDescription& d = sim.description();
  EXPECT_NEAR((sim.linkInWorld(d.linkIndex("finger_b")).translation() -
               sim.linkInWorld(d.linkIndex("finger_a")).translation())
                  .norm(),
              0.040, 1e-9);
}

// -------------------------------------------------------------------------------- grasps --

struct Grasp {
  Eigen::Isometry3d held;
  double left_mm, right_mm;
};

// Closes the WSG-50 on the object without gravity (each drive's effort set by
// wsgGraspConfig), then lets gravity act.
Grasp graspWithTheWsg(HandSim& sim) {
  sim.resetObject(sim.config().object_pose, false);
  sim.setOpening(0.0);
  sim.step(1500);
  sim.setObjectGravity(true);
  sim.step(500);
  return {sim.objectInWorld(), sim.contact(0).penetration_m * 1e3,
          sim.contact(1).penetration_m * 1e3};
}

HandSimConfig wsgGraspConfig(const std::string& object, double depth_m) {
  HandSimConfig config = wsgConfig(object);
  config.hand.default_drive.effort = config.gel_law.force(depth_m);
  return config;
}

// Held 10 s without moving, then opened: the object leaves both gels and falls onto the WSG's
// body (its top is 72.5 mm above the base at 50 mm).
void expectHeldThenDropped(HandSim& sim, double initial_opening, double object_half_height_m) {
  const Eigen::Isometry3d held = sim.objectInWorld();
  sim.step(10000);  // 10 s
  const Eigen::Isometry3d later = sim.objectInWorld();
  std::printf("held 10 s: drift %.2f um, %.4f deg; gels %.4f / %.4f mm, %.3f / %.3f N\n",
              (later.translation() - held.translation()).norm() * 1e6,
              Eigen::AngleAxisd(held.linear().transpose() * later.linear()).angle() * 180 / M_PI,
              sim.contact(0).penetration_m * 1e3, sim.contact(1).penetration_m * 1e3,
              sim.contact(0).normal_force_n, sim.contact(1).normal_force_n);
  EXPECT_LT((later.translation() - held.translation()).norm(), 0.1e-3);
  EXPECT_LT(Eigen::AngleAxisd(held.linear().transpose() * later.linear()).angle(),
            0.1 * M_PI / 180);
  EXPECT_TRUE(sim.contact(0).in_contact && sim.contact(1).in_contact);
  sim.setOpening(initial_opening);
  sim.step(1500);
  EXPECT_FALSE(sim.contact(0).in_contact || sim.contact(1).in_contact);
  EXPECT_NEAR(sim.objectInWorld().translation().z(), 0.05 + 0.0725 + object_half_height_m, 1e-3);
}

TEST(HandSimGrasp, Wsg50HoldsTheCubeAtOneMillimetreOnBothGelsThenDropsIt) {
  HandSim sim(wsgGraspConfig("box:30x30x30", 1e-3));
  const Grasp grasp = graspWithTheWsg(sim);
  EXPECT_NEAR(grasp.left_mm, 1.0, 0.05);
  EXPECT_NEAR(grasp.right_mm, 1.0, 0.05);
  // The force each gel carries is the drive's effort.
  EXPECT_NEAR(sim.contact(0).normal_force_n,
              sim.jointEffort(sim.description().jointIndex("base_joint_gripper_left")),
              0.05 * sim.contact(0).normal_force_n);
  expectHeldThenDropped(sim, (0.040 - 0.016) / (0.055 - 0.016), 0.015);
}

TEST(HandSimGrasp, Wsg50HoldsASixtyMillimetreCylinder) {
  test::ScratchDirectory dir;
  // A 60 mm cylinder, 40 mm tall, standing along z: 48 facets.
  std::ofstream obj(dir.path("cylinder.obj"));
  const int n = 48;
  for (int ring = 0; ring < 2; ++ring) {
    for (int i = 0; i < n; ++i) {
      obj << "v " << 30 * std::cos(2 * M_PI * i / n) << " " << 30 * std::sin(2 * M_PI * i / n)
          << " " << (ring ? 20 : -20) << "\n";
    }
  }
  for (int i = 0; i < n; ++i) {
    const int a = i + 1, b = (i + 1) % n + 1;
    obj << "f " << a << " " << b << " " << b + n << "\nf " << a << " " << b + n << " " << a + n
        << "\n";
  }
  for (int i = 1; i + 1 < n; ++i) {
    obj << "f 1 " << i + 2 << " " << i + 1 << "\nf " << n + 1 << " " << n + i + 1 << " "
        << n + i + 2 << "\n";
  }
  obj.close();
  HandSimConfig config = wsgGraspConfig(dir.path("cylinder.obj"), 1e-3);
  config.object.scale = 1e-3;
  config.hand.initial_positions = {{"base_joint_gripper_left", -0.050},
                                   {"base_joint_gripper_right", 0.050}};
  HandSim sim(config);
  EXPECT_EQ(sim.collision().kind, "hull");
  const Grasp grasp = graspWithTheWsg(sim);
  EXPECT_NEAR(grasp.left_mm, 1.0, 0.05);
  EXPECT_NEAR(grasp.right_mm, 1.0, 0.05);
  expectHeldThenDropped(sim, (0.050 - 0.016) / (0.055 - 0.016), 0.020);
}

TEST(HandSimGrasp, AllegroClosesFourFingersOnASphereInItsPalmByATrajectory) {
  // Palm up (its +x, the palm's normal, along world +z), a 90 mm ball of 0.1 kg resting on the
  // palm; every finger flexes 1.3 rad per joint and the thumb turns in, within 2 s. Each drive
  // pushes with at most 0.7 N m: a fingertip 3-7 cm from its joints presses with 10-23 N.
  HandSimConfig config;
  config.hand = loadHandConfig(kAllegroYaml);
  config.hand.base_pose = poseFromXyzRpy({0.0, 0.0, 0.1, 0.0, -M_PI / 2, 0.0});
  config.object.mesh = "sphere:45";
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.03, 0.0, 0.17));
  HandSim sim(config);
  sim.step(500);  // the ball settles on the palm
  EXPECT_NEAR(sim.objectInWorld().translation().z(), 0.1 + 0.0111 + 0.045, 1e-3);
  JointTrajectoryCommand close;
  close.joint_names = {"joint_1.0",  "joint_2.0",  "joint_3.0",  "joint_5.0",  "joint_6.0",
                       "joint_7.0",  "joint_9.0",  "joint_10.0", "joint_11.0", "joint_12.0",
                       "joint_13.0", "joint_14.0", "joint_15.0"};
  close.times_s = {2.0};
  close.positions = {{1.3, 1.3, 1.3, 1.3, 1.3, 1.3, 1.3, 1.3, 1.3, 1.39, 1.15, 1.15, 1.15}};
  EXPECT_TRUE(sim.setTrajectory(close).empty());
  sim.step(3000);  // closed at 2 s, then 1 s for the contacts to settle
  const Eigen::Vector3d held = sim.objectInWorld().translation();
  sim.step(5000);  // 5 s
  const Eigen::Vector3d later = sim.objectInWorld().translation();
  int touching = 0;
  for (int s = 0; s < 4; ++s) {
    std::printf("%s: %s %.2f N, %.3f mm\n", sim.sensor(s).name.c_str(),
                sim.contact(s).in_contact ? "in contact" : "free", sim.contact(s).normal_force_n,
                sim.contact(s).penetration_m * 1e3);
    if (!sim.contact(s).in_contact) continue;
    ++touching;
    EXPECT_GT(sim.contact(s).normal_force_n, 2.0) << sim.sensor(s).name;
    EXPECT_LT(sim.contact(s).normal_force_n, 30.0) << sim.sensor(s).name;
    EXPECT_FALSE(sim.contact(s).too_deep) << sim.sensor(s).name;
  }
  EXPECT_GE(touching, 3);
  std::printf("ball moved %.1f um over 5 s\n", (later - held).norm() * 1e6);
  EXPECT_LT((later - held).norm(), 1e-3);
}

TEST(HandSimGrasp, TheBuiltInGripperAsAUrdfHoldsTheCubeAsGripperSimDoes) {
  // config/hands/parallel_gripper.yaml against GripperSim on the same scene (config/scenes/
  // cube.yaml): both grasp the cube at 1 mm on each gel, hold it without drift, drop it opened.
  const std::string source = NORM2TEX_SOURCE_DIR;
  GripperSimConfig scene = loadGripperSimConfig(source + "/config/scenes/cube.yaml");
  setGelFromSensor(makeDigitSensorModel(), scene);
  GripperSim gripper(scene);
  gripper.reset(1, 0.0);
  const Eigen::Isometry3d gripper_held = gripper.objectInWorld();
  gripper.step(10000);

  HandSimConfig config = makeHandSimConfig(source + "/config/hands/parallel_gripper.yaml", scene);
  // The coupled drive carries both gels: twice the force that indents one by 1 mm.
  config.hand.drives["finger_left_joint"].effort = 2.0 * scene.gel_law.force(1e-3);
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 0.2));
  HandSim hand(config);
  EXPECT_TRUE(
      (hand.gelInWorld(0).linear() - gripper.gelInWorld(Finger::kLeft).linear()).isZero(1e-12));
  EXPECT_TRUE(
      (hand.gelInWorld(1).linear() - gripper.gelInWorld(Finger::kRight).linear()).isZero(1e-12));
  EXPECT_NEAR(hand.gelInWorld(0).translation().y(), 0.020, 1e-12);
  hand.resetObject(config.object_pose, false);
  hand.setOpening(0.0);
  hand.step(1500);
  hand.setObjectGravity(true);
  hand.step(500);
  for (int s = 0; s < 2; ++s) {
    const Finger finger = static_cast<Finger>(s);
    EXPECT_NEAR(gripper.contact(finger).penetration_m, 1e-3, 3e-6);
    EXPECT_NEAR(hand.contact(s).penetration_m, 1e-3, 3e-6) << hand.sensor(s).name;
    EXPECT_NEAR(hand.contact(s).normal_force_n, gripper.contact(finger).normal_force_n,
                0.01 * gripper.contact(finger).normal_force_n);
  }
  // The cube hangs in the gels as deep in both: its weight shears them the same way.
  const Eigen::Isometry3d held = hand.objectInWorld();
  EXPECT_NEAR(held.translation().z(), gripper_held.translation().z(), 0.05e-3);
  hand.step(10000);
  const double hand_drift = (hand.objectInWorld().translation() - held.translation()).norm();
  const double gripper_drift =
      (gripper.objectInWorld().translation() - gripper_held.translation()).norm();
  std::printf("10 s drift: built-in as URDF %.3f um, GripperSim %.3f um\n", hand_drift * 1e6,
              gripper_drift * 1e6);
  EXPECT_LT(hand_drift, 1e-6);
  EXPECT_LT(gripper_drift, 1e-6);
  hand.setOpening(1.0);
  hand.step(1500);
  EXPECT_FALSE(hand.contact(0).in_contact || hand.contact(1).in_contact);
  EXPECT_LT(hand.objectInWorld().translation().z(), 0.2 - 0.0128);  // below the gel pads
}

TEST(HandSimGrasp, Wsg50PicksTheCubeOffTheFloorAsItsBaseRises) {
  // Turned upside down over a cube on the floor, closed at 10 N a finger, then its base lifted
  // 50 mm in 1 s: the cube rises with it, held by the gels' friction alone.
  HandSimConfig config;
  config.hand = loadHandConfig(kRobots + "/wsg50/wsg50_top_grasp.yaml");
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 0.015));
  HandSim sim(config);
  sim.step(200);
  EXPECT_NEAR(sim.objectInWorld().translation().z(), 0.015, 1e-4);
  sim.setOpening(0.0);
  sim.step(1500);
  ASSERT_TRUE(sim.contact(0).in_contact && sim.contact(1).in_contact);
  EXPECT_NEAR(sim.contact(0).normal_force_n, 10.0, 0.1);
  Eigen::Isometry3d up = sim.basePose();
  up.translation().z() += 0.05;
  sim.setBasePose(up, 1.0);
  sim.step(500);
  EXPECT_NEAR(sim.basePose().translation().z(), 0.133 + 0.025, 1e-9);  // halfway
  sim.step(1500);
  EXPECT_NEAR(sim.objectInWorld().translation().z(), 0.065, 0.2e-3);
  EXPECT_TRUE(sim.contact(0).in_contact && sim.contact(1).in_contact);
  test::expectError([&] { sim.setBasePose(up, -1.0); }, {"duration"});
}

}  // namespace
}  // namespace norm2tex
