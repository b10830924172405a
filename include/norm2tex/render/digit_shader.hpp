#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/render/sensor_model.hpp"

namespace norm2tex {

/// A synthetic DIGIT no-contact frame of `size` that resembles a real one: reddish upper-left,
/// green on the right, blue-violet lower side, smooth vignetting, mean BGR near (99, 105, 99).
/// Deterministic (no noise). Built from four smooth Gaussian glows, a base level and a radial
/// vignette in normalised coordinates, so any size works. Targets vs reached (BGR means, thirds
/// of the image): global (99, 105, 99) -> (98.5, 105.1, 99.0); top-left (117, 106, 133) ->
/// (114.6, 101.7, 132.6); top-right (105, 117, 73) -> (103.4, 116.4, 75.3); bottom-centre
/// (98, 92, 70) -> (97.7, 92.5, 66.6); centre (102, 123, 134) -> (103.6, 120.7, 130.5).
/// Throws Error for a non-positive size.
cv::Mat3b makeSyntheticBackground(cv::Size size);

/// The user's own no-contact frame, resized to the model's image size if needed. Accepts 8- or
/// 16-bit, gray, BGR or BGRA; throws Error naming the file if it cannot be used, including a
/// landscape frame for a portrait sensor (or the reverse): a frame the driver did not rotate.
cv::Mat3b loadBackground(const std::string& path, cv::Size size);

/// Turns the gel's final indentation into a DIGIT image.
///
/// Shading model. The membrane surface is z(x, y) = dome(x, y) - H(x, y) (gel frame, mm;
/// dome = 0 for a flat gel), so indentation moves it towards the camera. Its slopes come from
/// central differences of H_final in consistent units (dH in mm over mm_per_pixel per pixel;
/// one-sided at the image border). The LEDs light the membrane's inner side, whose normal is
/// n = (dz/dx, dz/dy, -1) / |.|. Each LED i, seen from the pixel's point on the undeformed
/// surface along the unit vector l_i, contributes
///   colour_i * intensity_i * w_i * max(0, n . l_i),   w_i = |LED_i| / |LED_i - p|
/// (Lambertian with a mild 1/d fall-off, 1 at the gel centre). Because the LEDs sit at grazing
/// angles behind the surface, a slope of an indentation facing an LED catches more of its light:
/// the top-left side of a press turns redder, the top-right greener, the bottom bluer.
///   x     = 360 * (shading(H) - shading(undeformed gel))      per channel, grey levels
///   image = background + shading_gain * x / (1 + |x| / 70) + noise
/// The soft knee (linear for small slopes, saturating towards 70 grey levels on steep ones)
/// reproduces real presses, which show colour across the whole contact rather than only a
/// bright rim: an 8.8 mm ball pressed 1.5 mm (after GelModel) gives a mean |frame -
/// background| of 29 grey levels inside the contact and a 95th percentile of 48, as measured
/// on real DIGIT ball presses (linear shading at the same mean gives a 95th percentile of 74).
///
/// Cost. Shading is computed only in the bounding box of the pixels with H != 0, grown by 2 px;
/// elsewhere the output is the background (+ noise) bit for bit. Noise is Gaussian with sigma
/// = noise_sigma, drawn over the whole frame in raster order from the seed with xoshiro256**
/// and a 4096-entry inverse-CDF table (five samples per 64-bit draw): fresh per frame,
/// identical for the same seed, cheap. It is added last and the result rounded and clipped to
/// bgr8. Thread-safe: shade() keeps no state between calls.
class DigitShader {
 public:
  /// `background` must have the model's image size (CV_8UC3).
  DigitShader(const SensorModel& model, cv::Mat3b background);

  /// `h_final_mm` CV_32FC1 of image size, indentation in mm (>= 0 into the gel), finite. With
  /// `noise_seed` < 0 no noise is added; otherwise the noise is drawn from that seed. Throws
  /// Error for a wrong size or NaN / infinite values.
  cv::Mat3b shade(const cv::Mat1f& h_final_mm, std::int64_t noise_seed) const;

  /// Shading difference only (float BGR, grey levels), before background and noise. For tests.
  cv::Mat3f shadingDifference(const cv::Mat1f& h_final_mm) const;

  const cv::Mat3b& background() const { return background_; }

 private:
  void checkHeight(const cv::Mat1f& h_final_mm) const;
  /// Pixels with H != 0, grown by the stencil margin and clipped; empty if there are none.
  cv::Rect contactBox(const cv::Mat1f& h) const;
  /// shading(H) - shading(flat) for the pixels of `box`, into `diff` (box-sized).
  void shadeBox(const cv::Mat1f& h, const cv::Rect& box, cv::Mat3f& diff) const;

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
  std::vector<float> noise_table_;        // sigma * normal quantiles; empty if sigma == 0
};

}  // namespace norm2tex
