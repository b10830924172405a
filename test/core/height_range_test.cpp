#include <cmath>

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
