#include "texture/masked_gaussian.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace detail {
namespace {

int kernelRadius(double sigma) {
  return sigma > 0.0 ? static_cast<int>(std::ceil(3.0 * sigma)) : 0;
}

/// One row of one pass: `smoothed` (the blurred sums) to slopes added into gx, gy. The same
/// IEEE operations in the same order as the per-texel definition (length, 1 / length, scaled
/// normal, weight * nx / nz subtracted), four texels a step: sqrt and division dominate.
void addRowSlopes(const cv::Vec3f* smoothed, const cv::Vec3f* original, const uchar* ok, int cols,
                  float min_nz, float weight, float* gx, float* gy) {
  int c = 0;
#if CV_SIMD128
  const cv::v_float32x4 tiny = cv::v_setall_f32(1e-12f), one = cv::v_setall_f32(1.0f);
  const cv::v_float32x4 w = cv::v_setall_f32(weight), limit = cv::v_setall_f32(min_nz);
  const cv::v_uint32x4 none = cv::v_setzero_u32();
  for (; c + 4 <= cols; c += 4) {
    cv::v_float32x4 s0, s1, s2, o0, o1, o2;
    cv::v_load_deinterleave(reinterpret_cast<const float*>(smoothed + c), s0, s1, s2);
    cv::v_load_deinterleave(reinterpret_cast<const float*>(original + c), o0, o1, o2);
    const cv::v_float32x4 length = cv::v_sqrt(s0 * s0 + s1 * s1 + s2 * s2);
    const cv::v_float32x4 scale = one / length;
    // A vanishing sum (opposite normals cancelling) keeps the texel's own normal.
    const cv::v_float32x4 usable = length > tiny;
    const cv::v_float32x4 n0 = cv::v_select(usable, s0 * scale, o0);
    const cv::v_float32x4 n1 = cv::v_select(usable, s1 * scale, o1);
    const cv::v_float32x4 n2 = cv::v_select(usable, s2 * scale, o2);
    const cv::v_float32x4 use =
        (n2 > limit) & cv::v_reinterpret_as_f32(cv::v_load_expand_q(ok + c) != none);
    const cv::v_float32x4 x = cv::v_load(gx + c), y = cv::v_load(gy + c);
    cv::v_store(gx + c, cv::v_select(use, x - w * n0 / n2, x));
    cv::v_store(gy + c, cv::v_select(use, y - w * n1 / n2, y));
  }
#endif
  for (; c < cols; ++c) {
    if (!ok[c]) continue;
    const float length = std::sqrt(smoothed[c].dot(smoothed[c]));
    const cv::Vec3f n = length > 1e-12f ? smoothed[c] / length : original[c];
    if (!(n[2] > min_nz)) continue;
    gx[c] -= weight * n[0] / n[2];
    gy[c] -= weight * n[1] / n[2];
  }
}

}  // namespace

void addMaskedGaussianSlopes(const cv::Mat3f& normals, const cv::Mat1b& mask,
                             const std::vector<SlopePass>& passes, double min_nz, cv::Mat1f& dx,
                             cv::Mat1f& dy, SlopeScratch& scratch) {
  if (normals.size() != mask.size() || dx.size() != mask.size() || dy.size() != mask.size()) {
    throw Error("addMaskedGaussianSlopes: normals, mask and slopes differ in size");
  }
  if (passes.empty()) return;
  // Bands of rows with a halo of the widest kernel's radius: the blurred band's middle rows are
  // exactly the whole image's, and the scratch stays a few MB however large the map (a 4096^2
  // map would otherwise need a 192 MB copy of its normals, mostly page-fault time).
  int halo = 0;
  for (const SlopePass& pass : passes) halo = std::max(halo, kernelRadius(pass.sigma));
  constexpr int kBandRows = 128;
  const float min_nz_f = static_cast<float>(min_nz);
  for (int first = 0; first < normals.rows; first += kBandRows) {
    const int last = std::min(normals.rows, first + kBandRows);  // exclusive
    const int rows = last - first;
    cv::Mat3f band = scratch.band.view(rows + 2 * halo, normals.cols);
    for (int i = 0; i < band.rows; ++i) {
      const int r = first - halo + i;
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
    for (const SlopePass& pass : passes) {
      const int radius = kernelRadius(pass.sigma);
      // This pass's rows: its own halo around the band's rows, an image of its own (isolated).
      const cv::Mat3f source = band.rowRange(halo - radius, halo + rows + radius);
      cv::Mat3f smoothed = source;
      if (radius > 0) {
        // blur(n * m) / blur(m) differs from blur(n * m) by a positive scale per texel, which
        // does not change the slopes -nx/nz, -ny/nz, so blur(m) is never computed.
        smoothed = scratch.blurred.view(source.rows, source.cols);
        const cv::Size kernel(2 * radius + 1, 2 * radius + 1);
        cv::GaussianBlur(source, smoothed, kernel, pass.sigma, pass.sigma,
                         cv::BORDER_CONSTANT | cv::BORDER_ISOLATED);
      }
      for (int r = first; r < last; ++r) {
        addRowSlopes(smoothed.ptr<cv::Vec3f>(r - first + radius), normals.ptr<cv::Vec3f>(r),
                     mask.ptr<uchar>(r), normals.cols, min_nz_f, pass.weight, dx.ptr<float>(r),
                     dy.ptr<float>(r));
      }
    }
  }
}

}  // namespace detail
}  // namespace norm2tex
