#include "norm2tex/texture/normal_encoding.hpp"

#include <cmath>
#include <cstdint>
#include <vector>

#include "norm2tex/common/error.hpp"
#include "norm2tex/common/huge_pages.hpp"

namespace norm2tex {
namespace {

/// round((component + 1) / 2 * full_scale), halves away from zero, saturated to [0, full_scale]:
/// std::round's result without its libm call (a 2048^2 map makes 12.6 million of them).
template <typename T>
T quantise(float component, double full_scale) {
  const double v = (component + 1.0) * 0.5 * full_scale;
  if (!(v > 0.0)) return 0;  // also NaN, as saturate_cast<T>(NaN) gives
  if (v >= full_scale) return static_cast<T>(full_scale);
  const auto whole = static_cast<std::int64_t>(v);  // floor: v > 0
  return static_cast<T>(whole + (v - static_cast<double>(whole) >= 0.5 ? 1 : 0));
}

/// One row of texels: gradients (gx, gy) to normals in BGR(A) order; alpha, when there is one,
/// is full scale on valid texels and 0 elsewhere.
template <typename T, int kChannels>
void encodeRow(const float* gx, const float* gy, const uchar* ok, int cols, float y_sign,
               double full_scale, T* out) {
  for (int c = 0; c < cols; ++c, out += kChannels) {
    float x = 0.0f, y = 0.0f, z = 1.0f;
    const bool valid = ok == nullptr || ok[c];
    if (valid) {
      const float length = std::sqrt(gx[c] * gx[c] + gy[c] * gy[c] + 1.0f);
      x = -gx[c] / length;
      y = -gy[c] / length;
      z = 1.0f / length;
    }
    out[0] = quantise<T>(z, full_scale);
    out[1] = quantise<T>(y_sign * y, full_scale);
    out[2] = quantise<T>(x, full_scale);
    if (kChannels == 4) out[3] = valid ? static_cast<T>(full_scale) : T(0);
  }
}

template <typename T>
void encodeImageRow(const float* gx, const float* gy, const uchar* ok, int cols, float y_sign,
                    double full_scale, int channels, uchar* out) {
  if (channels == 4) {
    encodeRow<T, 4>(gx, gy, ok, cols, y_sign, full_scale, reinterpret_cast<T*>(out));
  } else {
    encodeRow<T, 3>(gx, gy, ok, cols, y_sign, full_scale, reinterpret_cast<T*>(out));
  }
}

void encodeAnyRow(const float* gx, const float* gy, const uchar* ok, int cols, float y_sign,
                  int depth, int channels, uchar* out) {
  if (depth == CV_8U) {
    encodeImageRow<uchar>(gx, gy, ok, cols, y_sign, 255.0, channels, out);
  } else {
    encodeImageRow<ushort>(gx, gy, ok, cols, y_sign, 65535.0, channels, out);
  }
}

void requireDepth(int depth, const char* function) {
  if (depth != CV_8U && depth != CV_16U) {
    throw Error(std::string(function) + ": depth must be CV_8U or CV_16U");
  }
}

/// Slopes of one row of a height field: central differences where both neighbours belong to
/// the surface, one-sided where only one does, 0 where neither does or the texel is masked.
void slopeRow(const cv::Mat1f& height, const cv::Mat1b& mask, int r, float* gx, float* gy) {
  const int rows = height.rows, cols = height.cols;
  const float* h = height.ptr<float>(r);
  const float* up = r > 0 ? height.ptr<float>(r - 1) : nullptr;
  const float* down = r + 1 < rows ? height.ptr<float>(r + 1) : nullptr;
  const bool masked = !mask.empty();
  const uchar* m = masked ? mask.ptr<uchar>(r) : nullptr;
  const uchar* m_up = masked && up != nullptr ? mask.ptr<uchar>(r - 1) : nullptr;
  const uchar* m_down = masked && down != nullptr ? mask.ptr<uchar>(r + 1) : nullptr;
  const auto slope = [](bool forward, bool backward, float ahead, float here, float behind) {
    if (forward && backward) return 0.5f * (ahead - behind);
    if (forward) return ahead - here;
    if (backward) return here - behind;
    return 0.0f;
  };
  for (int c = 0; c < cols; ++c) {
    if (masked && !m[c]) {
      gx[c] = gy[c] = 0.0f;
      continue;
    }
    const bool right = c + 1 < cols && (!masked || m[c + 1]);
    const bool left = c > 0 && (!masked || m[c - 1]);
    const bool below = down != nullptr && (!masked || m_down[c]);
    const bool above = up != nullptr && (!masked || m_up[c]);
    gx[c] = slope(right, left, right ? h[c + 1] : 0.0f, h[c], left ? h[c - 1] : 0.0f);
    gy[c] = slope(below, above, below ? down[c] : 0.0f, h[c], above ? up[c] : 0.0f);
  }
}

}  // namespace

cv::Mat encodeNormalMap(const cv::Mat1f& dx, const cv::Mat1f& dy, NormalConvention convention,
                        int depth, const cv::Mat1b& mask) {
  if (dx.empty() || dx.size() != dy.size() || (!mask.empty() && mask.size() != dx.size())) {
    throw Error("encodeNormalMap: gradients and mask must be non-empty and of one size");
  }
  requireDepth(depth, "encodeNormalMap");
  const float y_sign = convention == NormalConvention::kOpenGL ? -1.0f : 1.0f;
  cv::Mat image;
  createWithHugePages(image, dx.rows, dx.cols, CV_MAKETYPE(depth, 3));
  for (int r = 0; r < dx.rows; ++r) {
    encodeAnyRow(dx.ptr<float>(r), dy.ptr<float>(r), mask.empty() ? nullptr : mask.ptr<uchar>(r),
                 dx.cols, y_sign, depth, 3, image.ptr(r));
  }
  return image;
}

cv::Mat encodeNormalMapFromHeight(const cv::Mat1f& height, NormalConvention convention, int depth,
                                  const cv::Mat1b& mask, bool with_alpha) {
  if (height.empty()) throw Error("encodeNormalMapFromHeight: empty height field");
  if (!mask.empty() && mask.size() != height.size()) {
    throw Error("encodeNormalMapFromHeight: the mask and the height field differ in size");
  }
  requireDepth(depth, "encodeNormalMapFromHeight");
  const float y_sign = convention == NormalConvention::kOpenGL ? -1.0f : 1.0f;
  const int channels = with_alpha ? 4 : 3;
  cv::Mat image;  // 32 MB for a 2048^2 16-bit BGRA map: huge pages fault it in ~30x cheaper
  createWithHugePages(image, height.rows, height.cols, CV_MAKETYPE(depth, channels));
  // Row by row: the slopes never exist as whole images (32 MB for a 2048^2 map).
  std::vector<float> gx(height.cols), gy(height.cols);
  for (int r = 0; r < height.rows; ++r) {
    slopeRow(height, mask, r, gx.data(), gy.data());
    encodeAnyRow(gx.data(), gy.data(), mask.empty() ? nullptr : mask.ptr<uchar>(r), height.cols,
                 y_sign, depth, channels, image.ptr(r));
  }
  return image;
}

}  // namespace norm2tex
