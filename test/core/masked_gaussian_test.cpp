// The bake's smoothing-and-slopes step (src/core/texture/masked_gaussian.cpp) against its
// per-texel definition over the whole image: band by band, vectorised and with several passes
// fused, it must give the same floats.
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "texture/masked_gaussian.hpp"

namespace norm2tex {
namespace {

/// The definition: mask the normals, blur the whole image (zero outside), and per masked texel
/// normalise the sum (its own normal if the sum vanishes) and subtract weight * (nx, ny) / nz.
void definition(const cv::Mat3f& normals, const cv::Mat1b& mask, double sigma, float weight,
                float min_nz, cv::Mat1f& dx, cv::Mat1f& dy) {
  cv::Mat3f sums = cv::Mat3f::zeros(normals.size());
  normals.copyTo(sums, mask);
  const int radius = sigma > 0.0 ? static_cast<int>(std::ceil(3.0 * sigma)) : 0;
  if (radius > 0) {
    cv::GaussianBlur(sums, sums, cv::Size(2 * radius + 1, 2 * radius + 1), sigma, sigma,
                     cv::BORDER_CONSTANT);
  }
  for (int r = 0; r < normals.rows; ++r) {
    for (int c = 0; c < normals.cols; ++c) {
      if (!mask(r, c)) continue;
      const cv::Vec3f s = sums(r, c);
      const float length = std::sqrt(s.dot(s));
      const cv::Vec3f n = length > 1e-12f ? s / length : normals(r, c);
      if (!(n[2] > min_nz)) continue;
      dx(r, c) -= weight * n[0] / n[2];
      dy(r, c) -= weight * n[1] / n[2];
    }
  }
}

TEST(MaskedGaussianSlopes, EqualTheirPerTexelDefinitionBitForBit) {
  // 301 rows: three bands and a short one; 203 columns: a vector tail of 3.
  std::mt19937 random(11);
  std::uniform_real_distribution<float> tilt(-0.6f, 0.6f);
  cv::Mat3f normals(301, 203);
  cv::Mat1b mask(normals.size());
  for (int r = 0; r < normals.rows; ++r) {
    for (int c = 0; c < normals.cols; ++c) {
      cv::Vec3f n(tilt(random), tilt(random), 1.0f);
      if (random() % 50 == 0) n[2] = -0.2f;  // facing away: no slope there
      normals(r, c) = n / std::sqrt(n.dot(n));
      mask(r, c) = (r / 37 + c / 29) % 5 != 0 && random() % 13 != 0 ? 255 : 0;
    }
  }
  // Opposite normals side by side: their sums vanish, the texels keep their own normals.
  normals(150, 100) = cv::Vec3f(0.6f, 0.0f, 0.8f);
  normals(150, 101) = cv::Vec3f(-0.6f, 0.0f, -0.8f);
  const float min_nz = 0.05f;
  const std::vector<detail::SlopePass> passes = {{0.35, 0.8f}, {1.1, 0.2f}, {0.0, 0.5f}};
  cv::Mat1f dx(normals.size()), dy(normals.size());
  cv::randu(dx, -1.0f, 1.0f);  // slopes are added to what is there
  cv::randu(dy, -1.0f, 1.0f);
  cv::Mat1f expected_dx = dx.clone(), expected_dy = dy.clone();
  for (const detail::SlopePass& pass : passes) {
    definition(normals, mask, pass.sigma, pass.weight, min_nz, expected_dx, expected_dy);
  }
  detail::SlopeScratch scratch;
  detail::addMaskedGaussianSlopes(normals, mask, passes, min_nz, dx, dy, scratch);
  EXPECT_EQ(cv::norm(dx, expected_dx, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(dy, expected_dy, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(dx, cv::Mat1f(dx.size(), 0.0f), cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace norm2tex
