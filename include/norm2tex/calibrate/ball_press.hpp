#pragma once

#include <opencv2/core.hpp>

#include "norm2tex/calibrate/press_detection.hpp"
#include "norm2tex/render/sensor_model.hpp"

namespace norm2tex {

/// Indentation (mm, CV_32FC1 of the model's image size) of a rigid ball of `ball_radius_mm`
/// pressed into a flat gel so that its contact circle is `contact`: the depth follows from the
/// contact radius a (mm) as d = R - sqrt(R^2 - a^2), and H = d - (R - sqrt(R^2 - rho^2)) for
/// rho < a, 0 outside (rho: distance from the centre in mm at the model's mm_per_pixel).
/// Throws Error when a >= R (the ball is too small for that contact, or the scale too coarse).
cv::Mat1f ballPressIndentation(const SensorModel& model, const PressCircle& contact,
                               double ball_radius_mm);

/// How deep a rigid ball of `ball_radius_mm` presses into a flat gel to make a contact circle of
/// `contact_radius_mm`: R - sqrt(R^2 - a^2). Throws Error as ballPressIndentation when a >= R.
double ballPressDepthMm(double contact_radius_mm, double ball_radius_mm);

}  // namespace norm2tex
