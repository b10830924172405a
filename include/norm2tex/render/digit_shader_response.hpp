#pragma once

#include <array>
#include <string>

#include <opencv2/core.hpp>

#include "norm2tex/render/sensor_model.hpp"

namespace norm2tex {

/// The calibrated DIGIT shading: a signed, per-channel linear response to a few per-pixel
/// features of the gel's deformation H (indentation after GelModel, mm, >= 0 into the gel):
///
///   diff_c(p) = gain * sum_j response_bgr[c][j] * feature_j(p)       (grey levels)
///
///   0 slope_x     dH/dx    central differences, mm over mm (so any resolution gives the same)
///   1 slope_y     dH/dy    (x to the image right, y down: the gel frame of SensorModel)
///   2 slope_xx    (dH/dx)^2
///   3 slope_xy    dH/dx * dH/dy
///   4 slope_yy    (dH/dy)^2    (with 0-2 a second-order polynomial in the surface normal)
///   5 depth       H / 1 mm     the flat centre of a press brightens or darkens by unit
///   6 rim         (B - H) / 1 mm, B = H blurred with sigma shadow_sigma_mm: positive in a band
///                 just outside the contact rim, negative on its crest
///   7 rim_slope_x dB/dx        the blurred deformation's slopes reach past the rim: a pixel
///   8 rim_slope_y dB/dy        whose neighbourhood rises towards an LED lies in that LED's
///                              shadow, so these (fitted per channel) draw the dark crescent
///                              real sensors show just outside the contact.
///
/// Why this form: summed clamped Lambertian terms can only add light, giving saturated sectors
/// with straight seams and no shadow; a signed response to the slopes, fitted by least squares
/// on ball presses, explains 56-71 % of the held-out pixel variance on real units. Every
/// feature is exactly 0 where the gel is flat within the reach (shadingReachPixels) of the
/// deformation, so the frame there is the background. The dome of a curved gel is ignored:
/// its own shading is part of the captured background.
using ShadingFeatureArray = std::array<cv::Mat1f, kShadingFeatureCount>;

/// "slope_x, slope_y, ..." in the order above (for yaml comments and messages).
std::string shadingFeatureNames();

/// The response fitted on the MIT calibration set of one real DIGIT (digit_calibration_s09,
/// 6 mm ball, norm2tex_calibrate); rows B, G, R.
std::array<std::array<double, kShadingFeatureCount>, 3> defaultShadingResponse();

/// How far (pixels) beyond the last deformed pixel the features can be non-zero.
int shadingReachPixels(double mm_per_pixel, double shadow_sigma_mm);

/// Features of `gel_mm` (CV_32FC1, image size, finite) over `box` (inside the image), as
/// box-sized planes (reallocated only when the box size changes). One-sided differences at the
/// image border; the blur replicates the border.
void computeShadingFeatures(const cv::Mat1f& gel_mm, double mm_per_pixel, double shadow_sigma_mm,
                            const cv::Rect& box, ShadingFeatureArray& features);

/// diff (CV_32FC3, box-sized) = gain * response applied to the features.
void applyShadingResponse(const ShadingFeatureArray& features, const ShadingOptions& shading,
                          cv::Mat3f& diff);

}  // namespace norm2tex
