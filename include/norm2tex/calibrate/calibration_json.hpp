#pragma once

#include <string>

#include "norm2tex/calibrate/sensor_calibration.hpp"

namespace norm2tex {

/// The calibration as a machine-readable report (JSON text): the ball, the fitted scale, radius
/// factor and rim shadow; for the held-out and for the fitted presses their count, variance
/// explained and the medians of the frame measures (PressFrameComparison: ssim, contact_ssim,
/// psnr_db, mean_abs_diff) of the render ("median") and of the bare background
/// ("median_bare_background"); and every press in input order: image, held_out, labelled, its
/// circle (centre_x_px, centre_y_px, radius_px: as labelled, or detected and refined),
/// contact_radius_px and depth_mm as rendered, its four measures and, under bare_background,
/// the baseline's. A PSNR of identical frames (infinite) is written as null.
std::string calibrationReportJson(const CalibrationResult& result, double ball_diameter_mm);

/// Checks, before a calibration's minutes of work, that a report can go to `path`: its directory
/// exists and is writable and `path` is not a directory. Throws Error naming the path and why.
void checkJsonReportPath(const std::string& path);

/// Writes calibrationReportJson to `path`; throws Error naming the path and the reason when it
/// cannot be written.
void writeCalibrationReportJson(const std::string& path, const CalibrationResult& result,
                                double ball_diameter_mm);

}  // namespace norm2tex
