#include "norm2tex/texture/height_range.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/error_messages.hpp"
#include "norm2tex/common/error.hpp"

namespace norm2tex {

HeightRange parseHeightRange(const std::string& text) {
  std::string value;
  for (char c : text) {
    if (c != ' ' && c != '[' && c != ']') value += static_cast<char>(std::tolower(c));
  }
  if (value == "0,-1" || value == "-1,0" || value == "remove") return HeightRange::kRemove;
  if (value == "-1,1" || value == "symmetric") return HeightRange::kSymmetric;
  if (value == "0,1" || value == "add") return HeightRange::kAdd;
  throw Error("unknown height range '" + text +
              "'; valid: 0,-1 (remove), -1,1 (symmetric), 0,1 (add)");
}

std::string toString(HeightRange range) {
  switch (range) {
    case HeightRange::kRemove:
      return "0,-1";
    case HeightRange::kSymmetric:
      return "-1,1";
    case HeightRange::kAdd:
      return "0,1";
  }
  return "?";
}

cv::Vec2f rangeBounds(HeightRange range) {
  switch (range) {
    case HeightRange::kRemove:
      return {-1.0f, 0.0f};
    case HeightRange::kSymmetric:
      return {-1.0f, 1.0f};
    case HeightRange::kAdd:
      return {0.0f, 1.0f};
  }
  return {0.0f, 0.0f};
}

cv::Vec2f maskedPercentiles(const cv::Mat1f& height, const cv::Mat1b& mask, double low_percent,
                            double high_percent) {
  detail::requireParameter(
      0.0 <= low_percent && low_percent < high_percent && high_percent <= 100.0, "percentiles",
      std::to_string(low_percent) + "," + std::to_string(high_percent), "0 <= low < high <= 100");
  std::vector<float> values;
  values.reserve(static_cast<size_t>(cv::countNonZero(mask)));
  for (int r = 0; r < height.rows; ++r) {
    const float* h = height.ptr<float>(r);
    const uchar* ok = mask.ptr<uchar>(r);
    for (int c = 0; c < height.cols; ++c) {
      if (ok[c] && std::isfinite(h[c])) values.push_back(h[c]);
    }
  }
  if (values.empty()) throw Error("percentiles of an empty set: no valid texel");
  // Linear interpolation between the order statistics around rank p (n - 1) / 100.
  const auto percentile = [&values](double percent) {
    const double rank = percent / 100.0 * static_cast<double>(values.size() - 1);
    const size_t below = static_cast<size_t>(std::floor(rank));
    std::nth_element(values.begin(), values.begin() + below, values.end());
    const float low = values[below];
    if (below + 1 >= values.size()) return low;
    const float high = *std::min_element(values.begin() + below + 1, values.end());
    return static_cast<float>(low + (rank - below) * (high - low));
  };
  const float low = percentile(low_percent);
  const float high = percentile(high_percent);
  return {low, high};
}

void normalizeToRange(cv::Mat1f& height, const cv::Mat1b& mask, cv::Vec2f low_high,
                      HeightRange range) {
  const cv::Vec2f bounds = rangeBounds(range);
  const float low = low_high[0], high = low_high[1];
  // Relief below 1e-4 texel is under even 16-bit normal quantisation (3e-5 slope per texel):
  // it is rounding noise, and stretching it to the full range would invent a texture.
  constexpr float kFlatRelief = 1e-4f;
  const bool flat = !(high - low > kFlatRelief) || !std::isfinite(high - low);
  const float scale = flat ? 0.0f : (bounds[1] - bounds[0]) / (high - low);
  for (int r = 0; r < height.rows; ++r) {
    float* h = height.ptr<float>(r);
    const uchar* ok = mask.ptr<uchar>(r);
    for (int c = 0; c < height.cols; ++c) {
      if (!ok[c] || flat || !std::isfinite(h[c])) {
        h[c] = 0.0f;
        continue;
      }
      h[c] = std::clamp(bounds[0] + (h[c] - low) * scale, bounds[0], bounds[1]);
    }
  }
}

}  // namespace norm2tex
