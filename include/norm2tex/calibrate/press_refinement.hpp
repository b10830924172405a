#pragma once

#include "norm2tex/calibrate/shading_fit.hpp"
#include "norm2tex/render/digit_shader.hpp"

namespace norm2tex {

/// Refines a press's contact circle against a shading model: the centre and radius (pixels)
/// whose ball press, rendered by `shader` (its response and scale), best matches the press's
/// difference in least squares over the pixels within kFitRegionRadii of `start`. A pattern
/// search from `start` (steps of 2 px and 4 %, halved three times). Why: the detector's
/// threshold contour is pulled towards the brighter side of a press and its radius bias
/// depends on where the press is (the response varies over the image), so one global radius
/// factor leaves each press a little off; estimating each press's geometry with the model (as
/// a label would give it) lets the fit see the shading rather than the geometry errors.
/// Throws Error if `start` does not fit the ball.
PressCircle refinePressCircle(const DigitShader& shader, const SensorModel& model,
                              const PressObservation& press, const PressCircle& start,
                              double ball_radius_mm);

}  // namespace norm2tex
