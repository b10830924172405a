#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

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

TEST(HeightAtlas, NonFiniteTexelsAreInvalidNeverHeights) {
  cv::Mat1f heights(3, 4, 0.25f);
  heights(1, 1) = std::numeric_limits<float>::quiet_NaN();
  heights(1, 2) = std::numeric_limits<float>::infinity();
  heights(0, 3) = -std::numeric_limits<float>::infinity();
  const HeightAtlas atlas(heights, cv::Mat1b(3, 4, 255), UvWrap::kClamp);
  EXPECT_EQ(cv::countNonZero(atlas.valid()), 12 - 3);
  EXPECT_EQ(atlas.valid()(1, 1), 0);
  EXPECT_EQ(atlas.valid()(1, 2), 0);
  EXPECT_TRUE(cv::checkRange(atlas.heights())) << "no NaN or inf left";
  // Every look-up, also right on the bad texels, is a finite height of the good ones.
  for (double u = 0.0; u <= 1.0; u += 0.05) {
    for (double v = 0.0; v <= 1.0; v += 0.05) {
      bool valid = false;
      const float h = atlas.sample(u, v, &valid);
      ASSERT_TRUE(std::isfinite(h));
      if (valid) {
        EXPECT_FLOAT_EQ(h, 0.25f) << u << "," << v;
      }
    }
  }
}

TEST(HeightAtlas, OwnsItsDataALaterWriteByTheCallerChangesNothing) {
  cv::Mat1f heights(4, 4, 1.0f);
  cv::Mat1b valid(4, 4, 255);
  valid(0, 0) = 0;
  const HeightAtlas atlas(heights, valid);
  heights.setTo(7.0f);
  valid.setTo(0);
  EXPECT_FLOAT_EQ(atlas.sample(0.5, 0.5), 1.0f);
  EXPECT_EQ(cv::countNonZero(atlas.valid()), 15);
  EXPECT_FLOAT_EQ(heights(0, 0), 7.0f) << "the caller's matrix is not written by the atlas";
  cv::Mat1f roi_source(8, 8, 2.0f);
  const HeightAtlas from_roi(roi_source(cv::Rect(2, 2, 4, 4)), cv::Mat1b(4, 4, 255));
  roi_source.setTo(0.0f);
  EXPECT_FLOAT_EQ(from_roi.sample(0.5, 0.5), 2.0f);
}

TEST(HeightAtlas, GivenIslandLabelsKeepTouchingIslandsApart) {
  // Two charts side by side with no gap: as one 4-connected region they would blend at the
  // seam; with the bake's (or the mesh's) labels they do not.
  cv::Mat1f heights(2, 4);
  heights << 0.0f, 0.0f, 8.0f, 8.0f, 0.0f, 0.0f, 8.0f, 8.0f;
  cv::Mat1i labels(2, 4);
  labels << 1, 1, 2, 2, 1, 1, 2, 2;
  const HeightAtlas atlas(heights, cv::Mat1b(2, 4, 255), labels, UvWrap::kClamp);
  EXPECT_EQ(atlas.islandCount(), 2);
  // u = 0.45 lies between texel columns 1 (island 1) and 2 (island 2), nearer column 1.
  EXPECT_FLOAT_EQ(atlas.sample(0.45, 0.5), 0.0f);
  EXPECT_FLOAT_EQ(atlas.sample(0.55, 0.5), 8.0f);
  const HeightAtlas merged(heights, cv::Mat1b(2, 4, 255), UvWrap::kClamp);
  EXPECT_EQ(merged.islandCount(), 1);
  EXPECT_GT(merged.sample(0.45, 0.5), 0.0f) << "one region blends across the seam";
  cv::Mat1i wrong = labels.clone();
  wrong(0, 0) = 0;  // a valid texel without an island
  EXPECT_THROW(HeightAtlas(heights, cv::Mat1b(2, 4, 255), wrong), Error);
}

TEST(HeightAtlas, RowLookUpEqualsSingleLookUpsBitForBit) {
  // Random heights on three islands with gaps between them, and on one island filling the map
  // (a tiling texture: the look-up reads no interior flags); UVs anywhere (outside [0, 1] too,
  // on texel lines, at the map's edges), some pixels not wanted; both wrap modes.
  cv::RNG rng(7);
  cv::Mat1f heights(37, 53);
  rng.fill(heights, cv::RNG::UNIFORM, -1.0, 1.0);
  cv::Mat1b islands(heights.size(), 255);
  islands.colRange(20, 23).setTo(0);
  islands.rowRange(10, 12).setTo(0);
  islands(cv::Rect(40, 25, 5, 5)).setTo(0);
  const cv::Mat1b whole(heights.size(), 255);
  for (const auto& [valid, wrap] : {std::pair{islands, UvWrap::kRepeat},
                                    {islands, UvWrap::kClamp},
                                    {whole, UvWrap::kRepeat},
                                    {whole, UvWrap::kClamp}}) {
    const HeightAtlas atlas(heights, valid, wrap);
    constexpr int kCount = 4003;  // not a multiple of 4: the scalar tail runs too
    std::vector<cv::Vec2f> uv(kCount);
    std::vector<unsigned char> wanted(kCount);
    for (int i = 0; i < kCount; ++i) {
      if (i % 7 == 0) {  // exactly on texel centres and lines
        uv[i] = cv::Vec2f(static_cast<float>(rng.uniform(0, 54)) / 53.0f,
                          static_cast<float>(rng.uniform(0, 38)) / 37.0f);
      } else {
        uv[i] = cv::Vec2f(rng.uniform(-1.5f, 2.5f), rng.uniform(-1.5f, 2.5f));
      }
      wanted[i] = rng.uniform(0, 5) != 0;
    }
    std::vector<float> row(kCount, -99.0f);
    atlas.sampleFiniteRow(uv.data(), wanted.data(), kCount, row.data());
    int mismatches = 0, fast = 0;
    for (int i = 0; i < kCount; ++i) {
      const float single = wanted[i] ? atlas.sampleFinite(uv[i][0], uv[i][1]) : 0.0f;
      // Bit for bit, not approximately: the renderer's output must not depend on the path.
      if (std::memcmp(&single, &row[i], sizeof(float)) != 0) ++mismatches;
      if (wanted[i] && single != 0.0f) ++fast;
    }
    EXPECT_EQ(mismatches, 0);
    EXPECT_GT(fast, kCount / 2);  // most look-ups found an island
  }
}

TEST(HeightAtlas, RejectsEmptyOrMismatchedInput) {
  EXPECT_THROW(HeightAtlas(cv::Mat1f(), cv::Mat1b()), Error);
  EXPECT_THROW(HeightAtlas(cv::Mat1f(2, 2, 0.0f), cv::Mat1b(2, 3, 255)), Error);
}

}  // namespace
}  // namespace norm2tex
