#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/render/digit_shader_noise.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/render/synthetic_background.hpp"

namespace norm2tex {

/// The user's own no-contact frame, resized to the model's image size if needed. Accepts 8- or
/// 16-bit, gray, BGR or BGRA; throws Error naming the file if it cannot be used, including a
/// landscape frame for a portrait sensor (or the reverse): a frame the driver did not rotate.
cv::Mat3b loadBackground(const std::string& path, cv::Size size);

/// Where a background comes from: a captured frame already carries the sensor's noise.
enum class BackgroundSource { kSynthetic, kCaptured };

/// Turns the gel's final deformation into a DIGIT image:
///   image = background + shading difference + noise     (rounded, clipped to bgr8)
///
/// Shading (SensorModel::shading.kind):
/// - calibrated (default): the signed per-channel response to the gel's slopes, depth and rim
///   of digit_shader_response.hpp, fitted to a real sensor by norm2tex_calibrate. It brightens
///   and darkens (a dark shadow crescent just outside the contact rim), colouring a press like
///   a smooth hue wheel as real units do.
/// - analytic_leds: the earlier analytic model. The membrane surface is z = dome - H; its
///   inner normal n = (dz/dx, dz/dy, -1) / |.|; each LED i, seen from the pixel along l_i,
///   contributes colour_i * intensity_i * w_i * max(0, n . l_i), w_i = |LED_i| / |LED_i - p|;
///     x = 205 * (shading(H) - shading(undeformed gel)),  diff = gain * x / (1 + |x| / 300).
///   It can only add light (no shadows) and draws three saturated sectors.
///
/// Cost. Shading is computed only in the bounding box of the pixels with H != 0, grown by the
/// shading's reach; elsewhere the output is the background (+ noise) bit for bit.
///
/// Noise (DigitShaderNoise): none on a captured background unless
/// noise.on_real_background, since the frame already carries the sensor's own noise; on a
/// synthetic background, correlated per-channel noise drawn from the seed over the whole frame
/// (a pixel's noise depends only on the seed and its position). Thread-safe: shade() keeps no
/// state between calls.
class DigitShader {
 public:
  /// `background` must have the model's image size (CV_8UC3).
  DigitShader(const SensorModel& model, cv::Mat3b background, BackgroundSource source);

  /// `h_final_mm` CV_32FC1 of image size, indentation in mm (>= 0 into the gel), finite. With
  /// `noise_seed` < 0 no noise is added; otherwise the noise is drawn from that seed. Throws
  /// Error for a wrong size or NaN / infinite values.
  cv::Mat3b shade(const cv::Mat1f& h_final_mm, std::int64_t noise_seed) const;

  /// Shading difference only (float BGR, grey levels), before background and noise. For tests.
  cv::Mat3f shadingDifference(const cv::Mat1f& h_final_mm) const;

  const cv::Mat3b& background() const { return background_; }
  /// Whether shade() with a seed >= 0 adds noise (see the class comment).
  bool addsNoise() const { return noise_.enabled() && adds_noise_; }
  /// How far (pixels) beyond the deformed pixels the shading difference can be non-zero.
  int reachPixels() const { return reach_px_; }

 private:
  void checkHeight(const cv::Mat1f& h_final_mm) const;
  /// Pixels with H != 0, grown by the stencil margin and clipped; empty if there are none.
  cv::Rect contactBox(const cv::Mat1f& h) const;
  /// The shading difference for the pixels of `box`, into `diff` (box-sized).
  void shadeBox(const cv::Mat1f& h, const cv::Rect& box, cv::Mat3f& diff) const;
  /// analytic_leds: shading(H) - shading(flat) for the pixels of `box`.
  void shadeBoxAnalytic(const cv::Mat1f& h, const cv::Rect& box, cv::Mat3f& diff) const;

  SensorModel model_;
  cv::Mat3b background_;
  // Per pixel, precomputed once, as planes (structure of arrays, for SIMD) with a few spare
  // columns: the unit vector towards each LED times its fall-off weight ([3 * led + xyz]), the
  // undeformed gel's shading (grey levels, BGR) and the dome's slopes dz/dx, dz/dy (empty for
  // a flat gel).
  std::array<cv::Mat1f, 9> light_planes_;
  std::array<cv::Mat1f, 3> flat_planes_;
  std::array<cv::Mat1f, 2> dome_planes_;
  std::array<cv::Vec3f, 3> led_colours_;  // colour * intensity * shading scale
  DigitShaderNoise noise_;
  bool adds_noise_ = true;  // false on a captured background (unless asked for)
  int reach_px_ = 2;
};

}  // namespace norm2tex
