#pragma once

#include <string>

#include <opencv2/core.hpp>

#include "norm2tex/calibrate/press_detection.hpp"

namespace norm2tex {

/// The scale measured from two presses a known distance apart.
struct PressScale {
  double mm_per_pixel = 0.0;
  PressCircle first, second;  ///< the two contact circles found
  double distance_px = 0.0;   ///< between their centres
};

/// Ball presses do not pin a DIGIT's scale (the shading absorbs a change of it), but two presses
/// of anything at a known distance do: press the same ball (or a pin) twice, moved by
/// `distance_mm` along the gel between the frames (a caliper or a stage), and the distance
/// between the two contact centres in pixels gives mm per pixel. Each centre is found as the
/// calibration finds a press's (detectPress on the frame minus `background`), so its error is a
/// small fraction of a pixel; the longer the distance, the smaller the scale's relative error
/// (8 mm at 0.054 mm/px: 148 px). Throws Error naming the frame without a press, for frames of
/// another size than the background, a distance that is not finite and > 0, or centres closer
/// than 20 px (too short a baseline to measure a scale on).
PressScale measureScaleFromTwoPresses(const cv::Mat3b& background, const cv::Mat3b& first,
                                      const std::string& first_name, const cv::Mat3b& second,
                                      const std::string& second_name, double distance_mm);

}  // namespace norm2tex
