#pragma once

#include <array>
#include <string>

#include <opencv2/core.hpp>

#include "norm2tex/render/sensor_model.hpp"

namespace norm2tex {

/// The calibrated DIGIT shading: a signed, per-channel linear response to per-pixel features
/// of the gel's deformation H (indentation after GelModel, mm, >= 0 into the gel):
///
///   diff_c(p) = gain * sum_j response_bgr[c][j] * feature_j(p)       (grey levels)
///
/// with gx = dH/dx, gy = dH/dy (central differences, mm over mm, so any resolution gives the
/// same; x to the image right, y down: the gel frame of SensorModel), B = H blurred with sigma
/// shadow_sigma_mm, bx, by its slopes, and u, v the pixel's position in [-1, 1] (image left /
/// top to right / bottom):
///
///    0-1  slope_x, slope_y             gx, gy: the first-order response to the normal (with
///                                      slope_saturation s > 0, both times
///                                      1 / sqrt(1 + (gx^2 + gy^2) / s^2), in 2-4 and 12-15 too)
///    2-4  slope_xx, slope_xy, slope_yy gx^2, gx gy, gy^2: second order (wide secondary-colour
///                                      zones of a real hue wheel)
///    5    depth                        H / 1 mm: the flat centre brightens or darkens by unit
///    6-7  rim_out, rim_in              max(B - H, 0), min(B - H, 0) (mm): a band just outside
///                                      the contact rim, and its crest inside
///    8-11 rim_right, rim_left,         max(bx, 0), max(-bx, 0), max(by, 0), max(-by, 0): the
///         rim_down, rim_up             blurred deformation rising towards a side; outside the
///                                      contact this is the neighbourhood that shadows the LED
///                                      on that side, so they draw the dark crescent real
///                                      sensors show just outside the rim (one-sided, so the
///                                      fit can darken one side without brightening the other)
///   12-15 slope_x*u ... slope_y*v      gx u, gx v, gy u, gy v
///   16-23 rim_right*u ... rim_up*v     each of 8-11 times u and times v
///
/// 12-23 let the response vary with the position in the image (first order, as Taxim's
/// per-bin polynomials do): each LED lights the gel from one edge, so a press near it shows
/// different colours and shadows than one at the centre. On the calibration set these take
/// the held-out variance explained from 0.66 to 0.79 and the rim shadow from half to 90 % of
/// the real one.
///
/// Why this form: summed clamped Lambertian terms can only add light, giving saturated sectors
/// with straight seams and no shadow; a signed response, fitted by least squares on ball
/// presses, brightens and darkens like a real sensor. Every feature is exactly 0 where the gel
/// is flat within the reach (shadingReachPixels) of the deformation, so the frame there is the
/// background. The dome of a curved gel is ignored: its own shading is part of the captured
/// background.
using ShadingFeatureArray = std::array<cv::Mat1f, kShadingFeatureCount>;

/// "slope_x, slope_y, ..." in the order above (for yaml comments and messages).
std::string shadingFeatureNames();

/// The response fitted on the MIT calibration set of one real DIGIT (digit_calibration_s09,
/// session sphere2: 49 presses of a 6 mm ball, at its measured 0.0532 mm/px, rim-shadow sigma
/// 0.6 mm, slope saturation 0.3 (kDefaultSlopeSaturation), norm2tex_calibrate); rows B, G, R.
std::array<std::array<double, kShadingFeatureCount>, 3> defaultShadingResponse();
/// The slope saturation defaultShadingResponse() was fitted with (and makeDigitSensorModel's).
constexpr double kDefaultSlopeSaturation = 0.3;

/// How far (pixels) beyond the last deformed pixel the features can be non-zero.
int shadingReachPixels(double mm_per_pixel, double shadow_sigma_mm);

/// Features of `gel_mm` (CV_32FC1, image size, finite) over `box` (inside the image), as
/// box-sized planes (reallocated only when the box size changes), with the shading's
/// shadow_sigma_mm and slope_saturation. One-sided differences at the image border; the blur
/// replicates the border.
void computeShadingFeatures(const cv::Mat1f& gel_mm, double mm_per_pixel,
                            const ShadingOptions& shading, const cv::Rect& box,
                            ShadingFeatureArray& features);

/// diff (CV_32FC3, box-sized) = gain * response applied to the features.
void applyShadingResponse(const ShadingFeatureArray& features, const ShadingOptions& shading,
                          cv::Mat3f& diff);

/// The same as computeShadingFeatures then applyShadingResponse (equal up to float rounding),
/// fused for the renderer: no feature planes; the position-dependent terms are folded into
/// per-row coefficients a + b u, and four pixels run at once (SIMD). `diff` is box-sized.
void computeShadingDifference(const cv::Mat1f& gel_mm, double mm_per_pixel,
                              const ShadingOptions& shading, const cv::Rect& box, cv::Mat3f& diff);

}  // namespace norm2tex
