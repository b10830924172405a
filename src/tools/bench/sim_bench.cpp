// Physics cost of GripperSim (one core): ticks per second holding the default 30 mm cube, a
// 20k-triangle ball (recognised as a sphere: it collides exactly; the render mesh keeps every
// triangle), the same ball forced to collide as its 10k-vertex hull (the worst case of a big
// convex mesh), and a user's 128-facet cylinder (its hull).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include <benchmark/benchmark.h>

#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/mesh/uv_unwrap.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/contact_patch.hpp"
#include "norm2tex/sim/gripper_sim.hpp"

namespace {

norm2tex::GripperSimConfig config(const std::string& mesh) {
  norm2tex::GripperSimConfig c;
  c.object.mesh = mesh;
  norm2tex::setGelFromSensor(norm2tex::makeDigitSensorModel(), c);
  return c;
}

// A 12 mm ball of 2 x 70 x 143 = 20,020 triangles, written once as an OBJ file.
std::string ballMesh20k() {
  static const std::string path = [] {
    const std::string file =
        (std::filesystem::temp_directory_path() / "norm2tex_bench_ball_20k.obj").string();
    norm2tex::saveMesh(norm2tex::makeUvSphere(0.012, 71, 143), file);
    return file;
  }();
  return path;
}

// A 24 mm, 30 mm tall cylinder of 128 facets in millimetres, written once as an OBJ file.
std::string cylinderMesh128() {
  static const std::string path = [] {
    const std::string file =
        (std::filesystem::temp_directory_path() / "norm2tex_bench_cylinder_128.obj").string();
    std::FILE* obj = std::fopen(file.c_str(), "w");
    constexpr int kFacets = 128;
    for (double z : {-15.0, 15.0}) {
      for (int k = 0; k < kFacets; ++k) {
        const double a = 2 * M_PI * k / kFacets;
        std::fprintf(obj, "v %.6f %.6f %.1f\n", 12 * std::cos(a), 12 * std::sin(a), z);
      }
    }
    for (int k = 0; k < kFacets; ++k) {
      const int a = k + 1, b = (k + 1) % kFacets + 1;
      std::fprintf(obj, "f %d %d %d\nf %d %d %d\n", a, b, b + kFacets, a, b + kFacets,
                   a + kFacets);
    }
    for (int k = 1; k + 1 < kFacets; ++k) {
      std::fprintf(obj, "f 1 %d %d\nf %d %d %d\n", k + 2, k + 1, kFacets + 1, kFacets + k + 1,
                   kFacets + k + 2);
    }
    std::fclose(obj);
    return file;
  }();
  return path;
}

void holdAndStep(benchmark::State& state, const norm2tex::GripperSimConfig& c) {
  norm2tex::GripperSim sim(c);
  sim.reset(1, 0.0);
  for (auto _ : state) sim.step(1);
  state.counters["ticks/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["triangles"] = static_cast<double>(sim.object().mesh.triangles().size());
}

void BM_GripperSim_Tick_Cube(benchmark::State& state) {
  holdAndStep(state, config("box:30x30x30"));
}
BENCHMARK(BM_GripperSim_Tick_Cube)->Unit(benchmark::kMicrosecond);

void BM_GripperSim_Tick_Ball20kTriangles(benchmark::State& state) {
  holdAndStep(state, config(ballMesh20k()));
}
BENCHMARK(BM_GripperSim_Tick_Ball20kTriangles)->Unit(benchmark::kMicrosecond);

void BM_GripperSim_Tick_Ball20kTrianglesHull(benchmark::State& state) {
  norm2tex::GripperSimConfig c = config(ballMesh20k());
  c.object.collision = "hull";
  holdAndStep(state, c);
}
BENCHMARK(BM_GripperSim_Tick_Ball20kTrianglesHull)->Unit(benchmark::kMicrosecond);

void BM_GripperSim_Tick_Cylinder128(benchmark::State& state) {
  norm2tex::GripperSimConfig c = config(cylinderMesh128());
  c.object.scale = 0.001;
  holdAndStep(state, c);
}
BENCHMARK(BM_GripperSim_Tick_Cylinder128)->Unit(benchmark::kMicrosecond);

// One 60 Hz sensor frame of contact_sim: 17 ticks plus both gels' contact patches.
void BM_GripperSim_Frame_Cube(benchmark::State& state) {
  norm2tex::GripperSim sim(config("box:30x30x30"));
  sim.reset(1, 0.0);
  norm2tex::ContactPatchMeter left(norm2tex::makeDigitSensorModel()),
      right(norm2tex::makeDigitSensorModel());
  for (auto _ : state) {
    sim.step(17);
    benchmark::DoNotOptimize(
        left.measure(sim.object().mesh, sim.contact(norm2tex::Finger::kLeft).object_in_gel));
    benchmark::DoNotOptimize(
        right.measure(sim.object().mesh, sim.contact(norm2tex::Finger::kRight).object_in_gel));
  }
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_GripperSim_Frame_Cube)->Unit(benchmark::kMicrosecond);

}  // namespace
