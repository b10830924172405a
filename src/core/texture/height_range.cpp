#include "norm2tex/texture/height_range.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
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

namespace {

/// Finite masked values of `height`, located by order statistic through a histogram: two
/// passes over the map plus a sort of one bin, instead of copying every value and partially
/// sorting them (a 2048 x 2048 atlas: 16 MB of copies and two nth_element over 4 M values).
class OrderStatistics {
 public:
  OrderStatistics(const cv::Mat1f& height, const cv::Mat1b& mask) : height_(height), mask_(mask) {
    forEachValue([this](float value) {
      low_ = std::min(low_, value);
      high_ = std::max(high_, value);
      ++count_;
    });
    if (count_ == 0) return;
    scale_ = high_ > low_ ? kBins / (static_cast<double>(high_) - low_) : 0.0;
    counts_.assign(kBins + 1, 0);
    forEachValue([this](float value) { ++counts_[bin(value)]; });
  }

  size_t count() const { return count_; }

  /// The k-th smallest value (0-based), exact.
  float at(size_t k) {
    size_t below = 0;
    int b = 0;
    while (below + counts_[b] <= k) below += counts_[b++];
    if (b != cached_bin_) {
      cached_values_.clear();
      forEachValue([this, b](float value) {
        if (bin(value) == b) cached_values_.push_back(value);
      });
      std::sort(cached_values_.begin(), cached_values_.end());
      cached_bin_ = b;
    }
    return cached_values_[k - below];
  }

 private:
  static constexpr int kBins = 1 << 16;

  template <typename F>
  void forEachValue(F visit) const {
    for (int r = 0; r < height_.rows; ++r) {
      const float* h = height_.ptr<float>(r);
      const uchar* ok = mask_.ptr<uchar>(r);
      for (int c = 0; c < height_.cols; ++c) {
        if (ok[c] && std::isfinite(h[c])) visit(h[c]);
      }
    }
  }
  int bin(float value) const {
    return std::min(kBins, static_cast<int>((static_cast<double>(value) - low_) * scale_));
  }

  const cv::Mat1f& height_;
  const cv::Mat1b& mask_;
  float low_ = std::numeric_limits<float>::infinity();
  float high_ = -std::numeric_limits<float>::infinity();
  size_t count_ = 0;
  double scale_ = 0.0;
  std::vector<size_t> counts_;
  int cached_bin_ = -1;
  std::vector<float> cached_values_;
};

}  // namespace

cv::Vec2f maskedPercentiles(const cv::Mat1f& height, const cv::Mat1b& mask, double low_percent,
                            double high_percent) {
  detail::requireParameter(
      0.0 <= low_percent && low_percent < high_percent && high_percent <= 100.0, "percentiles",
      std::to_string(low_percent) + "," + std::to_string(high_percent), "0 <= low < high <= 100");
  if (height.size() != mask.size())
    throw Error("maskedPercentiles: height and mask differ in size");
  OrderStatistics values(height, mask);
  if (values.count() == 0) throw Error("percentiles of an empty set: no valid texel");
  // Linear interpolation between the order statistics around rank p (n - 1) / 100.
  const auto percentile = [&values](double percent) {
    const double rank = percent / 100.0 * static_cast<double>(values.count() - 1);
    const size_t below = static_cast<size_t>(std::floor(rank));
    const float low = values.at(below);
    if (below + 1 >= values.count()) return low;
    const float high = values.at(below + 1);
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
