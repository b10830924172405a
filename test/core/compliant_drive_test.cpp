// GripperSim with a compliant drive (gripper.stiffness_n_per_mm): the fingers sit back from the
// command by F / k, the series equilibrium settles without ringing, k = 0 is the rigid gripper
// bit for bit, and bad stiffnesses are refused by name.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/gel/gel_law.hpp"
#include "norm2tex/sim/gripper_sim.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

GripperSimConfig compliantCube(double stiffness_n_per_mm) {
  GripperSimConfig config;
  config.object.friction = 0.5;
  config.gripper.stiffness_n_per_m = stiffness_n_per_mm * 1e3;
  setGelFromSensor(makeDigitSensorModel(), config);
  return config;
}

double meanForce(const GripperSim& sim) {
  return 0.5 *
         (sim.contact(Finger::kLeft).normal_force_n + sim.contact(Finger::kRight).normal_force_n);
}

TEST(CompliantDriveTest, TheGelsTangentStiffnessIsTheLawsSlope) {
  // The Newton step's k_gel: a wrong slope would still converge, but slower or ringing.
  const GelLaw law = GelLaw::taximDefault();
  for (double d : {0.02e-3, 0.07e-3, 0.15e-3, 0.3e-3, 0.5e-3, 1.5e-3, 2.5e-3}) {
    const double h = 1e-9;
    const double slope = (law.force(d + h) - law.force(d - h)) / (2 * h);
    EXPECT_NEAR(law.tangentStiffness(d), slope, 1e-4 * slope) << d;
  }
  EXPECT_DOUBLE_EQ(law.tangentStiffness(0.0), law.secantStiffness(0.0));  // linear first touch
}

TEST(CompliantDriveTest, FingersSitBackFromTheCommandByForceOverStiffness) {
  // Commanded 24 mm apart, the 30 mm cube needs 3 mm on each side: gel indentation plus the
  // drive's deflection. A stiffer drive leaves the finger closer to its command and presses
  // harder.
  double previous_force = 0.0;
  for (double k_n_per_mm : {1.0, 2.0}) {
    const GripperSimConfig config = compliantCube(k_n_per_mm);
    GripperSim sim(config);
    sim.reset(1, 0.0);
    sim.setOpening(0.6);
    sim.step(1500);
    ASSERT_FALSE(sim.dropped()) << k_n_per_mm << " N/mm";
    const double commanded = sim.gapForOpening(sim.commandedOpening()) / 2.0;
    const double deflection = sim.fingerPosition() - commanded;
    const double force = meanForce(sim);
    RecordProperty("deflection_um_at_" + std::to_string(static_cast<int>(k_n_per_mm)) + "n_per_mm",
                   std::to_string(deflection * 1e6));
    RecordProperty("force_n_at_" + std::to_string(static_cast<int>(k_n_per_mm)) + "n_per_mm",
                   std::to_string(force));
    EXPECT_GT(deflection, 1e-3) << k_n_per_mm << " N/mm: the finger should sit well back";
    EXPECT_NEAR(deflection, force / config.gripper.stiffness_n_per_m, 0.03 * deflection)
        << k_n_per_mm << " N/mm";
    EXPECT_GT(force, previous_force) << k_n_per_mm << " N/mm";
    previous_force = force;
    // The finger is where the gel is: the cube's face lies its indentation inside it, and the
    // gel carries the law's force for that indentation.
    for (Finger finger : {Finger::kLeft, Finger::kRight}) {
      const GelContactState& c = sim.contact(finger);
      ASSERT_TRUE(c.in_contact);
      EXPECT_NEAR(sim.fingerPosition() + c.penetration_m, 0.015, 2e-5);
      EXPECT_NEAR(c.normal_force_n, config.gel_law.force(c.penetration_m),
                  0.1 * config.gel_law.force(c.penetration_m));
    }
    // The reported opening is the fingers', not the command.
    EXPECT_NEAR(sim.opening() - sim.commandedOpening(),
                2.0 * deflection / (config.gripper.max_gap_m - config.gripper.min_gap_m), 1e-12);
  }
}

TEST(CompliantDriveTest, TheGripSettlesWithoutRinging) {
  // The gel is ~10x stiffer than a 1 N/mm drive: a plain fixed-point update would diverge.
  GripperSim sim(compliantCube(1.0));
  sim.reset(2, 0.01);
  sim.setOpening(0.62);
  sim.step(1000);  // the drive travels ~11 mm from the grasp: ~0.55 s
  double f_min = std::numeric_limits<double>::infinity(), f_max = 0.0;
  double x_min = f_min, x_max = -f_min;
  for (int t = 0; t < 1000; ++t) {
    sim.step(1);
    if (t < 500) continue;  // the last 0.5 s of a 1 s hold
    f_min = std::min(f_min, meanForce(sim));
    f_max = std::max(f_max, meanForce(sim));
    x_min = std::min(x_min, sim.fingerPosition());
    x_max = std::max(x_max, sim.fingerPosition());
  }
  ASSERT_GT(f_min, 0.5);
  RecordProperty("held_force_range_n", std::to_string(f_max - f_min));
  RecordProperty("held_finger_range_um", std::to_string((x_max - x_min) * 1e6));
  EXPECT_LT(f_max - f_min, 0.01 * f_max) << "force " << f_min << " ... " << f_max << " N";
  EXPECT_LT(x_max - x_min, 1e-6) << "finger " << x_min << " ... " << x_max << " m";
  EXPECT_FALSE(sim.dropped());
}

