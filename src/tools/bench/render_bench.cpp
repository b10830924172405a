// Per-frame cost of the DIGIT renderer at 320 x 240 (one core): whole frames with and without
// texture, a 200k-triangle mesh, and each stage on its own.
#include <chrono>
#include <cmath>
#include <memory>
#include <thread>

#include <benchmark/benchmark.h>

#include "norm2tex/texture/analytic_surface.hpp"
#include "norm2tex/render/contact_rasterizer.hpp"
#include "norm2tex/render/gel_conformity.hpp"
#include "norm2tex/render/gel_model.hpp"
#include "norm2tex/texture/height_atlas_baker.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/texture/normal_encoding.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "norm2tex/render/texture_overlay.hpp"

namespace {

// The reference scene: a 10 mm sphere pressed 1 mm near the gel centre. The UV
// sphere lies on its side (contact on the equator, like a real textured ball); pressed on its
// pole instead, the UVs fan around the whole atlas width (BM_Render_Textured_AtUvPole).
Eigen::Isometry3d pressedSphere(bool at_pole = false) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  if (!at_pole)
    pose.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0.0003, -0.0002, 0.005 - 0.001);
  return pose;
}

std::shared_ptr<const norm2tex::TexturedMesh> sphere(int rings, int segments) {
  return std::make_shared<norm2tex::TexturedMesh>(norm2tex::makeUvSphere(0.005, rings, segments));
}

std::shared_ptr<const norm2tex::HeightAtlas> atlas() {
  static const auto baked = [] {
    const cv::Size size(1024, 1024);
    norm2tex::AnalyticSurface s = norm2tex::makeWaves(size, {{1.0, 37.0, 0.4, 0.0}});
    s += norm2tex::makeRidges(size, {1.2, 11.0, 1.5, 0.8});
    const cv::Mat image =
        norm2tex::encodeNormalMap(s.dx, s.dy, norm2tex::NormalConvention::kOpenGL, CV_8U);
    return std::make_shared<const norm2tex::HeightAtlas>(
        norm2tex::bakeHeightAtlas(norm2tex::NormalMap::fromImage(image)));
  }();
  return baked;
}

