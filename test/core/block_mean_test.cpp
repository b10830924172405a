// blockMean: the shrunk, background-subtracted frames the learning pipeline sees.
#include <gtest/gtest.h>

#include "norm2tex/common/error.hpp"
#include "norm2tex/render/block_mean.hpp"

namespace norm2tex {
namespace {

cv::Mat3b ramp(int rows, int cols, int offset) {
  cv::Mat3b image(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      image(r, c) = cv::Vec3b(static_cast<uchar>((r * 7 + c * 3 + offset) % 256),
                              static_cast<uchar>((r * 11 + c + offset) % 256),
                              static_cast<uchar>((r + c * 13 + offset) % 256));
    }
  }
  return image;
}

// Each output pixel against the mean of its block computed the plainest way, in double.
TEST(BlockMean, EqualsEachBlocksMeanAndCropsPartialBlocks) {
  const cv::Mat3b image = ramp(23, 31, 0), background = ramp(23, 31, 100);
  for (int factor : {1, 2, 3, 4, 5}) {
    for (bool subtract : {false, true}) {
      const cv::Mat3f out = blockMean(image, factor, subtract ? background : cv::Mat3b());
      ASSERT_EQ(out.rows, 23 / factor);
      ASSERT_EQ(out.cols, 31 / factor);
      for (int br = 0; br < out.rows; ++br) {
        for (int bc = 0; bc < out.cols; ++bc) {
          for (int k = 0; k < 3; ++k) {
            double sum = 0;
            for (int r = br * factor; r < (br + 1) * factor; ++r) {
              for (int c = bc * factor; c < (bc + 1) * factor; ++c) {
                sum += image(r, c)[k] - (subtract ? background(r, c)[k] : 0);
              }
            }
            EXPECT_NEAR(out(br, bc)[k], sum / (factor * factor), 1e-5)
                << "factor " << factor << " block " << br << "," << bc;
          }
        }
      }
    }
  }
}

TEST(BlockMean, BackgroundOfItselfIsZeroAndFactorOneIsTheImage) {
  const cv::Mat3b image = ramp(12, 16, 5);
  EXPECT_EQ(cv::countNonZero(blockMean(image, 4, image).reshape(1)), 0);
  cv::Mat3f same;
  image.convertTo(same, CV_32F);
  EXPECT_EQ(cv::norm(blockMean(image, 1), same, cv::NORM_INF), 0.0);
}

TEST(BlockMean, ReusesTheOutputBuffer) {
  const cv::Mat3b image = ramp(240, 320, 0);
  cv::Mat3f out;
  blockMean(image, 4, cv::Mat3b(), out);
  const uchar* data = out.data;
  blockMean(ramp(240, 320, 9), 4, cv::Mat3b(), out);
  EXPECT_EQ(out.data, data);
  EXPECT_EQ(out.size(), cv::Size(80, 60));
}

TEST(BlockMean, RefusesBadInput) {
  const cv::Mat3b image = ramp(8, 8, 0);
  EXPECT_THROW(blockMean(image, 0), Error);
  EXPECT_THROW(blockMean(image, 9), Error);
  EXPECT_THROW(blockMean(image, 2, ramp(8, 9, 0)), Error);
}

}  // namespace
}  // namespace norm2tex
