// Physics cost of HandSim (one core) on the hands the tests load (TACTO's WSG-50 and Allegro
// with DIGITs, test/fixtures/robots of the source tree): a tick holding the 30 mm cube at 1 mm
// on both gels, and a tick of the Allegro's 16 joints and 4 gels moving with nothing touched.
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
    if (ticks++ % 200 == 0) sim.setJointTargets(sim.actuatedJoints(), (ticks / 200) % 2 ? up : down);
    sim.step(1);
  }
  state.counters["ticks/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_HandSim_Tick_AllegroMovingFree)->Unit(benchmark::kMicrosecond);

}  // namespace
