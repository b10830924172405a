#include "norm2tex/texture/height_range.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/core/hal/intrin.hpp>

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

/// Finite masked values of `height`, located by order statistic through a histogram: three
/// passes over the map (range, histogram, the few bins asked for) and a sort of those bins,
/// instead of copying every value and partially sorting them (a 2048 x 2048 atlas: 16 MB of
/// copies and two nth_element over 4 M values).
class OrderStatistics {
 public:
  OrderStatistics(const cv::Mat1f& height, const cv::Mat1b& mask) : height_(height), mask_(mask) {
    findRange();
    if (count_ == 0) return;
    const double scale = high_ > low_ ? kBins / (static_cast<double>(high_) - low_) : 0.0;
    // Bins in float where the scale fits (every map but a near-constant one): 2x faster than
    // double. Either way bin() only has to be monotonic: the values are exact, not binned.
    float_bins_ = scale < 1e30;
    scale_ = scale;
    scale_f_ = static_cast<float>(scale);
    counts_.assign(kBins + 1, 0);
    forEachValue([this](float value) { ++counts_[bin(value)]; });
  }

  size_t count() const { return count_; }

  /// Loads the values of the bins holding the order statistics `ranks` (0-based, < count())
  /// in one pass, so at() can answer them.
  void prepare(const std::vector<size_t>& ranks) {
    bins_.clear();
    for (size_t k : ranks) {
      const int b = binOf(k);
      if (std::find(bins_.begin(), bins_.end(), b) == bins_.end()) bins_.push_back(b);
    }
    values_.assign(bins_.size(), {});
    forEachValue([this](float value) {
      const int b = bin(value);
      for (size_t i = 0; i < bins_.size(); ++i) {
        if (bins_[i] == b) values_[i].push_back(value);
      }
    });
    for (std::vector<float>& v : values_) std::sort(v.begin(), v.end());
  }

  /// The k-th smallest value (0-based), exact; k must be among prepare()'s ranks.
  float at(size_t k) const {
    size_t below = 0;
    const int b = binOf(k, &below);
    const size_t i = std::find(bins_.begin(), bins_.end(), b) - bins_.begin();
    return values_.at(i).at(k - below);
  }

 private:
  static constexpr int kBins = 1 << 16;

  /// The bin of the k-th smallest value, and how many values lie in the bins below it.
  int binOf(size_t k, size_t* below_out = nullptr) const {
    size_t below = 0;
    int b = 0;
    while (below + counts_[b] <= k) below += counts_[b++];
    if (below_out != nullptr) *below_out = below;
    return b;
  }

  /// low_, high_ and count_ of the finite masked values, four lanes at a time.
  void findRange() {
    const cv::v_float32x4 infinity = cv::v_setall_f32(std::numeric_limits<float>::infinity());
    const cv::v_float32x4 zero = cv::v_setzero_f32();
    const cv::v_float32x4 minus_infinity =
        cv::v_setall_f32(-std::numeric_limits<float>::infinity());
    cv::v_float32x4 low = infinity, high = minus_infinity;
    cv::v_uint32x4 count = cv::v_setzero_u32();
    const cv::v_uint32x4 none = cv::v_setzero_u32();
    for (int r = 0; r < height_.rows; ++r) {
      const float* h = height_.ptr<float>(r);
      const uchar* ok = mask_.ptr<uchar>(r);
      int c = 0;
      for (; c + 4 <= height_.cols; c += 4) {
        const cv::v_float32x4 value = cv::v_load(h + c);
        // value - value is 0 for a finite value, NaN for an infinite one or NaN.
        const cv::v_float32x4 finite = (value - value) == zero;
        const cv::v_float32x4 use =
            finite & cv::v_reinterpret_as_f32(cv::v_load_expand_q(ok + c) != none);
        low = cv::v_min(low, cv::v_select(use, value, infinity));
        high = cv::v_max(high, cv::v_select(use, value, minus_infinity));
        count -= cv::v_reinterpret_as_u32(use);  // a lane in use is all ones: -1
      }
      for (; c < height_.cols; ++c) {
        if (ok[c] && std::isfinite(h[c])) {
          low_ = std::min(low_, h[c]);
          high_ = std::max(high_, h[c]);
          ++count_;
        }
      }
    }
    low_ = std::min(low_, cv::v_reduce_min(low));
    high_ = std::max(high_, cv::v_reduce_max(high));
    count_ += cv::v_reduce_sum(count);
  }

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
    if (float_bins_) return std::min(kBins, static_cast<int>((value - low_) * scale_f_));
    return std::min(kBins, static_cast<int>((static_cast<double>(value) - low_) * scale_));
  }

  const cv::Mat1f& height_;
  const cv::Mat1b& mask_;
  float low_ = std::numeric_limits<float>::infinity();
  float high_ = -std::numeric_limits<float>::infinity();
  size_t count_ = 0;
  double scale_ = 0.0;
  float scale_f_ = 0.0f;
  bool float_bins_ = false;
  std::vector<size_t> counts_;
  std::vector<int> bins_;
  std::vector<std::vector<float>> values_;
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
  const auto rank = [&values](double percent) {
    return percent / 100.0 * static_cast<double>(values.count() - 1);
  };
  std::vector<size_t> ranks;
  for (double percent : {low_percent, high_percent}) {
    const size_t below = static_cast<size_t>(std::floor(rank(percent)));
    ranks.push_back(below);
    if (below + 1 < values.count()) ranks.push_back(below + 1);
  }
  values.prepare(ranks);
  const auto percentile = [&values, &rank](double percent) {
    const double r = rank(percent);
    const size_t below = static_cast<size_t>(std::floor(r));
    const float low = values.at(below);
    if (below + 1 >= values.count()) return low;
    const float high = values.at(below + 1);
    return static_cast<float>(low + (r - below) * (high - low));
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
