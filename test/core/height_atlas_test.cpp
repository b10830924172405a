#include <cmath>

#include <gtest/gtest.h>

#include "norm2tex/common/error.hpp"
#include "norm2tex/texture/height_atlas.hpp"

namespace norm2tex {
namespace {

// Texel centre of (row, col) in UV: u = (c + 0.5) / cols, v = 1 - (r + 0.5) / rows.
double uOf(int col, int cols) { return (col + 0.5) / cols; }
double vOf(int row, int rows) { return 1.0 - (row + 0.5) / rows; }

TEST(HeightAtlas, ImageRowZeroIsVOne) {
  cv::Mat1f heights(4, 4, 0.0f);
  heights(0, 1) = 1.0f;  // top row of the image
  const HeightAtlas atlas(heights, cv::Mat1b(4, 4, 255));
  EXPECT_FLOAT_EQ(atlas.sample(uOf(1, 4), vOf(0, 4)), 1.0f);
  EXPECT_GT(vOf(0, 4), 0.8) << "top row has high v";
  EXPECT_FLOAT_EQ(atlas.sample(uOf(1, 4), 1.0 - vOf(0, 4)), 0.0f);
}

TEST(HeightAtlas, BilinearBetweenTexelCentres) {
  cv::Mat1f heights(2, 2);
  heights << 0.0f, 1.0f, 2.0f, 3.0f;
  const HeightAtlas atlas(heights, cv::Mat1b(2, 2, 255), UvWrap::kClamp);
  EXPECT_FLOAT_EQ(atlas.sample(0.5, 0.5), 1.5f);              // centre of the four
  EXPECT_FLOAT_EQ(atlas.sample(0.5, vOf(0, 2)), 0.5f);        // between (0,0) and (0,1)
  EXPECT_FLOAT_EQ(atlas.sample(uOf(1, 2), vOf(1, 2)), 3.0f);  // on a centre
  bool valid = false;
  atlas.sample(0.3, 0.3, &valid);
  EXPECT_TRUE(valid);
}

TEST(HeightAtlas, RepeatWrapsAndClampClamps) {
  cv::Mat1f heights(1, 4);
  heights << 10.0f, 20.0f, 30.0f, 40.0f;
  HeightAtlas atlas(heights, cv::Mat1b(1, 4, 255), UvWrap::kRepeat);
  EXPECT_FLOAT_EQ(atlas.sample(uOf(1, 4) + 1.0, 0.5), 20.0f);
  EXPECT_FLOAT_EQ(atlas.sample(uOf(2, 4) - 3.0, 0.5), 30.0f);
  EXPECT_FLOAT_EQ(atlas.sample(0.0, 0.5), 25.0f) << "u = 0 blends the last and first texel";
  atlas.setWrap(UvWrap::kClamp);
  EXPECT_FLOAT_EQ(atlas.sample(0.0, 0.5), 10.0f);
  EXPECT_FLOAT_EQ(atlas.sample(-5.0, 0.5), 10.0f);
  EXPECT_FLOAT_EQ(atlas.sample(7.0, 0.5), 40.0f);
}

TEST(HeightAtlas, IslandBordersDoNotBlendWithGapsOrNeighbours) {
  // Columns: island A (value 1) | gap | island B (value 5).
  cv::Mat1f heights(3, 5, 0.0f);
  cv::Mat1b valid(3, 5, uchar(0));
  heights.colRange(0, 2).setTo(1.0f);
  valid.colRange(0, 2).setTo(255);
  heights.colRange(3, 5).setTo(5.0f);
  valid.colRange(3, 5).setTo(255);
  heights(1, 2) = 99.0f;  // garbage in the gap: the atlas zeroes invalid texels
  const HeightAtlas atlas(heights, valid, UvWrap::kClamp);
  EXPECT_EQ(atlas.islandCount(), 2);
  EXPECT_FLOAT_EQ(atlas.heights()(1, 2), 0.0f);
  const double v = vOf(1, 3);
  // Between A's last texel (col 1) and the gap (col 2): only A counts.
  EXPECT_FLOAT_EQ(atlas.sample(uOf(1, 5) + 0.3 / 5.0, v), 1.0f);
  EXPECT_FLOAT_EQ(atlas.sample(uOf(3, 5) - 0.3 / 5.0, v), 5.0f);
  // On the gap's centre line both islands are one texel away: one of them answers, unblended.
  bool valid_sample = false;
  const float on_gap = atlas.sample(uOf(2, 5), v, &valid_sample);
  EXPECT_TRUE(on_gap == 1.0f || on_gap == 5.0f) << on_gap;
  EXPECT_TRUE(valid_sample);
}

TEST(HeightAtlas, FarFromEveryIslandIsNotValid) {
  cv::Mat1b valid(8, 8, uchar(0));
  valid(0, 0) = 255;
  const HeightAtlas atlas(cv::Mat1f(8, 8, 2.0f), valid, UvWrap::kClamp);
  bool ok = true;
  EXPECT_FLOAT_EQ(atlas.sample(0.6, 0.4, &ok), 0.0f);
  EXPECT_FALSE(ok);
  EXPECT_FLOAT_EQ(atlas.sample(uOf(0, 8), vOf(0, 8), &ok), 2.0f);
  EXPECT_TRUE(ok);
  EXPECT_FLOAT_EQ(atlas.sample(std::nan(""), 0.5, &ok), 0.0f);
  EXPECT_FALSE(ok);
}

TEST(HeightAtlas, RejectsEmptyOrMismatchedInput) {
  EXPECT_THROW(HeightAtlas(cv::Mat1f(), cv::Mat1b()), Error);
  EXPECT_THROW(HeightAtlas(cv::Mat1f(2, 2, 0.0f), cv::Mat1b(2, 3, 255)), Error);
}

}  // namespace
}  // namespace norm2tex
