#include "texture/masked_gaussian.hpp"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace detail {

void addMaskedGaussianSlopes(const cv::Mat3f& normals, const cv::Mat1b& mask, double sigma,
                             double min_nz, float weight, cv::Mat1f& dx, cv::Mat1f& dy,
                             ScratchBuffer<cv::Vec3f>& scratch) {
  if (normals.size() != mask.size() || dx.size() != mask.size() || dy.size() != mask.size()) {
    throw Error("addMaskedGaussianSlopes: normals, mask and slopes differ in size");
  }
  cv::Mat3f smoothed = scratch.view(normals.size());
  for (int r = 0; r < normals.rows; ++r) {
    const uchar* ok = mask.ptr<uchar>(r);
    const cv::Vec3f* n = normals.ptr<cv::Vec3f>(r);
    cv::Vec3f* out = smoothed.ptr<cv::Vec3f>(r);
    for (int c = 0; c < normals.cols; ++c) out[c] = ok[c] ? n[c] : cv::Vec3f(0.0f, 0.0f, 0.0f);
  }
  if (sigma > 0.0) {
    const int radius = static_cast<int>(std::ceil(3.0 * sigma));
    const cv::Size kernel(2 * radius + 1, 2 * radius + 1);
    // Zero padding: texels beyond the patch are "not in the island", exactly like masked ones.
    // blur(n * m) / blur(m) differs from blur(n * m) by a positive scale per texel, which
    // does not change the slopes -nx/nz, -ny/nz, so blur(m) is never computed.
    cv::GaussianBlur(smoothed, smoothed, kernel, sigma, sigma,
                     cv::BORDER_CONSTANT | cv::BORDER_ISOLATED);
  }
  const float min_nz_f = static_cast<float>(min_nz);
  for (int r = 0; r < normals.rows; ++r) {
    const uchar* ok = mask.ptr<uchar>(r);
    const cv::Vec3f* original = normals.ptr<cv::Vec3f>(r);
    const cv::Vec3f* s = smoothed.ptr<cv::Vec3f>(r);
    float* gx = dx.ptr<float>(r);
    float* gy = dy.ptr<float>(r);
    for (int c = 0; c < normals.cols; ++c) {
      if (!ok[c]) continue;
      const float length = std::sqrt(s[c].dot(s[c]));
      // A vanishing sum (opposite normals cancelling) keeps the texel's own normal.
      const cv::Vec3f n = length > 1e-12f ? s[c] / length : original[c];
      if (!(n[2] > min_nz_f)) continue;
      gx[c] -= weight * n[0] / n[2];
      gy[c] -= weight * n[1] / n[2];
    }
  }
}

}  // namespace detail
}  // namespace norm2tex
