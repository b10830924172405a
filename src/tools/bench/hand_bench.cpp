// Physics cost of HandSim (one core) on the hands the tests load (TACTO's WSG-50 and Allegro
// with DIGITs, test/fixtures/robots of the source tree): a tick holding the 30 mm cube at 1 mm
// on both gels, the Allegro's 16 joints and 4 gels moving with nothing touched, and the Allegro
// holding a ball in its palm with its four DIGITs.
#include <cmath>
#include <filesystem>
#include <string>

#include <benchmark/benchmark.h>

#include "norm2tex/sim/hand_sim.hpp"

namespace {

const std::string kRobots = std::string(NORM2TEX_SOURCE_DIR) + "/test/fixtures/robots";

bool fixturesThere(benchmark::State& state) {
  if (std::filesystem::exists(kRobots)) return true;
  state.SkipWithError(("the hand fixtures are not at " + kRobots).c_str());
  return false;
}

void BM_HandSim_Tick_Wsg50HoldingCube(benchmark::State& state) {
  if (!fixturesThere(state)) return;
  norm2tex::HandSimConfig config;
  config.hand = norm2tex::loadHandConfig(kRobots + "/wsg50/wsg50_hand.yaml");
  config.hand.default_drive.effort = config.gel_law.force(1e-3);
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 0.168));
  norm2tex::HandSim sim(config);
  sim.resetObject(config.object_pose, false);
  sim.setOpening(0.0);
  sim.step(1500);
  sim.setObjectGravity(true);
  sim.step(500);
  for (auto _ : state) sim.step(1);
  state.counters["ticks/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_HandSim_Tick_Wsg50HoldingCube)->Unit(benchmark::kMicrosecond);

// The top grasp of hand_sim.test and the ROS benchmark: the WSG-50 upside down, the cube on the
// floor pressed by both gels at the drives' 10 N (Bullet's solver also carries the floor).
void BM_HandSim_Tick_Wsg50TopGrasp(benchmark::State& state) {
  if (!fixturesThere(state)) return;
  norm2tex::HandSimConfig config;
  config.hand = norm2tex::loadHandConfig(kRobots + "/wsg50/wsg50_top_grasp.yaml");
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 0.015));
  norm2tex::HandSim sim(config);
  sim.setOpening(0.0);
  sim.step(3000);
  for (auto _ : state) sim.step(1);
  state.counters["ticks/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_HandSim_Tick_Wsg50TopGrasp)->Unit(benchmark::kMicrosecond);

void BM_HandSim_Tick_AllegroMovingFree(benchmark::State& state) {
  if (!fixturesThere(state)) return;
  norm2tex::HandSimConfig config;
  config.hand = norm2tex::loadHandConfig(kRobots + "/allegro_hand_description/allegro_hand.yaml");
  config.object.mesh = "sphere:10";
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.5, 0.0, 0.01));
  norm2tex::HandSim sim(config);
  std::vector<double> up(sim.actuatedJoints().size(), 0.3), down(up.size(), 0.0);
  int ticks = 0;
  for (auto _ : state) {
    // Every joint moves: a new target every 0.2 s.
    if (ticks++ % 200 == 0)
      sim.setJointTargets(sim.actuatedJoints(), (ticks / 200) % 2 ? up : down);
    sim.step(1);
  }
  state.counters["ticks/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_HandSim_Tick_AllegroMovingFree)->Unit(benchmark::kMicrosecond);

void BM_HandSim_Tick_AllegroHoldingSphere(benchmark::State& state) {
  if (!fixturesThere(state)) return;
  // hand_sim_test's grasp: palm up, a 90 mm ball in the palm, four DIGITs pressing on it.
  norm2tex::HandSimConfig config;
  config.hand = norm2tex::loadHandConfig(kRobots + "/allegro_hand_description/allegro_hand.yaml");
  config.hand.base_pose = norm2tex::poseFromXyzRpy({0.0, 0.0, 0.1, 0.0, -M_PI / 2, 0.0});
  config.object.mesh = "sphere:45";
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.03, 0.0, 0.17));
  norm2tex::HandSim sim(config);
  sim.step(500);
  norm2tex::JointTrajectoryCommand close;
  close.joint_names = {"joint_1.0",  "joint_2.0",  "joint_3.0",  "joint_5.0",  "joint_6.0",
                       "joint_7.0",  "joint_9.0",  "joint_10.0", "joint_11.0", "joint_12.0",
                       "joint_13.0", "joint_14.0", "joint_15.0"};
  close.times_s = {2.0};
  close.positions = {{1.3, 1.3, 1.3, 1.3, 1.3, 1.3, 1.3, 1.3, 1.3, 1.39, 1.15, 1.15, 1.15}};
  sim.setTrajectory(close);
  sim.step(3000);
  for (auto _ : state) sim.step(1);
  int touching = 0;
  for (int s = 0; s < sim.sensorCount(); ++s) touching += sim.contact(s).in_contact;
  state.counters["ticks/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["gels_touching"] = touching;
}
BENCHMARK(BM_HandSim_Tick_AllegroHoldingSphere)->Unit(benchmark::kMicrosecond);

}  // namespace
