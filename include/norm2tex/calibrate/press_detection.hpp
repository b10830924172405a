#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace norm2tex {

/// A ball press's contact circle in image pixels (column x, row y; pixel centres at integers).
struct PressCircle {
  cv::Point2d centre_px;
  double radius_px = 0.0;
};

/// Finds the contact circle of one ball press from its difference to the no-contact frame.
///
/// How: m = |B| + |G| + |R| of `diff` (frame - background, grey levels), blurred (sigma 2 px at
/// QVGA, scaled with the width) against JPEG and sensor noise; the baseline is m's median.
/// Pixels above baseline + 0.25 (peak - baseline) form the press; the largest connected region
/// is kept and its holes filled (the flat centre under the ball barely changes colour, so the
/// raw region is often a ring). A circle is fitted by algebraic least squares (Kasa) to the
/// region's outer contour, leaving out contour points on the image border, so a press cut by
/// the border still gets its full circle. The threshold contour lies near the rim; the
/// calibration fits one global factor on top of these radii, so a constant bias costs nothing.
///
/// Throws Error naming `frame_name` when there is no press: a peak under 12 grey levels (sum of
/// the three channels) above the baseline, a region under 30 pixels, or a contour too short
/// to fit.
PressCircle detectPress(const cv::Mat3f& diff, const std::string& frame_name);

}  // namespace norm2tex
