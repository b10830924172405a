// The shading stage alone at QVGA (one core): the calibrated response with its rim shadows
// against the analytic LED model it replaces, on two ball presses through the GelModel, on a
// captured background (no noise, as by default) and on the synthetic one (with noise).
#include <cmath>

#include <benchmark/benchmark.h>

#include "norm2tex/calibrate/ball_press.hpp"
#include "norm2tex/render/digit_shader.hpp"
#include "norm2tex/render/gel_model.hpp"

namespace {

// Contact radius 1.5 mm of a 6 mm ball (the calibration set's presses) or 3.3 mm of an
// 8.8 mm ball pressed 1.5 mm (the press the real-capture statistics were measured on).
cv::Mat1f pressGel(const norm2tex::SensorModel& model, bool large) {
  const double contact_mm = large ? 3.3 : 1.5, ball_mm = large ? 4.4 : 3.0;
  const norm2tex::PressCircle circle{{0.5 * model.cols - 0.5 + 6, 0.5 * model.rows - 0.5 - 9},
                                     contact_mm / model.mm_per_pixel};
  cv::Mat1f gel;
  norm2tex::GelModel(model).apply(norm2tex::ballPressIndentation(model, circle, ball_mm), gel);
  return gel;
}

void shadingLoop(benchmark::State& state, norm2tex::ShadingKind kind, bool noise) {
  norm2tex::SensorModel model = norm2tex::makeDigitSensorModel();
  model.shading.kind = kind;
  const cv::Mat1f gel = pressGel(model, state.range(0) != 0);
  const norm2tex::DigitShader shader(
      model, norm2tex::makeSyntheticBackground(model),
      noise ? norm2tex::BackgroundSource::kSynthetic : norm2tex::BackgroundSource::kCaptured);
  std::int64_t seed = 0;
  for (auto _ : state) {
    cv::Mat3b image = shader.shade(gel, seed++);
    benchmark::DoNotOptimize(image.data);
  }
}

void BM_Shading_Calibrated(benchmark::State& state) {
  shadingLoop(state, norm2tex::ShadingKind::kCalibrated, false);
}
void BM_Shading_AnalyticLeds(benchmark::State& state) {
  shadingLoop(state, norm2tex::ShadingKind::kAnalyticLeds, false);
}
void BM_Shading_Calibrated_SyntheticBackgroundWithNoise(benchmark::State& state) {
  shadingLoop(state, norm2tex::ShadingKind::kCalibrated, true);
}

BENCHMARK(BM_Shading_Calibrated)->ArgName("large")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Shading_AnalyticLeds)->ArgName("large")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Shading_Calibrated_SyntheticBackgroundWithNoise)
    ->ArgName("large")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMicrosecond);

}  // namespace
