#include "norm2tex/texture/normal_encoding.hpp"

#include <cmath>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

template <typename T>
cv::Mat encode(const cv::Mat1f& dx, const cv::Mat1f& dy, float y_sign, double full_scale,
               const cv::Mat1b& mask) {
  cv::Mat_<cv::Vec<T, 3>> image(dx.size());
  const auto quantise = [full_scale](float component) {
    return cv::saturate_cast<T>(std::round((component + 1.0) * 0.5 * full_scale));
  };
  for (int r = 0; r < dx.rows; ++r) {
    const float* gx = dx.ptr<float>(r);
    const float* gy = dy.ptr<float>(r);
    const uchar* ok = mask.empty() ? nullptr : mask.ptr<uchar>(r);
    auto* out = image.template ptr<cv::Vec<T, 3>>(r);
    for (int c = 0; c < dx.cols; ++c) {
      float x = 0.0f, y = 0.0f, z = 1.0f;
      if (ok == nullptr || ok[c]) {
        const float length = std::sqrt(gx[c] * gx[c] + gy[c] * gy[c] + 1.0f);
        x = -gx[c] / length;
        y = -gy[c] / length;
        z = 1.0f / length;
      }
      out[c] = cv::Vec<T, 3>(quantise(z), quantise(y_sign * y), quantise(x));  // B, G, R
    }
  }
  return image;
}

}  // namespace

cv::Mat encodeNormalMap(const cv::Mat1f& dx, const cv::Mat1f& dy, NormalConvention convention,
                        int depth, const cv::Mat1b& mask) {
  if (dx.empty() || dx.size() != dy.size() || (!mask.empty() && mask.size() != dx.size())) {
    throw Error("encodeNormalMap: gradients and mask must be non-empty and of one size");
  }
  const float y_sign = convention == NormalConvention::kOpenGL ? -1.0f : 1.0f;
  if (depth == CV_8U) return encode<uchar>(dx, dy, y_sign, 255.0, mask);
  if (depth == CV_16U) return encode<ushort>(dx, dy, y_sign, 65535.0, mask);
  throw Error("encodeNormalMap: depth must be CV_8U or CV_16U");
}

cv::Mat encodeNormalMapFromHeight(const cv::Mat1f& height, NormalConvention convention, int depth,
                                  const cv::Mat1b& mask) {
  if (height.empty()) throw Error("encodeNormalMapFromHeight: empty height field");
  const auto inside = [&](int r, int c) {
    return r >= 0 && c >= 0 && r < height.rows && c < height.cols &&
           (mask.empty() || mask(r, c) != 0);
  };
  // Central difference where both neighbours belong to the surface, one-sided otherwise.
  const auto slope = [&](int r, int c, int dr, int dc) {
    const bool forward = inside(r + dr, c + dc);
    const bool backward = inside(r - dr, c - dc);
    if (forward && backward) return 0.5f * (height(r + dr, c + dc) - height(r - dr, c - dc));
    if (forward) return height(r + dr, c + dc) - height(r, c);
    if (backward) return height(r, c) - height(r - dr, c - dc);
    return 0.0f;
  };
  cv::Mat1f dx(height.size(), 0.0f), dy(height.size(), 0.0f);
  for (int r = 0; r < height.rows; ++r) {
    for (int c = 0; c < height.cols; ++c) {
      if (!inside(r, c)) continue;
      dx(r, c) = slope(r, c, 0, 1);
      dy(r, c) = slope(r, c, 1, 0);
    }
  }
  return encodeNormalMap(dx, dy, convention, depth, mask);
}

}  // namespace norm2tex
