#include "texture/masked_gaussian.hpp"

#include <algorithm>
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
  // Bands of rows with a halo of the kernel's radius: the blurred band's middle rows are
  // exactly the whole image's, and the scratch stays a few MB however large the map (a
  // 4096^2 map would otherwise need a 192 MB copy of its normals, mostly page-fault time).
  const int radius = sigma > 0.0 ? static_cast<int>(std::ceil(3.0 * sigma)) : 0;
  const cv::Size kernel(2 * radius + 1, 2 * radius + 1);
  constexpr int kBandRows = 128;
  const float min_nz_f = static_cast<float>(min_nz);
  for (int first = 0; first < normals.rows; first += kBandRows) {
    const int last = std::min(normals.rows, first + kBandRows);  // exclusive
    cv::Mat3f band = scratch.view(last - first + 2 * radius, normals.cols);
    for (int i = 0; i < band.rows; ++i) {
      const int r = first - radius + i;
      cv::Vec3f* out = band.ptr<cv::Vec3f>(i);
      if (r < 0 || r >= normals.rows) {
        // Beyond the patch is "not in the island", exactly like a masked texel.
        std::fill(out, out + normals.cols, cv::Vec3f(0.0f, 0.0f, 0.0f));
        continue;
      }
      const uchar* ok = mask.ptr<uchar>(r);
      const cv::Vec3f* n = normals.ptr<cv::Vec3f>(r);
      for (int c = 0; c < normals.cols; ++c) out[c] = ok[c] ? n[c] : cv::Vec3f(0.0f, 0.0f, 0.0f);
    }
    if (radius > 0) {
      // blur(n * m) / blur(m) differs from blur(n * m) by a positive scale per texel, which
      // does not change the slopes -nx/nz, -ny/nz, so blur(m) is never computed.
      cv::GaussianBlur(band, band, kernel, sigma, sigma, cv::BORDER_CONSTANT | cv::BORDER_ISOLATED);
    }
    for (int r = first; r < last; ++r) {
      const uchar* ok = mask.ptr<uchar>(r);
      const cv::Vec3f* original = normals.ptr<cv::Vec3f>(r);
      const cv::Vec3f* s = band.ptr<cv::Vec3f>(r - first + radius);
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
}

}  // namespace detail
}  // namespace norm2tex