void renderLoop(benchmark::State& state, std::shared_ptr<const norm2tex::TexturedMesh> mesh,
                double beta_mm, std::int64_t seed, bool at_pole = false,
                const Eigen::Isometry3d* pose_override = nullptr, bool conformity = false) {
  norm2tex::SensorModel model = norm2tex::makeDigitSensorModel();
  model.conformity.enabled = conformity;
  norm2tex::TactileRenderer renderer(model);
  renderer.setObject(std::move(mesh), beta_mm > 0 ? atlas() : nullptr, beta_mm);
  const Eigen::Isometry3d pose = pose_override ? *pose_override : pressedSphere(at_pole);
  int frame = 0;
  for (auto _ : state) {
    const norm2tex::TactileFrame& out = renderer.render(pose, seed < 0 ? -1 : seed + frame++);
    benchmark::DoNotOptimize(out.image.data);
  }
  state.counters["fps"] = benchmark::Counter(1.0, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_Render_Textureless(benchmark::State& state) { renderLoop(state, sphere(96, 192), 0.0, 1); }
void BM_Render_Textured(benchmark::State& state) { renderLoop(state, sphere(96, 192), 0.2, 1); }
void BM_Render_Textured_AtUvPole(benchmark::State& state) {
  renderLoop(state, sphere(96, 192), 0.2, 1, true);
}
void BM_Render_Textured_200kTriangles(benchmark::State& state) {
  renderLoop(state, sphere(317, 317), 0.2, 1);
}
// The gripper's scene: the 30 mm cube held 1 mm deep, its face over the whole gel but its lower
// edge (7 mm below the gel centre): the contact covers 3/4 of the image. `yaw` turns it about
// the gel normal (degrees), so the face's UV axes run across the image's rows or columns.
Eigen::Isometry3d heldCubePose(double yaw_degrees = 0.0) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() =
      Eigen::AngleAxisd(yaw_degrees * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0.0, -0.008, 0.014);
  return pose;
}
std::shared_ptr<const norm2tex::TexturedMesh> cube() {
  return std::make_shared<norm2tex::TexturedMesh>(
      norm2tex::makeBox(Eigen::Vector3d(0.03, 0.03, 0.03), 0.02));
}
void BM_Render_Textured_HeldCube(benchmark::State& state) {
  const Eigen::Isometry3d pose = heldCubePose(static_cast<double>(state.range(0)));
  // noise 0: what the nodes render with the shipped sensor (a captured background gets no
  // noise on top); noise 1: the synthetic background's correlated noise.
  renderLoop(state, cube(), 0.2, state.range(1) != 0 ? 1 : -1, false, &pose);
}

// The held cube with the gel's conformity to the texture on (its force from the gel law).
void BM_Render_Textured_HeldCube_Conformity(benchmark::State& state) {
  const Eigen::Isometry3d pose = heldCubePose();
  renderLoop(state, cube(), 0.2, -1, false, &pose, true);
}

// The held cube rendered once per 60 Hz tick, as the renderer nodes do: the thread sleeps
// between frames, so each frame starts with what the idle CPU left of its caches (warm loops
// miss that). Manual time: the render only. `conformity` 0/1: the fixed-depth overlay or the
// gel's conformity (the default sensor).
// `rehearse_ms` > 0: the same render once more that long before each tick, its output unused
// (what tactile_renderer's ~rehearse_ms does in real time).
void BM_Render_HeldCube_Paced60Hz(benchmark::State& state) {
  norm2tex::SensorModel model = norm2tex::makeDigitSensorModel();
  model.conformity.enabled = state.range(0) != 0;
  const auto rehearse = std::chrono::microseconds(state.range(1) * 1000);
  norm2tex::TactileRenderer renderer(model);
  renderer.setObject(cube(), atlas(), 0.2);
  const Eigen::Isometry3d pose = heldCubePose();
  using Clock = std::chrono::steady_clock;
  Clock::time_point tick = Clock::now();
  for (auto _ : state) {
    tick += std::chrono::nanoseconds(16'666'667);
    if (rehearse.count() > 0) {
      std::this_thread::sleep_until(tick - rehearse);
      benchmark::DoNotOptimize(renderer.render(pose, -1).image.data);
    }
    std::this_thread::sleep_until(tick);
    const Clock::time_point start = Clock::now();
    const norm2tex::TactileFrame& out = renderer.render(pose, -1);
    benchmark::DoNotOptimize(out.image.data);
    state.SetIterationTime(std::chrono::duration<double>(Clock::now() - start).count());
  }
}

// --- stages ---------------------------------------------------------------------------------
// Argument "cube": 0 = the pressed sphere, 1 = the held cube (contact over 3/4 of the gel).
struct StageFixture {
  explicit StageFixture(bool held_cube = false)
      : mesh(held_cube ? cube() : sphere(96, 192)),
        pose(held_cube ? heldCubePose() : pressedSphere()) {
    rasterizer.rasterize(*mesh, pose, overlay.reachMm(), true, raster);
    overlay.apply(raster, model.gel_thickness_mm, h_final);
    gel.apply(h_final, gel_mm);
  }
  norm2tex::SensorModel model = norm2tex::makeDigitSensorModel();
  std::shared_ptr<const norm2tex::TexturedMesh> mesh;
  Eigen::Isometry3d pose;
  norm2tex::ContactRasterizer rasterizer{model};
  norm2tex::TextureOverlay overlay{atlas(), 0.2};
  norm2tex::GelModel gel{model};
  norm2tex::ContactRaster raster;
  cv::Mat1f h_final, gel_mm;
};

void BM_Stage_Raster(benchmark::State& state) {
  StageFixture f(state.range(0) != 0);
  const bool want_uv = state.range(1) != 0;
  for (auto _ : state)
    f.rasterizer.rasterize(*f.mesh, f.pose, want_uv ? f.overlay.reachMm() : 0.0, want_uv,
                           f.raster);
}
void BM_Stage_Overlay(benchmark::State& state) {
  StageFixture f(state.range(0) != 0);
  for (auto _ : state) f.overlay.apply(f.raster, f.model.gel_thickness_mm, f.h_final);
}
void BM_Stage_Gel(benchmark::State& state) {
  StageFixture f(state.range(0) != 0);
  for (auto _ : state) f.gel.apply(f.h_final, f.gel_mm);
}
// GelConformity alone (5 N; the renderer adds H_final's rewrite).
void BM_Stage_Conformity(benchmark::State& state) {
  StageFixture f(state.range(0) != 0);
  norm2tex::ConformityOptions options;
  options.enabled = true;
  norm2tex::GelConformity conformity(options, f.model.mm_per_pixel);
  cv::Mat1f h_local, followed;
  f.overlay.apply(f.raster, f.model.gel_thickness_mm, f.h_final, &h_local);
  for (auto _ : state) {
    const norm2tex::ConformityStats stats = conformity.apply(
        f.raster.h_sensor_mm, h_local, f.overlay.betaMm(), f.raster.covered_box, 5.0, followed);
    benchmark::DoNotOptimize(stats.mean_pressure_mpa);
  }
}
void BM_Stage_Shading(benchmark::State& state) {
  StageFixture f(state.range(0) != 0);
  norm2tex::DigitShader shader(f.model, norm2tex::makeSyntheticBackground(f.model),
                               norm2tex::BackgroundSource::kSynthetic);
  const bool noise = state.range(1) != 0;
  std::int64_t seed = 0;
  for (auto _ : state) {
    cv::Mat3b image = shader.shade(f.gel_mm, noise ? seed++ : -1);
    benchmark::DoNotOptimize(image.data);
  }
}

// The held cube's render (conformity on) stage by stage, each timed: `paced` 0 renders back to
// back, 1 once per 60 Hz tick with the thread asleep in between. Which stages pay for the
// wait is what the difference of their counters (ms per frame) shows. The stages are the
// renderer's own objects in TactileRenderer::render()'s order; manual time: their sum.
void BM_Render_HeldCube_Stages(benchmark::State& state) {
  StageFixture f(true);
  const bool paced = state.range(0) != 0;
  norm2tex::ConformityOptions options;
  options.enabled = true;
  norm2tex::GelConformity conformity(options, f.model.mm_per_pixel);
  norm2tex::DigitShader shader(f.model, norm2tex::makeSyntheticBackground(f.model),
                               norm2tex::BackgroundSource::kSynthetic);
  cv::Mat1f h_local;
  using Clock = std::chrono::steady_clock;
  enum { kRaster, kOverlay, kConformity, kGel, kShading, kStages };
  const char* names[kStages] = {"raster_ms", "overlay_ms", "conformity_ms", "gel_ms", "shading_ms"};
  double totals[kStages] = {};
  Clock::time_point tick = Clock::now();
  for (auto _ : state) {
    if (paced) {
      tick += std::chrono::nanoseconds(16'666'667);
      std::this_thread::sleep_until(tick);
    }
    Clock::time_point t[kStages + 1];
    t[0] = Clock::now();
    f.rasterizer.rasterize(*f.mesh, f.pose, f.overlay.reachMm(), true, f.raster);
    t[1] = Clock::now();
    f.overlay.apply(f.raster, f.model.gel_thickness_mm, f.h_final, &h_local);
    t[2] = Clock::now();
    conformity.applyToFinal(f.raster.h_sensor_mm, h_local, f.overlay.betaMm(),
                            f.raster.covered_box, 5.0, f.raster.gap_mm,
                            f.model.gel_thickness_mm, f.h_final);
    t[3] = Clock::now();
    f.gel.apply(f.h_final, f.gel_mm);
    t[4] = Clock::now();
    cv::Mat3b image = shader.shade(f.gel_mm, -1);
    benchmark::DoNotOptimize(image.data);
    t[5] = Clock::now();
    for (int k = 0; k < kStages; ++k)
      totals[k] += std::chrono::duration<double, std::milli>(t[k + 1] - t[k]).count();
    state.SetIterationTime(std::chrono::duration<double>(t[kStages] - t[0]).count());
  }
  for (int k = 0; k < kStages; ++k) {
    state.counters[names[k]] = totals[k] / static_cast<double>(state.iterations());
  }
}

BENCHMARK(BM_Render_Textureless)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK(BM_Render_Textured)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK(BM_Render_Textured_AtUvPole)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK(BM_Render_Textured_200kTriangles)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK(BM_Render_Textured_HeldCube)
    ->ArgNames({"yaw", "noise"})
    ->ArgsProduct({{0, 90}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
BENCHMARK(BM_Render_Textured_HeldCube_Conformity)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK(BM_Render_HeldCube_Paced60Hz)
    ->ArgNames({"conformity", "rehearse_ms"})
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({1, 3})
    ->Args({1, 5})
    ->UseManualTime()
    ->Iterations(180)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Render_HeldCube_Stages)
    ->ArgName("paced")
    ->Arg(0)
    ->Arg(1)
    ->UseManualTime()
    ->Iterations(180)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Stage_Raster)->ArgNames({"cube", "uv"})->ArgsProduct({{0, 1}, {0, 1}})->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Stage_Overlay)->ArgName("cube")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Stage_Conformity)->ArgName("cube")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Stage_Gel)->ArgName("cube")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Stage_Shading)
    ->ArgNames({"cube", "noise"})
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
