#pragma once

#include <algorithm>

#include <opencv2/core.hpp>

namespace norm2tex {

/// How many times QVGA resolution a frame of `size` has, by its short side: 1 for 320 x 240
/// whether portrait (a DIGIT's) or landscape (a GelSight Mini's), 2 for 640 x 480. The
/// calibration's pixel constants are stated at QVGA and scaled by it.
inline double qvgaScale(cv::Size size) { return std::min(size.width, size.height) / 240.0; }

}  // namespace norm2tex
