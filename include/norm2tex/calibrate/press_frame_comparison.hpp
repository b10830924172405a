#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/calibrate/image_metrics.hpp"
#include "norm2tex/calibrate/press_detection.hpp"

namespace norm2tex {

/// One press's calibrated render against its real frame, with what the calibration knows of the
/// press (the JSON report lists these).
struct PressFrameComparison {
  std::string name;
  int index = 0;                   ///< its position among the calibration's presses
  bool held_out = false;           ///< judged, not fitted
  bool labelled = false;           ///< circle given by a label (else detected, then refined)
  PressCircle circle;              ///< as labelled, or as detected and refined
  double contact_radius_px = 0.0;  ///< circle radius x the fit's radius factor: as rendered
  double depth_mm = 0.0;           ///< the ball's indentation that makes that contact
  /// Render vs the real frame as captured (its lighting drift, removed for the fit, counts
  /// against the render); ssim_in_mask: inside the contact disc of contact_radius_px.
  ImageSimilarity similarity;
  /// The background alone (a render without the press) against the same real frame: the
  /// baseline that shows what rendering the press adds. Most of a frame is untouched gel, so
  /// its whole-frame SSIM is already high; the contact's tells the two apart.
  ImageSimilarity bare_background;
};

/// Pixels (255) within `radius_px` of `centre` (pixel centres at integer coordinates).
cv::Mat1b contactDiscMask(cv::Size size, cv::Point2d centre, double radius_px);

/// The frame the calibrated model renders for a press: `background` plus the simulated shading
/// difference, rounded and saturated to 8 bits as a camera frame is.
cv::Mat3b renderedPressFrame(const cv::Mat3b& background, const cv::Mat3f& simulated_diff);

/// The median of each measure over `presses` (the mean of the two middle values for an even
/// count, as numpy's median) of the render (`measures` = &PressFrameComparison::similarity) or of
/// the baseline (&PressFrameComparison::bare_background); throws Error for none.
ImageSimilarity medianSimilarity(
    const std::vector<PressFrameComparison>& presses,
    ImageSimilarity PressFrameComparison::*measures = &PressFrameComparison::similarity);

}  // namespace norm2tex