TEST(CompliantDriveTest, ASqueezeSettlesWithoutOvershoot) {
  // From the grasp, commanded 4 mm narrower at once on a 5 N/mm drive: the drive travels at its
  // speed limit and the fingers follow it through their springs into the gels. One drive for
  // both fingers: the gels' forces differ only while the cube shifts between them. The report
  // (JUnit XML) keeps the overshoot of the mean force, the largest difference between the gels
  // and the ticks to settle within 1 %.
  GripperSim sim(compliantCube(5.0));
  const EpisodeStart start = sim.reset(2, 0.0);
  sim.setOpening(start.grasp_opening - 0.1);
  std::vector<double> mean;
  double largest_difference = 0.0;
  for (int t = 0; t < 3000; ++t) {
    sim.step(1);
    mean.push_back(meanForce(sim));
    largest_difference =
        std::max(largest_difference, std::abs(sim.contact(Finger::kLeft).normal_force_n -
                                              sim.contact(Finger::kRight).normal_force_n));
  }
  const double settled = mean.back();
  const double peak = *std::max_element(mean.begin(), mean.end());
  int settling_ticks = 0;
  for (int t = 0; t < static_cast<int>(mean.size()); ++t) {
    if (std::abs(mean[t] - settled) > 0.01 * settled) settling_ticks = t + 1;
  }
  RecordProperty("settled_force_n", std::to_string(settled));
  RecordProperty("overshoot_percent", std::to_string((peak / settled - 1.0) * 100.0));
  RecordProperty("largest_gel_difference_n", std::to_string(largest_difference));
  RecordProperty("settling_ticks", std::to_string(settling_ticks));
  EXPECT_LT(peak, 1.01 * settled);
  EXPECT_LT(largest_difference, 0.05 * settled);
  EXPECT_LT(settling_ticks, 1500);  // the drive's 2 mm at 20 mm/s take 100 ticks
  EXPECT_FALSE(sim.dropped());
}

TEST(CompliantDriveTest, ZeroStiffnessIsTheRigidGripperBitForBit) {
  test::ScratchDirectory dir;
  const auto load = [&](const std::string& name, const std::string& gripper) {
    std::ofstream(dir.path(name)) << "gripper: {" << gripper << "}\n";
    GripperSimConfig config = loadGripperSimConfig(dir.path(name));
    setGelFromSensor(makeDigitSensorModel(), config);
    return config;
  };
  struct Frame {
    Eigen::Matrix4d object;
    double finger, left_force, right_force;
    bool operator==(const Frame& o) const {
      return object == o.object && finger == o.finger && left_force == o.left_force &&
             right_force == o.right_force;
    }
  };
  // Grasp, squeeze, then open until the cube falls.
  const auto run = [](const GripperSimConfig& config) {
    GripperSim sim(config);
    sim.reset(42, 0.012);
    std::vector<Frame> frames;
    for (int i = 0; i < 120 && !sim.dropped(); ++i) {
      sim.addOpening(i < 20 ? -0.005 : 0.005);
      sim.step(17);
      frames.push_back({sim.objectInWorld().matrix(), sim.fingerPosition(),
                        sim.contact(Finger::kLeft).normal_force_n,
                        sim.contact(Finger::kRight).normal_force_n});
    }
    return frames;
  };
  const auto absent = run(load("absent.yaml", "max_gap_mm: 40"));
  const auto zero = run(load("zero.yaml", "max_gap_mm: 40, stiffness_n_per_mm: 0"));
  const auto soft = run(load("soft.yaml", "max_gap_mm: 40, stiffness_n_per_mm: 1"));
  ASSERT_EQ(absent.size(), zero.size());
  for (std::size_t i = 0; i < absent.size(); ++i) {
    EXPECT_TRUE(absent[i] == zero[i]) << "frame " << i << " differs";
  }
  EXPECT_FALSE(absent == soft) << "a compliant drive should change the trajectory";
}

TEST(CompliantDriveTest, BadStiffnessesAreRefusedByName) {
  test::ScratchDirectory dir;
  const auto write = [&](const std::string& text) {
    std::ofstream(dir.path("scene.yaml")) << text;
    return dir.path("scene.yaml");
  };
  for (const char* value : {"-1", ".nan", ".inf", "2000"}) {
    test::expectError(
        [&] {
          loadGripperSimConfig(
              write(std::string("gripper: {stiffness_n_per_mm: ") + value + "}\n"));
        },
        {"scene.yaml", "gripper.stiffness_n_per_mm", "(0, 1000] N/mm"});
  }
  GripperSimConfig config = compliantCube(1.0);
  config.gripper.stiffness_n_per_m = NAN;
  test::expectError([&] { GripperSim sim(config); }, {"gripper.stiffness_n_per_mm"});
  EXPECT_NEAR(
      loadGripperSimConfig(write("gripper: {stiffness_n_per_mm: 1.5}\n")).gripper.stiffness_n_per_m,
      1500.0, 1e-9);
}

}  // namespace
}  // namespace norm2tex
