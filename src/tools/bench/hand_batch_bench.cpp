// A batch of simulated hands stepped and rendered over T threads, as a learning setup runs many
// environments at once: environment steps per second (one sensor frame of physics and every
// sensor's image) and images per second, for T = 1, 2, 4, ... up to the machine's cores, so that
// scaling can be read off on machines with many. The hands are TACTO's WSG-50 of the source
// tree's test fixtures, each holding a 30 mm cube at 10 N per finger; the batch has 8 of them,
// sharing one texture cache; each iteration steps every hand by one frame, thread t taking
// hands t, t + T, ... (threads started per iteration: ~0.1 ms against ~25 ms of work).
#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <benchmark/benchmark.h>

#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/tactile_hand.hpp"

namespace {

const std::string kRobots = std::string(NORM2TEX_SOURCE_DIR) + "/test/fixtures/robots";
constexpr int kHands = 8;

std::vector<std::unique_ptr<norm2tex::TactileHand>> makeBatch() {
  norm2tex::HandSimConfig config;
  config.hand = norm2tex::loadHandConfig(kRobots + "/wsg50/wsg50_top_grasp.yaml");
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 0.015));
  const norm2tex::SensorModel sensor = norm2tex::makeDigitSensorModel();
  norm2tex::TactileHandOptions options;
  options.material_config = std::string(NORM2TEX_SOURCE_DIR) + "/config/materials/wood.yaml";
  auto textures = std::make_shared<norm2tex::ObjectTextureCache>(2);  // variant 0, one spare
  std::vector<std::unique_ptr<norm2tex::TactileHand>> batch;
  for (int h = 0; h < kHands; ++h) {
    batch.push_back(std::make_unique<norm2tex::TactileHand>(config, sensor, options, textures));
    batch.back()->sim().setOpening(0.0);
    batch.back()->step(60);  // closed on the cube
  }
  return batch;
}

void BM_HandBatch_Wsg50HoldingCube(benchmark::State& state) {
  if (!std::filesystem::exists(kRobots)) {
    state.SkipWithError(("the hand fixtures are not at " + kRobots).c_str());
    return;
  }
  const int threads = static_cast<int>(state.range(0));
  auto batch = makeBatch();
  int images_per_step = 0;
  for (const auto& hand : batch) images_per_step += hand->sensorCount();
  for (auto _ : state) {
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) {
      pool.emplace_back([&batch, t, threads] {
        for (int h = t; h < kHands; h += threads) batch[h]->step(1);
      });
    }
    for (std::thread& thread : pool) thread.join();
  }
  state.counters["env_steps/s"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * kHands, benchmark::Counter::kIsRate);
  state.counters["images/s"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * images_per_step, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_HandBatch_Wsg50HoldingCube)
    ->Apply([](benchmark::internal::Benchmark* b) {
      const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
      for (int t = 1; t <= std::min(cores, kHands); t *= 2) b->Arg(t);
    })
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
