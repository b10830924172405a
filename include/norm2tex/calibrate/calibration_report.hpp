#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/calibrate/sensor_calibration.hpp"

namespace norm2tex {

/// A side-by-side picture of a calibration: for up to `max_presses` held-out presses, one row
/// of three crops around the press (2 x 1.6 contact radii, each scaled to 160 x 160):
/// the real frame | the calibrated render (background + simulated difference) | real minus
/// render, amplified 2x around grey 128. Above them, the held-out fit figures as text.
cv::Mat3b makeCalibrationReport(const CalibrationResult& result, int max_presses = 4);

/// The fit figures as lines of text (for the report image and the tool's output): the held-out
/// presses' measures, then the medians of the frame measures of held-out and fitted presses.
std::vector<std::string> describeFitQuality(const CalibrationResult& result);

/// When the scale was searched: how well each scale of the coarse grid fits, and the range of
/// those within kScaleIndifference of the best, as lines of text; empty otherwise.
std::vector<std::string> describeScaleSearch(const ShadingFit& fit);

}  // namespace norm2tex
