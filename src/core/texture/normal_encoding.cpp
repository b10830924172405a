#include "norm2tex/texture/normal_encoding.hpp"

#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>

#include <opencv2/core/hal/intrin.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/common/huge_pages.hpp"

namespace norm2tex {
namespace {

/// round((component + 1) / 2 * full_scale), halves away from zero, saturated to [0, full_scale]:
/// std::round's result without its libm call or a branch (a 2048^2 map makes 12.6 million).
/// v is exact in double (a float + 1, halved, times a 16-bit scale), and so is v + 0.5 below a
/// power of two, so truncating v + 0.5 is rounding v half up; v > 0 also sends NaN to 0, as
/// saturate_cast<T>(NaN) does.
template <typename T>
T quantise(float component, double full_scale) {
  const double v = (component + 1.0) * 0.5 * full_scale;
  const double clamped = v > 0.0 ? (v < full_scale ? v : full_scale) : 0.0;
  return static_cast<T>(static_cast<int>(clamped + 0.5));
}

#if CV_SIMD128 && CV_SIMD128_64F
/// quantise() of four floats, in two double pairs: the same operations, so the same values.
inline cv::v_int32x4 quantise4(const cv::v_float32x4& component, double full_scale) {
  const cv::v_float64x2 one = cv::v_setall_f64(1.0), half = cv::v_setall_f64(0.5);
  const cv::v_float64x2 zero = cv::v_setzero_f64(), full = cv::v_setall_f64(full_scale);
  const auto pair = [&](const cv::v_float64x2& d) {
    const cv::v_float64x2 v = (d + one) * half * full;
    const cv::v_float64x2 clamped = cv::v_select(v > zero, cv::v_min(v, full), zero);
    return cv::v_trunc(clamped + half);  // lanes 0, 1
  };
  return cv::v_combine_low(pair(cv::v_cvt_f64(component)), pair(cv::v_cvt_f64_high(component)));
}

/// encodeRow's 16-bit texels, eight a step (the materials' normal maps: 12.6 million
/// quantisations for a 2048^2 map). Returns the number of texels done.
template <int kChannels>
int encodeRow16(const float* gx, const float* gy, const uchar* ok, int cols, float y_sign,
                ushort* out) {
  const cv::v_float32x4 one = cv::v_setall_f32(1.0f), zero = cv::v_setzero_f32();
  const cv::v_float32x4 minus_one = cv::v_setall_f32(-1.0f), sign = cv::v_setall_f32(y_sign);
  const cv::v_uint32x4 none = cv::v_setzero_u32();
  const cv::v_float32x4 all = cv::v_reinterpret_as_f32(cv::v_setall_u32(0xffffffffu));
  int c = 0;
  for (; c + 8 <= cols; c += 8) {
    cv::v_int32x4 b[2], g[2], r[2], a[2];
    for (int half = 0; half < 2; ++half) {
      const int i = c + 4 * half;
      const cv::v_float32x4 x = cv::v_load(gx + i), y = cv::v_load(gy + i);
      const cv::v_float32x4 valid =
          ok == nullptr ? all : cv::v_reinterpret_as_f32(cv::v_load_expand_q(ok + i) != none);
      const cv::v_float32x4 length = cv::v_sqrt(x * x + y * y + one);
      b[half] = quantise4(cv::v_select(valid, one / length, one), 65535.0);
      g[half] = quantise4(sign * cv::v_select(valid, minus_one * y / length, zero), 65535.0);
      r[half] = quantise4(cv::v_select(valid, minus_one * x / length, zero), 65535.0);
      a[half] = cv::v_reinterpret_as_s32(valid) & cv::v_setall_s32(65535);
    }
    ushort* texel = out + kChannels * c;
    if (kChannels == 4) {
      cv::v_store_interleave(texel, cv::v_pack_u(b[0], b[1]), cv::v_pack_u(g[0], g[1]),
                             cv::v_pack_u(r[0], r[1]), cv::v_pack_u(a[0], a[1]));
    } else {
      cv::v_store_interleave(texel, cv::v_pack_u(b[0], b[1]), cv::v_pack_u(g[0], g[1]),
                             cv::v_pack_u(r[0], r[1]));
    }
  }
  return c;
}
#endif

/// One row of texels: gradients (gx, gy) to normals in BGR(A) order; alpha, when there is one,
/// is full scale on valid texels and 0 elsewhere.
template <typename T, int kChannels>
void encodeRow(const float* gx, const float* gy, const uchar* ok, int cols, float y_sign,
               double full_scale, T* out) {
  int c = 0;
#if CV_SIMD128 && CV_SIMD128_64F
  if constexpr (std::is_same<T, ushort>::value) {
    c = encodeRow16<kChannels>(gx, gy, ok, cols, y_sign, reinterpret_cast<ushort*>(out));
    out += kChannels * c;
  }
#endif
  for (; c < cols; ++c, out += kChannels) {
    const bool valid = ok == nullptr || ok[c];
    // Computed for every texel and then selected: no branch in the loop.
    const float length = std::sqrt(gx[c] * gx[c] + gy[c] * gy[c] + 1.0f);
    const float x = valid ? -gx[c] / length : 0.0f;
    const float y = valid ? -gy[c] / length : 0.0f;
    const float z = valid ? 1.0f / length : 1.0f;
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

/// Whether all `count` bytes from `p` are non-zero.
inline bool allSet(const uchar* p, int count) {
  for (int i = 0; i < count; ++i) {
    if (p[i] == 0) return false;
  }
  return true;
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
  const auto slopes = [&](int begin, int end) {
    for (int c = begin; c < end; ++c) {
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
  };
  int c = 0;
#if CV_SIMD128
  // Blocks of four texels whose neighbours all belong to the surface (the inside of an island:
  // nearly every texel) take central differences four at a time, the same operations.
  if (up != nullptr && down != nullptr) {
    const cv::v_float32x4 half = cv::v_setall_f32(0.5f);
    slopes(0, 1);
    for (c = 1; c + 5 <= cols; c += 4) {
      if (masked && !(allSet(m + c - 1, 6) && allSet(m_up + c, 4) && allSet(m_down + c, 4))) {
        slopes(c, c + 4);
        continue;
      }
      cv::v_store(gx + c, half * (cv::v_load(h + c + 1) - cv::v_load(h + c - 1)));
      cv::v_store(gy + c, half * (cv::v_load(down + c) - cv::v_load(up + c)));
    }
  }
#endif
  slopes(c, cols);
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
