// Cost of the gel's lateral motion at 320 x 240 (one core): the shear stage alone (traction,
// Cerruti's field by FFT, markers placed), the markers' drawing, and whole frames of a sheared
// press with and without them, beside the same frame unsheared.
#include <memory>

#include <benchmark/benchmark.h>

#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/render/contact_rasterizer.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "norm2tex/shear/shear_field.hpp"

namespace {

// A 10 mm ball pressed 1 mm near the gel's centre (render_bench's scene), or the held cube's
// face over 3/4 of the gel; 1 N pushed along x and 2 N mm of twist on a 3 N press.
Eigen::Isometry3d pressPose(bool cube) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() =
      cube ? Eigen::Vector3d(0.0, -0.008, 0.014) : Eigen::Vector3d(0.0003, -0.0002, 0.004);
  return pose;
}

std::shared_ptr<const norm2tex::TexturedMesh> mesh(bool cube) {
  return std::make_shared<norm2tex::TexturedMesh>(
      cube ? norm2tex::makeBox(Eigen::Vector3d(0.03, 0.03, 0.03), 0.02)
           : norm2tex::makeUvSphere(0.005, 96, 192));
}

norm2tex::ShearLoad load() {
  norm2tex::ShearLoad l;
  l.force_n = {1.0, 0.3};
  l.torque_nm = 2e-3;
  return l;
}

// GelSight Mini's grid size on a DIGIT-sized image: 9 x 7 dots of 0.5 mm at 1.8 mm.
norm2tex::SensorModel model(bool markers) {
  norm2tex::SensorModel m = norm2tex::makeDigitSensorModel();
  m.markers.enabled = markers;
  m.markers.rows = 9;
  m.markers.cols = 7;
  return m;
}

void BM_Stage_Shear(benchmark::State& state) {
  const bool cube = state.range(0) != 0;
  const norm2tex::SensorModel m = model(state.range(1) != 0);
  norm2tex::ContactRasterizer rasterizer(m);
  norm2tex::ContactRaster raster;
  rasterizer.rasterize(*mesh(cube), pressPose(cube), 0.0, false, raster);
  norm2tex::ShearField shear(m);
  norm2tex::ShearFrame out;
  for (auto _ : state) {
    shear.compute(raster.h_sensor_mm, raster.covered_box, 3.0, load(), out);
    benchmark::DoNotOptimize(out.ux_mm.data);
  }
}

void BM_Stage_MarkerDrawing(benchmark::State& state) {
  const norm2tex::SensorModel m = model(true);
  norm2tex::ShearField shear(m);
  norm2tex::ShearFrame out;
  shear.rest(out);
  cv::Mat3b image(m.rows, m.cols, cv::Vec3b(180, 180, 180));
  for (auto _ : state) {
    shear.drawMarkers(image, out);
    benchmark::DoNotOptimize(image.data);
  }
}

// Whole frames: `shear` 0 unsheared, 1 sheared; `markers` 0/1.
void BM_Render_ShearedPress(benchmark::State& state) {
  const bool sheared = state.range(0) != 0;
  norm2tex::TactileRenderer renderer(model(state.range(1) != 0));
  renderer.setObject(mesh(false));
  const Eigen::Isometry3d pose = pressPose(false);
  const std::optional<norm2tex::ShearLoad> shear =
      sheared ? std::optional<norm2tex::ShearLoad>(load()) : std::nullopt;
  for (auto _ : state) {
    const norm2tex::TactileFrame& frame = renderer.render(pose, -1, 3.0, shear);
    benchmark::DoNotOptimize(frame.image.data);
  }
  state.counters["fps"] = benchmark::Counter(1.0, benchmark::Counter::kIsIterationInvariantRate);
}

BENCHMARK(BM_Stage_Shear)
    ->ArgNames({"cube", "markers"})
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Stage_MarkerDrawing)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Render_ShearedPress)
    ->ArgNames({"shear", "markers"})
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

}  // namespace
