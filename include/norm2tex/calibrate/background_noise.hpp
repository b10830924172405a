#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/render/sensor_model.hpp"

namespace norm2tex {

/// The sensor's pixel noise, measured on its no-contact frames (CV_8UC3, one size), as the
/// NoiseOptions that make DigitShaderNoise look the same.
///
/// How: the frames' high-pass residual r = frame - GaussianBlur(frame, sigma 3 px at QVGA)
/// removes the LED glows but also part of the noise, more so the more correlated it is. So the
/// residual's per-channel sigma, neighbour correlation and cross-channel correlations are
/// measured, and the model parameters are those whose own noise, high-passed the same way,
/// gives the same residual statistics (the neighbour correlation by interpolation over a grid
/// of 0-0.7, then the sigmas scaled by the residual-to-raw ratio at that correlation).
/// Cross-channel correlations are shrunk towards 0 if needed to stay positive definite.
/// Throws Error for no frames, frames of different sizes or smaller than 16 x 16.
NoiseOptions measureBackgroundNoise(const std::vector<cv::Mat3b>& backgrounds);

}  // namespace norm2tex
