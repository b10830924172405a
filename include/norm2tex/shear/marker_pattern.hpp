#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/render/sensor_model.hpp"

namespace norm2tex {

/// One printed dot: where it sits on the undeformed gel and where the gel has carried it.
struct Marker {
  cv::Point2f rest_px;         ///< image position at rest (x = column, y = row, pixel centres)
  cv::Point2f current_px;      ///< image position now
  cv::Point2f displacement_mm; ///< current - rest on the gel, mm (gel frame x, y)
};

/// The sensor's marker grid (MarkerOptions): rest positions on a rows x cols grid of the given
/// pitch, centred on the image plus the offset, each jittered by a seeded uniform +-jitter_mm;
/// and their drawing: each dot takes `darkness` of the light at its centre, a disc of the dot's
/// diameter with a Gaussian edge of blur_mm, so a dot carried half a pixel moves by half a
/// pixel in the image.
class MarkerPattern {
 public:
  /// Throws Error when the model's marker options are not valid.
  explicit MarkerPattern(const SensorModel& model);

  const std::vector<cv::Point2f>& restPx() const { return rest_px_; }

  /// Darkens `image` (bgr8) at every centre (pixels); dots partly outside are clipped, dots
  /// wholly outside drawn not at all. Overlapping dots multiply.
  void draw(cv::Mat3b& image, const std::vector<Marker>& markers) const;

 private:
  std::vector<cv::Point2f> rest_px_;
  double radius_px_ = 0.0;    // the dot's radius
  double reach_px_ = 0.0;     // how far from its centre a dot darkens anything
  double darkness_ = 0.0;
  // (1 - darkness * coverage) * 2^15, tabulated against the squared distance from the dot's
  // centre in steps of 1/64 px^2 (a disc's blurred edge costs one lookup per pixel, not an erfc).
  std::vector<std::int32_t> transmission_;
};

}  // namespace norm2tex
