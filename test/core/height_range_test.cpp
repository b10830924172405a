#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "norm2tex/common/error.hpp"
#include "norm2tex/texture/height_range.hpp"

namespace norm2tex {
namespace {

cv::Mat1f ramp(int n) {
  cv::Mat1f h(1, n);
  for (int i = 0; i < n; ++i) h(0, i) = static_cast<float>(i);
  return h;
}

TEST(HeightRange, EachRangeIsHonoured) {
  const cv::Mat1b all(1, 101, 255);
  for (const HeightRange range :
       {HeightRange::kRemove, HeightRange::kSymmetric, HeightRange::kAdd}) {
    cv::Mat1f h = ramp(101);
    normalizeToRange(h, all, maskedPercentiles(h, all, 0.0, 100.0), range);
    const cv::Vec2f bounds = rangeBounds(range);
    double low, high;
    cv::minMaxLoc(h, &low, &high);
    EXPECT_FLOAT_EQ(low, bounds[0]) << toString(range);
    EXPECT_FLOAT_EQ(high, bounds[1]) << toString(range);
    EXPECT_FLOAT_EQ(h(0, 50), 0.5f * (bounds[0] + bounds[1])) << "linear in between";
    EXPECT_LT(h(0, 10), h(0, 90)) << "order kept: peaks stay peaks";
  }
  EXPECT_EQ(rangeBounds(HeightRange::kRemove), cv::Vec2f(-1, 0));
}

TEST(HeightRange, PercentilesClipOutliers) {
  // 10000 values in [0, 1) and two wild spikes: the 0.05 / 99.95 percentiles ignore them.
  cv::Mat1f h(100, 100);
  cv::RNG rng(7);
  rng.fill(h, cv::RNG::UNIFORM, 0.0, 1.0);
  h(3, 3) = 1000.0f;
  h(7, 7) = -1000.0f;
  const cv::Mat1b all(h.size(), 255);
  const cv::Vec2f p = maskedPercentiles(h, all, 0.05, 99.95);
  EXPECT_GT(p[0], -0.01);
  EXPECT_LT(p[1], 1.01);
  normalizeToRange(h, all, p, HeightRange::kSymmetric);
  EXPECT_FLOAT_EQ(h(3, 3), 1.0f);
  EXPECT_FLOAT_EQ(h(7, 7), -1.0f);
  cv::Scalar mean, stddev;
  cv::meanStdDev(h, mean, stddev);
  EXPECT_GT(stddev[0], 0.5) << "the bulk spreads over the range, not squashed by the spikes";
}

TEST(HeightRange, PercentilesInterpolateBetweenOrderStatistics) {
  const cv::Mat1f h = ramp(11);  // 0..10
  const cv::Vec2f p = maskedPercentiles(h, cv::Mat1b(1, 11, 255), 25.0, 75.0);
  EXPECT_FLOAT_EQ(p[0], 2.5f);
  EXPECT_FLOAT_EQ(p[1], 7.5f);
}

/// The percentiles by their definition: sort the finite masked values, interpolate linearly.
cv::Vec2f sortedPercentiles(const cv::Mat1f& h, const cv::Mat1b& mask, double low, double high) {
  std::vector<float> values;
  for (int r = 0; r < h.rows; ++r) {
    for (int c = 0; c < h.cols; ++c) {
      if (mask(r, c) && std::isfinite(h(r, c))) values.push_back(h(r, c));
    }
  }
  std::sort(values.begin(), values.end());
  const auto at = [&values](double percent) {
    const double rank = percent / 100.0 * static_cast<double>(values.size() - 1);
    const size_t below = static_cast<size_t>(std::floor(rank));
    if (below + 1 >= values.size()) return values[below];
    return static_cast<float>(values[below] + (rank - below) * (values[below + 1] - values[below]));
  };
  return {at(low), at(high)};
}

// The histogram search (vector range pass, float bins) against sorting, bit for bit: odd widths
// (vector tails), masked texels, NaN and infinities, ties, a huge outlier that squeezes every
// other value into one bin, and a range so narrow its bin scale overflows a float.
TEST(HeightRange, PercentilesEqualSortingTheValues) {
  std::mt19937 random(7);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  const auto check = [](const cv::Mat1f& h, const cv::Mat1b& mask, const std::string& what) {
    for (const auto& p : {std::pair<double, double>{0.05, 99.95}, {0.0, 100.0}, {13.0, 50.5}}) {
      const cv::Vec2f expected = sortedPercentiles(h, mask, p.first, p.second);
      const cv::Vec2f got = maskedPercentiles(h, mask, p.first, p.second);
      EXPECT_EQ(got[0], expected[0]) << what << " low " << p.first;
      EXPECT_EQ(got[1], expected[1]) << what << " high " << p.second;
    }
  };
  cv::Mat1f h(257, 203);
  cv::Mat1b mask(h.size());
  for (int r = 0; r < h.rows; ++r) {
    for (int c = 0; c < h.cols; ++c) {
      h(r, c) = std::round(normal(random) * 64.0f) / 64.0f;  // many ties
      mask(r, c) = random() % 5 != 0 ? 255 : 0;
    }
  }
  h(3, 4) = std::numeric_limits<float>::quiet_NaN();
  h(5, 6) = std::numeric_limits<float>::infinity();
  h(7, 202) = -std::numeric_limits<float>::infinity();
  mask(3, 4) = mask(5, 6) = mask(7, 202) = 255;
  check(h, mask, "normal");
  h(100, 100) = 1e30f;
  mask(100, 100) = 255;
  check(h, mask, "outlier");
  cv::Mat1f narrow(33, 35);
  for (int r = 0; r < narrow.rows; ++r) {
    for (int c = 0; c < narrow.cols; ++c) {
      narrow(r, c) = std::numeric_limits<float>::denorm_min() * static_cast<float>(random() % 9);
    }
  }
  check(narrow, cv::Mat1b(narrow.size(), 255), "subnormal range");
}

TEST(HeightRange, OnlyMaskedTexelsCountAndTheRestBecomeZero) {
  cv::Mat1f h = ramp(10);
  cv::Mat1b mask(1, 10, uchar(0));
  mask(0, 2) = mask(0, 3) = mask(0, 4) = 255;
  h(0, 9) = 1e6f;  // outside the mask: must not move the percentiles
  const cv::Vec2f p = maskedPercentiles(h, mask, 0.0, 100.0);
  EXPECT_FLOAT_EQ(p[0], 2.0f);
  EXPECT_FLOAT_EQ(p[1], 4.0f);
  normalizeToRange(h, mask, p, HeightRange::kAdd);
  EXPECT_FLOAT_EQ(h(0, 3), 0.5f);
  EXPECT_FLOAT_EQ(h(0, 9), 0.0f);
  EXPECT_FLOAT_EQ(h(0, 0), 0.0f);
}

TEST(HeightRange, FlatMapGivesFlatZeroNotNaN) {
  for (const HeightRange range :
       {HeightRange::kRemove, HeightRange::kSymmetric, HeightRange::kAdd}) {
    cv::Mat1f h(8, 8, 3.25f);
    const cv::Mat1b all(h.size(), 255);
    normalizeToRange(h, all, maskedPercentiles(h, all, 0.05, 99.95), range);
    EXPECT_TRUE(cv::checkRange(h));
    EXPECT_EQ(cv::countNonZero(h), 0) << toString(range);
  }
}

TEST(HeightRange, EmptyMaskAndBadPercentilesAreErrors) {
  EXPECT_THROW(maskedPercentiles(ramp(4), cv::Mat1b(1, 4, uchar(0)), 1, 99), Error);
  EXPECT_THROW(maskedPercentiles(ramp(4), cv::Mat1b(1, 4, 255), 60, 40), Error);
  EXPECT_THROW(maskedPercentiles(ramp(4), cv::Mat1b(1, 4, 255), -1, 40), Error);
}

TEST(HeightRange, ParsesEveryDocumentedSpelling) {
  EXPECT_EQ(parseHeightRange("0,-1"), HeightRange::kRemove);
  EXPECT_EQ(parseHeightRange("[0, -1]"), HeightRange::kRemove);
  EXPECT_EQ(parseHeightRange("-1,1"), HeightRange::kSymmetric);
  EXPECT_EQ(parseHeightRange("add"), HeightRange::kAdd);
  EXPECT_EQ(parseHeightRange(toString(HeightRange::kAdd)), HeightRange::kAdd);
  EXPECT_THROW(parseHeightRange("0,2"), Error);
}

}  // namespace
}  // namespace norm2tex
