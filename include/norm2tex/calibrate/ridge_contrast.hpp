#pragma once

#include <opencv2/core.hpp>

namespace norm2tex {

/// How a ridged press's texture contrast is measured (issue 38's real DIGIT measurement: a flat
/// disc with straight ridges ~11 px apart pressed at 1-12 N).
struct RidgeContrastOptions {
  /// A difference of Gaussians across the ridges only: these sigmas (px) along the axis normal
  /// to the ridges, none along them. Between them: the ridges' ~11 px pitch.
  double fine_sigma_px = 1.5;
  double coarse_sigma_px = 6.0;
  /// The direction normal to the ridges in the image, radians from the image's +x axis towards
  /// its +y axis: 0 for vertical ridges (they vary along x), pi / 2 for horizontal ones.
  double normal_angle_rad = 0.0;
};

/// What measureRidgeContrast found, grey levels.
struct RidgeContrast {
  double raw = 0.0;    ///< the band's RMS in the box (B, G, R in quadrature)
  double noise = 0.0;  ///< the same outside the contact (the noise floor); 0 without a noise box
  /// The texture's share: sqrt(max(0, raw^2 - noise^2)).
  double contrast = 0.0;
};

/// The ridges' contrast in `box` of frame - background: each channel filtered by the
/// difference of Gaussians across the ridges, its RMS over the box, the three channels summed
/// in quadrature (as the package's other texture measures); the noise floor measured the same
/// way in `noise_box` (outside the contact; empty: none) and removed in quadrature. The filter
/// runs on the whole frame (rotated so the ridges' normal is the x axis when normal_angle_rad is
/// not 0), so the boxes see no border effects when they lie 3 coarse sigmas inside it. Throws
/// Error for frames of different sizes or types, boxes not inside the frame, or sigmas that are
/// not 0 < fine < coarse.
RidgeContrast measureRidgeContrast(const cv::Mat3b& frame, const cv::Mat3b& background,
                                   const cv::Rect& box, const cv::Rect& noise_box = {},
                                   const RidgeContrastOptions& options = {});

}  // namespace norm2tex
