// The ridged press's contrast measure against analytic truth: a sinusoid's difference of
// Gaussians has a closed-form gain, noise removed in quadrature, any ridge direction alike.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "norm2tex/calibrate/ridge_contrast.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Background 100 everywhere; the frame adds amplitude * sin(2 pi u / pitch) on every channel,
// u the coordinate along the ridges' normal (angle from +x towards +y), plus Gaussian noise.
void ridged(double amplitude, double pitch_px, double angle, double noise_sigma, cv::Mat3b& frame,
            cv::Mat3b& background) {
  background = cv::Mat3b(240, 320, cv::Vec3b(100, 100, 100));
  cv::Mat3f f(background.size());
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.0f, static_cast<float>(noise_sigma));
  for (int y = 0; y < f.rows; ++y) {
    for (int x = 0; x < f.cols; ++x) {
      const double u = x * std::cos(angle) + y * std::sin(angle);
      const float v = static_cast<float>(100.0 + amplitude * std::sin(2.0 * kPi * u / pitch_px));
      f(y, x) = cv::Vec3f(v + noise(rng), v + noise(rng), v + noise(rng));
    }
  }
  f.convertTo(frame, CV_8UC3);
}

// The RMS of the band of a unit-amplitude sinusoid of `pitch` px, per channel: its DoG gain
// exp(-(s1 k)^2 / 2) - exp(-(s2 k)^2 / 2) over sqrt(2).
double sinusoidBandRms(double pitch_px, const RidgeContrastOptions& o) {
  const double k = 2.0 * kPi / pitch_px;
  return (std::exp(-0.5 * std::pow(o.fine_sigma_px * k, 2)) -
          std::exp(-0.5 * std::pow(o.coarse_sigma_px * k, 2))) /
         std::sqrt(2.0);
}

TEST(RidgeContrast, ASinusoidsContrastIsItsDifferenceOfGaussiansGain) {
  cv::Mat3b frame, background;
  const RidgeContrastOptions options;  // 1.5 and 6 px, ridges vertical
  for (const double pitch : {8.0, 11.0, 16.0}) {
    ridged(10.0, pitch, 0.0, 0.0, frame, background);
    const RidgeContrast c = measureRidgeContrast(frame, background, cv::Rect(120, 88, 80, 65));
    // Three channels in quadrature; 8-bit rounding adds ~0.3 grey levels of its own.
    const double expected = std::sqrt(3.0) * 10.0 * sinusoidBandRms(pitch, options);
    EXPECT_NEAR(c.raw, expected, 0.02 * expected + 0.3) << pitch;
    EXPECT_EQ(c.noise, 0.0);
    EXPECT_EQ(c.contrast, c.raw);
  }
  // Across the ridges only: the same ridges measured along them (the wrong normal) show none.
  ridged(10.0, 11.0, 0.0, 0.0, frame, background);
  RidgeContrastOptions along;
  along.normal_angle_rad = kPi / 2.0;
  EXPECT_LT(measureRidgeContrast(frame, background, cv::Rect(120, 88, 80, 65), {}, along).raw, 0.5);
}

TEST(RidgeContrast, NoiseIsRemovedInQuadratureAndAnyDirectionMeasuresAlike) {
  cv::Mat3b clean, noisy, background;
  ridged(6.0, 11.0, 0.0, 0.0, clean, background);
  ridged(6.0, 11.0, 0.0, 3.0, noisy, background);
  const cv::Rect box(120, 88, 80, 65);
  const RidgeContrast truth = measureRidgeContrast(clean, background, box);
  // The noise floor from a ridge-free region: a frame of noise only, the same generator.
  cv::Mat3b flat;
  ridged(0.0, 11.0, 0.0, 3.0, flat, background);
  cv::Mat3b combined = noisy.clone();
  flat(cv::Rect(0, 0, 100, 240)).copyTo(combined(cv::Rect(0, 0, 100, 240)));
  const RidgeContrast measured =
      measureRidgeContrast(combined, background, box, cv::Rect(20, 40, 60, 160));
  EXPECT_GT(measured.noise, 1.0);
  EXPECT_GT(measured.raw, truth.raw * 1.05);                    // the noise adds to the raw RMS...
  EXPECT_NEAR(measured.contrast, truth.raw, 0.05 * truth.raw);  // ...and is taken off again

  for (const double angle : {kPi / 2.0, 0.5236, 1.2}) {
    cv::Mat3b turned;
    ridged(6.0, 11.0, angle, 0.0, turned, background);
    RidgeContrastOptions o;
    o.normal_angle_rad = angle;
    EXPECT_NEAR(measureRidgeContrast(turned, background, box, {}, o).raw, truth.raw,
                0.04 * truth.raw)
        << angle;
  }
}

TEST(RidgeContrast, BadInputIsAClearError) {
  cv::Mat3b frame, background;
  ridged(6.0, 11.0, 0.0, 0.0, frame, background);
  test::expectError([&] { measureRidgeContrast(frame, background, cv::Rect(300, 200, 80, 65)); },
                    {"not inside the 320 x 240 frame"});
  test::expectError([&] { measureRidgeContrast(frame, cv::Mat3b(10, 10), cv::Rect(0, 0, 5, 5)); },
                    {"differ in size"});
  RidgeContrastOptions o;
  o.coarse_sigma_px = 1.0;
  test::expectError([&] { measureRidgeContrast(frame, background, cv::Rect(0, 0, 5, 5), {}, o); },
                    {"0 < fine < coarse"});
}

}  // namespace
}  // namespace norm2tex
