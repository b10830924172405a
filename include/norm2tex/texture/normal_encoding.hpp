#pragma once

#include <opencv2/core.hpp>

#include "norm2tex/texture/normal_map.hpp"

namespace norm2tex {

/// Encodes height gradients (image frame, height units per texel: dx = dh/dcolumn,
/// dy = dh/drow) as a tangent-space normal map image in OpenCV channel order (BGR), the
/// inverse of NormalMap's decoding: n = normalize(-dx, -dy, 1), c = (n + 1) / 2, green
/// negated for OpenGL. `depth` is CV_8U or CV_16U. Texels where `mask` is 0 are encoded as the
/// flat normal (0, 0, 1); pass an empty mask for "all valid".
cv::Mat encodeNormalMap(const cv::Mat1f& dx, const cv::Mat1f& dy, NormalConvention convention,
                        int depth, const cv::Mat1b& mask = cv::Mat1b());

/// Same, from a height field in texel units: gradients by central differences (one-sided at
/// the border and at mask edges, so slopes never straddle two UV islands). With `with_alpha`
/// the image is BGRA, alpha full scale where `mask` is set (everywhere if it is empty) and 0
/// elsewhere: the layout NormalMap reads as "valid".
cv::Mat encodeNormalMapFromHeight(const cv::Mat1f& height, NormalConvention convention, int depth,
                                  const cv::Mat1b& mask = cv::Mat1b(), bool with_alpha = false);

}  // namespace norm2tex
