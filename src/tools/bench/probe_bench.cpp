// The probe dataset's render, one core: the shipped DIGIT on the 30 mm cube with one variant of
// a material, frame after frame of the seeded press-and-slide sequence. Every press lands on a
// new random point, so its texels are not in cache (unlike the BM_Render_* loops, which render
// one pose again and again). BM_Render_Probe/<material>: whole frames; BM_Overlay_Probe: the
// texture overlay alone (H_local look-ups), on the same frames' rasters.
#include <memory>
#include <vector>

#include <benchmark/benchmark.h>

#include "norm2tex/common/memory_reuse.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/materials/material_texture.hpp"
#include "norm2tex/mesh/object_mesh.hpp"
#include "norm2tex/render/contact_rasterizer.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "norm2tex/render/texture_overlay.hpp"
#include "norm2tex/sim/probe_scenario.hpp"
#include "package_paths.hpp"

namespace {

struct ProbeScene {
  explicit ProbeScene(const std::string& material) {
    norm2tex::keepFreedMemoryForReuse();  // as the nodes do
    config = norm2tex::loadMaterialConfig(norm2tex::cli::materialConfigPath(material));
    sensor = norm2tex::loadSensorModel(norm2tex::cli::configDirectory() + "/digit.yaml");
    auto cube = std::make_shared<norm2tex::TexturedMesh>(
        norm2tex::loadObjectMesh("box:30x30x30", 1.0).mesh);
    atlas = std::make_shared<const norm2tex::HeightAtlas>(
        norm2tex::bakeMaterialAtlas(config, 0, *cube, 4, 1));  // on the cube's UVs, as the dataset
    mesh = cube;
    norm2tex::ProbeScenario scenario(*mesh, norm2tex::ProbeConfig{}, sensor, 0);
    for (std::uint64_t press = 0; frames.size() < 2000; ++press) {
      for (const norm2tex::ProbeFrame& frame : scenario.press(press)) {
        frames.push_back(frame.object_in_gel);
      }
    }
  }
  norm2tex::MaterialConfig config;
  norm2tex::SensorModel sensor;
  std::shared_ptr<const norm2tex::TexturedMesh> mesh;
  std::shared_ptr<const norm2tex::HeightAtlas> atlas;
  std::vector<Eigen::Isometry3d> frames;
};

void BM_Render_Probe(benchmark::State& state, const std::string& material) {
  const ProbeScene scene(material);
  norm2tex::TactileRenderer renderer(scene.sensor);
  renderer.setObject(scene.mesh, scene.atlas, scene.config.beta_mm);
  std::size_t frame = 0;
  double contact_pixels = 0.0;
  for (auto _ : state) {
    const norm2tex::TactileFrame& out =
        renderer.render(scene.frames[frame % scene.frames.size()], static_cast<int>(frame));
    contact_pixels += cv::countNonZero(out.contact_mask);
    ++frame;
  }
  state.counters["fps"] = benchmark::Counter(1.0, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["contact_px"] =
      benchmark::Counter(contact_pixels, benchmark::Counter::kAvgIterations);
}

void BM_Overlay_Probe(benchmark::State& state, const std::string& material) {
  const ProbeScene scene(material);
  norm2tex::ContactRasterizer rasterizer(scene.sensor);
  const norm2tex::TextureOverlay overlay(scene.atlas, scene.config.beta_mm);
  norm2tex::ContactRaster raster;
  cv::Mat1f h_final;
  std::size_t frame = 0;
  double sampled = 0.0;
  for (auto _ : state) {
    state.PauseTiming();  // the raster does not touch the atlas
    rasterizer.rasterize(*scene.mesh, scene.frames[frame++ % scene.frames.size()],
                         overlay.reachMm(), true, raster);
    if (state.range(0) != 0) overlay.apply(raster, scene.sensor.gel_thickness_mm, h_final);
    state.ResumeTiming();
    overlay.apply(raster, scene.sensor.gel_thickness_mm, h_final);
    sampled += raster.covered_box.area();
  }
  state.counters["box_px"] = benchmark::Counter(sampled, benchmark::Counter::kAvgIterations);
}

}  // namespace

BENCHMARK_CAPTURE(BM_Render_Probe, wood, std::string("wood"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Render_Probe, print3d, std::string("print3d"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Render_Probe, smooth, std::string("smooth"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Overlay_Probe, wood, std::string("wood"))
    ->ArgName("warm")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Overlay_Probe, print3d, std::string("print3d"))
    ->ArgName("warm")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Overlay_Probe, smooth, std::string("smooth"))
    ->ArgName("warm")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMicrosecond);
