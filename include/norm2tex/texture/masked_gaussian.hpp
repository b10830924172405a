#pragma once

#include <opencv2/core.hpp>

namespace norm2tex {

/// Mask-aware Gaussian filter of unit normals: each output normal is the Gaussian-weighted mean
/// of the *valid* normals around it (normalised convolution: blur(n * m) / blur(m)), then
/// renormalised to unit length. Invalid texels contribute nothing and stay (0, 0, 0), so
/// filtering never drags the flat "outside" into an island's border. sigma <= 0 copies.
/// The kernel radius is ceil(3 sigma) texels.
cv::Mat3f maskedGaussianNormals(const cv::Mat3f& normals, const cv::Mat1b& mask, double sigma);

}  // namespace norm2tex
