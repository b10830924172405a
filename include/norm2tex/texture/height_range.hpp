#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace norm2tex {

/// Target range of H_global. The texture is later added as beta * H_local to the indentation,
/// so the range says what the texture does to the object's surface.
enum class HeightRange {
  kRemove,     ///< [0, -1]: peaks at 0, valleys to -1 (grooves, pores: texture removes material)
  kSymmetric,  ///< [-1, 1]: both
  kAdd,        ///< [0, 1]: valleys at 0, peaks to +1 (texture adds material)
};

/// Parses "0,-1" / "-1,1" / "0,1" (also "remove" / "symmetric" / "add"); throws Error listing
/// the valid spellings otherwise.
HeightRange parseHeightRange(const std::string& text);
std::string toString(HeightRange range);  ///< "0,-1", "-1,1" or "0,1"
/// Lowest and highest value of the range, e.g. (-1, 0) for kRemove.
cv::Vec2f rangeBounds(HeightRange range);

/// Values of `height` at the given percentiles (0..100) over the texels where `mask` != 0.
/// Percentiles interpolate linearly between order statistics. Throws Error on an empty mask.
cv::Vec2f maskedPercentiles(const cv::Mat1f& height, const cv::Mat1b& mask, double low_percent,
                            double high_percent);

/// Maps [low, high] linearly onto `range`, clamping values outside, on texels where `mask` != 0;
/// other texels become 0. A flat map (high - low <= 1e-4 texel, below 16-bit normal-map
/// quantisation, or not finite) becomes 0 everywhere: a texture without relief adds nothing.
void normalizeToRange(cv::Mat1f& height, const cv::Mat1b& mask, cv::Vec2f low_high,
                      HeightRange range);

}  // namespace norm2tex
