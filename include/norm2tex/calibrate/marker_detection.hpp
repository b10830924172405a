#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/render/sensor_model.hpp"

namespace norm2tex {

/// The printed dots of a marker gel (GelSight Mini's) found in a no-contact frame.
struct DetectedMarkers {
  std::vector<cv::Point2f> centres_px;  ///< each dot's centre (x = column, y = row)
  cv::Mat1b mask;           ///< 255 over every dot and a margin (what inpainting replaces)
  double pitch_px = 0.0;    ///< median distance to the nearest dot
  double diameter_px = 0.0; ///< median diameter at half the dot's darkness
  double darkness = 0.0;    ///< median fraction of the light a dot takes at its centre
  int rows = 0, cols = 0;   ///< the grid, counted along y and x
  cv::Point2f grid_centre_px;  ///< the middle of the grid's extreme rows and columns

  bool found() const { return !centres_px.empty(); }
  /// The layout in the sensor yaml's terms (markers:), at the given scale.
  MarkerOptions options(const SensorModel& model, double mm_per_pixel) const;
};

/// Finds the dots: darkness 1 - grey / (the frame with dark specks closed away), components
/// darker than kMarkerDarkness, dot-shaped and of one size; kept only when at least 9 of them
/// lie on a grid (most nearest-neighbour distances within 20 % of their median). A frame without
/// markers (a DIGIT's) gives none.
DetectedMarkers detectMarkers(const cv::Mat3b& frame);

/// `frame` with the masked pixels filled from their surroundings (a normalised Gaussian
/// convolution of the unmasked pixels, sigma about a dot's radius): a marker-free frame the
/// shading can be fitted on. `mask` empty: the frame unchanged.
cv::Mat3b withoutMarkers(const cv::Mat3b& frame, const cv::Mat1b& mask, double sigma_px);

/// Takes a marker gel's dots out of its frames: the light each dot lets through, measured on the
/// background (the background over its own fill, withoutMarkers, per channel), divides every
/// frame where it lets through at least kMarkerDivisible, so the shading under a dot is recovered
/// rather than guessed; the dots' dark cores, where dividing would amplify noise, are filled from
/// around them. Exact for dots that stay put (a pure press moves none); a dot a press moves
/// leaves an edge of a pixel or two.
class MarkerRemoval {
 public:
  MarkerRemoval(const cv::Mat3b& background, const DetectedMarkers& markers);
  cv::Mat3b apply(const cv::Mat3b& frame) const;

 private:
  cv::Mat1b mask_;          // the dots
  cv::Mat3f transmission_;  // per channel, 1 outside the dots
  cv::Mat1b core_;          // where the transmission is too low to divide by
  double sigma_px_ = 1.5;
};

/// The least transmission a frame is divided by (a dot's core is darker: filled instead).
constexpr double kMarkerDivisible = 0.3;

/// Darker than this fraction of the surrounding light counts as a dot.
constexpr double kMarkerDarkness = 0.2;

}  // namespace norm2tex
