#include "norm2tex/render/digit_shader_response.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/common/simd_dispatch.hpp"

namespace norm2tex {
namespace {

const char* const kFeatureNames[kShadingFeatureCount] = {
    "slope_x",    "slope_y",    "slope_xx",   "slope_xy",   "slope_yy",    "depth",
    "rim_out",    "rim_in",     "rim_right",  "rim_left",   "rim_down",    "rim_up",
    "slope_x*u",  "slope_x*v",  "slope_y*u",  "slope_y*v",  "rim_right*u", "rim_right*v",
    "rim_left*u", "rim_left*v", "rim_down*u", "rim_down*v", "rim_up*u",    "rim_up*v"};

// Gaussian blur of gel_mm over `region` with a wide sigma (pixels), replicating the image
// border. Wide blurs run on a copy reduced by a whole factor (sigma / kSigmaPerReducedPixel,
// area averaging) and are upsampled bilinearly: the blurred field is smooth, so this costs no
// visible accuracy but cuts the cost of a 0.6 mm blur at QVGA about 20-fold. The reduced grid
// is aligned to multiples of the factor in image coordinates, so a pixel's value does not
// depend on the region it was computed in (the shader's box or a whole frame).
constexpr double kSigmaPerReducedPixel = 2.5;

int reductionFactor(double sigma_px) {
  return std::max(1, static_cast<int>(sigma_px / kSigmaPerReducedPixel));
}

// How far the (reduced, truncated at 3 sigma, upsampled) blur spreads a value.
int blurRadiusPixels(double mm_per_pixel, double shadow_sigma_mm) {
  const double sigma_px = shadow_sigma_mm / mm_per_pixel;
  return static_cast<int>(std::ceil(3.0 * sigma_px)) + 2 * reductionFactor(sigma_px);
}

// The per-frame path reuses these per thread (fresh pages cost ~13 us each on these VMs).
struct BlurScratch {
  cv::Mat1f snapped, small, full;
};

void blurWide(const cv::Mat1f& gel_mm, const cv::Rect& region, double sigma_px, cv::Mat1f& out) {
  thread_local BlurScratch scratch;
  const int factor = reductionFactor(sigma_px);
  // The region snapped outwards to the reduced grid, padded by replication past the image.
  const int x0 = region.x / factor * factor, y0 = region.y / factor * factor;
  const int x1 = (region.x + region.width + factor - 1) / factor * factor;
  const int y1 = (region.y + region.height + factor - 1) / factor * factor;
  const cv::Rect inside =
      cv::Rect(x0, y0, x1 - x0, y1 - y0) & cv::Rect(0, 0, gel_mm.cols, gel_mm.rows);
  cv::Mat1f& snapped = scratch.snapped;
  cv::copyMakeBorder(gel_mm(inside), snapped, 0, y1 - y0 - inside.height, 0, x1 - x0 - inside.width,
                     cv::BORDER_REPLICATE);
  cv::Mat1f& small = factor > 1 ? scratch.small : snapped;
  if (factor > 1) {
    cv::resize(snapped, small, cv::Size(snapped.cols / factor, snapped.rows / factor), 0, 0,
               cv::INTER_AREA);
  }
  const double sigma_small = sigma_px / factor;
  const int radius = std::max(1, static_cast<int>(std::ceil(3.0 * sigma_small)));
  cv::GaussianBlur(small, small, cv::Size(2 * radius + 1, 2 * radius + 1), sigma_small, sigma_small,
                   cv::BORDER_REPLICATE);
  cv::Mat1f& full = factor > 1 ? scratch.full : small;
  if (factor > 1) cv::resize(small, full, snapped.size(), 0, 0, cv::INTER_LINEAR);
  full(cv::Rect(region.x - x0, region.y - y0, region.width, region.height)).copyTo(out);
}

// The per-pixel sums of the fused shading over one row (computeShadingDifference), and the
// differences they start from: plain loops that the compiler vectorises, built for AVX2 and the
// baseline (simd_dispatch.hpp).
constexpr int kVarying = 6;   // slope_x, slope_y, rim_right, rim_left, rim_down, rim_up
constexpr int kConstant = 6;  // slope_xx, slope_xy, slope_yy, depth, rim_out, rim_in

/// Per row and channel: the coefficient of varying feature q is a[c][q] + b[c][q] u.
struct RowCoefficients {
  float a[3][kVarying], b[3][kVarying], fixed[3][kConstant];
};

NORM2TEX_ALWAYS_INLINE void shadeRowBody(int n, const float* __restrict gx,
                                         const float* __restrict gy, const float* __restrict hh,
                                         const float* __restrict rim, const float* __restrict bx,
                                         const float* __restrict by, float u0, float du,
                                         const RowCoefficients& k, float* __restrict out_b,
                                         float* __restrict out_g, float* __restrict out_r) {
  for (int i = 0; i < n; ++i) {
    const float u = u0 + static_cast<float>(i) * du;
    const float x = gx[i], y = gy[i];
    const float varying[kVarying] = {x,
                                     y,
                                     std::max(bx[i], 0.0f),
                                     std::max(-bx[i], 0.0f),
                                     std::max(by[i], 0.0f),
                                     std::max(-by[i], 0.0f)};
    const float constant[kConstant] = {
        x * x, x * y, y * y, hh[i], std::max(rim[i], 0.0f), std::min(rim[i], 0.0f)};
    // Unrolled, so that the loop over pixels is the one vectorised.
    float acc[3] = {0.0f, 0.0f, 0.0f};
#pragma GCC unroll 3
    for (int c = 0; c < 3; ++c) {
#pragma GCC unroll 6
      for (int q = 0; q < kConstant; ++q) acc[c] += k.fixed[c][q] * constant[q];
#pragma GCC unroll 6
      for (int q = 0; q < kVarying; ++q) acc[c] += (k.a[c][q] + k.b[c][q] * u) * varying[q];
    }
    out_b[i] = acc[0];
    out_g[i] = acc[1];
    out_r[i] = acc[2];
  }
}

/// Interior columns [first, last) of one row: central differences of H and of its blur B, the
/// depth and B - H (no clamping, so the loop vectorises; the image's border columns are done
/// apart).
NORM2TEX_ALWAYS_INLINE void differencesBody(
    int first, int last, const float* __restrict h_row, const float* __restrict h_up,
    const float* __restrict h_down, const float* __restrict b_row, const float* __restrict b_up,
    const float* __restrict b_down, float half_inv_pixel, float dy_scale, float* __restrict gx,
    float* __restrict gy, float* __restrict hh, float* __restrict rim, float* __restrict bx,
    float* __restrict by) {
  for (int i = first; i < last; ++i) {
    gx[i] = (h_row[i + 1] - h_row[i - 1]) * half_inv_pixel;
    gy[i] = (h_down[i] - h_up[i]) * dy_scale;
    hh[i] = h_row[i];
    rim[i] = b_row[i] - h_row[i];
    bx[i] = (b_row[i + 1] - b_row[i - 1]) * half_inv_pixel;
    by[i] = (b_down[i] - b_up[i]) * dy_scale;
  }
}

using Differences = void (*)(int, int, const float*, const float*, const float*, const float*,
                             const float*, const float*, float, float, float*, float*, float*,
                             float*, float*, float*);

void differencesBaseline(int first, int last, const float* h_row, const float* h_up,
                         const float* h_down, const float* b_row, const float* b_up,
                         const float* b_down, float half_inv_pixel, float dy_scale, float* gx,
                         float* gy, float* hh, float* rim, float* bx, float* by) {
  differencesBody(first, last, h_row, h_up, h_down, b_row, b_up, b_down, half_inv_pixel, dy_scale,
                  gx, gy, hh, rim, bx, by);
}

#if NORM2TEX_HAS_AVX2_BUILD
NORM2TEX_TARGET_AVX2 void differencesAvx2(int first, int last, const float* h_row,
                                          const float* h_up, const float* h_down,
                                          const float* b_row, const float* b_up,
                                          const float* b_down, float half_inv_pixel, float dy_scale,
                                          float* gx, float* gy, float* hh, float* rim, float* bx,
                                          float* by) {
  differencesBody(first, last, h_row, h_up, h_down, b_row, b_up, b_down, half_inv_pixel, dy_scale,
                  gx, gy, hh, rim, bx, by);
}
#endif

using ShadeRow = void (*)(int, const float*, const float*, const float*, const float*, const float*,
                          const float*, float, float, const RowCoefficients&, float*, float*,
                          float*);

void shadeRowBaseline(int n, const float* gx, const float* gy, const float* hh, const float* rim,
                      const float* bx, const float* by, float u0, float du,
                      const RowCoefficients& k, float* out_b, float* out_g, float* out_r) {
  shadeRowBody(n, gx, gy, hh, rim, bx, by, u0, du, k, out_b, out_g, out_r);
}

#if NORM2TEX_HAS_AVX2_BUILD
NORM2TEX_TARGET_AVX2 void shadeRowAvx2(int n, const float* gx, const float* gy, const float* hh,
                                       const float* rim, const float* bx, const float* by, float u0,
                                       float du, const RowCoefficients& k, float* out_b,
                                       float* out_g, float* out_r) {
  shadeRowBody(n, gx, gy, hh, rim, bx, by, u0, du, k, out_b, out_g, out_r);
}
#endif

#if NORM2TEX_HAS_AVX2_BUILD
const ShadeRow shadeRow = pickSimd<ShadeRow>(shadeRowAvx2, shadeRowBaseline);
const Differences differences = pickSimd<Differences>(differencesAvx2, differencesBaseline);
#else
const ShadeRow shadeRow = shadeRowBaseline;
const Differences differences = differencesBaseline;
#endif

// 1 / s^2 for the shading's slope_saturation s, 0 for none.
float slopeSaturationFactor(const ShadingOptions& shading) {
  const double s = shading.slope_saturation;
  return s > 0.0 ? static_cast<float>(1.0 / (s * s)) : 0.0f;
}

// g <- g / sqrt(1 + |g|^2 / s^2) for n pixels' slopes: a plain loop the compiler vectorises
// (sqrtps, divps), built for AVX2 and the baseline. It vectorises only because this file is
// compiled with -fno-math-errno (src/core/CMakeLists.txt): with errno to set for a negative
// argument, each std::sqrt is a scalar call, and the saturated shading took twice as long.
NORM2TEX_ALWAYS_INLINE void saturateSlopesBody(int n, float inv_saturation_sq,
                                               float* __restrict gx, float* __restrict gy) {
  for (int i = 0; i < n; ++i) {
    const float scale =
        1.0f / std::sqrt(1.0f + (gx[i] * gx[i] + gy[i] * gy[i]) * inv_saturation_sq);
    gx[i] *= scale;
    gy[i] *= scale;
  }
}

using SaturateSlopes = void (*)(int, float, float*, float*);

void saturateSlopesBaseline(int n, float inv_saturation_sq, float* gx, float* gy) {
  saturateSlopesBody(n, inv_saturation_sq, gx, gy);
}

#if NORM2TEX_HAS_AVX2_BUILD
NORM2TEX_TARGET_AVX2 void saturateSlopesAvx2(int n, float inv_saturation_sq, float* gx,
                                             float* gy) {
  saturateSlopesBody(n, inv_saturation_sq, gx, gy);
}
const SaturateSlopes saturateSlopes =
    pickSimd<SaturateSlopes>(saturateSlopesAvx2, saturateSlopesBaseline);
#else
const SaturateSlopes saturateSlopes = saturateSlopesBaseline;
#endif

}  // namespace

std::string shadingFeatureNames() {
  std::string names;
  for (const char* name : kFeatureNames) names += (names.empty() ? "" : ", ") + std::string(name);
  return names;
}

std::array<std::array<double, kShadingFeatureCount>, 3> defaultShadingResponse() {
  // Fitted by norm2tex_calibrate on digit_calibration_s09 with slope_saturation 0.3 (see
  // config/digit.yaml, which holds the same numbers, and docs/calibration.md).
  // Rows B, G, R; columns in the order of shadingFeatureNames().
  return {{{{// blue
             -11.6549, -66.9970, -115.7654, -7.3730, 220.2167, 1.4765, -43.7759, -17.4153,
             23.8142, 69.4371, -229.6205, 127.9209, -18.0026, 78.2024, -75.3722, -8.2481,
             35.3787, -44.8325, -69.4913, -20.1452, 103.3825, -109.1378, -97.0656, 105.1620}},
           {{// green
             57.1098, -18.4961, 42.9353, 26.6173, -15.7187, -2.5161, 18.6744, -15.2371,
             19.9941, -47.5777, 68.5887, -45.4978, 94.5061, -81.1601, 98.9093, -86.4962,
             59.1973, -46.0293, -10.6551, -38.9401, -53.9935, 147.0741, 72.7469, -123.4794}},
           {{// red
             -109.4234, 79.9107, 125.1243, -16.7487, -56.4381, 11.9277, 86.1466, 5.9256,
             -141.1439, 36.5520, 94.9178, -87.7594, 127.7023, 149.1305, -131.6686, -116.5896,
             74.3790, 77.3305, -102.6713, -89.6208, 18.0551, 200.7395, -47.2826, -144.9630}}}};
}

int shadingReachPixels(double mm_per_pixel, double shadow_sigma_mm) {
  // The blur spreads the deformation by its radius; the central differences of its slopes by
  // one more pixel.
  return blurRadiusPixels(mm_per_pixel, shadow_sigma_mm) + 2;
}

void computeShadingFeatures(const cv::Mat1f& gel_mm, double mm_per_pixel,
                            const ShadingOptions& shading, const cv::Rect& box,
                            ShadingFeatureArray& features) {
  const double shadow_sigma_mm = shading.shadow_sigma_mm;
  const float inv_saturation_sq = slopeSaturationFactor(shading);
  if ((box & cv::Rect(0, 0, gel_mm.cols, gel_mm.rows)) != box || box.empty()) {
    throw Error("computeShadingFeatures: box outside the image");
  }
  for (cv::Mat1f& plane : features) plane.create(box.size());
  const float inv_pixel = static_cast<float>(1.0 / mm_per_pixel);
  const int last_row = gel_mm.rows - 1, last_col = gel_mm.cols - 1;
  const float inv_half_cols = 2.0f / gel_mm.cols, inv_half_rows = 2.0f / gel_mm.rows;

  // B = H blurred, over the box grown by one pixel for its differences (and by the kernel, so
  // the blur inside sees the real neighbourhood); a copy, so the image border replicates.
  const int radius = blurRadiusPixels(mm_per_pixel, shadow_sigma_mm);
  cv::Rect region(box.x - radius - 1, box.y - radius - 1, box.width + 2 * radius + 2,
                  box.height + 2 * radius + 2);
  region &= cv::Rect(0, 0, gel_mm.cols, gel_mm.rows);
  cv::Mat1f blurred;
  blurWide(gel_mm, region, shadow_sigma_mm / mm_per_pixel, blurred);

  for (int j = 0; j < box.height; ++j) {
    const int r = box.y + j;
    const int r0 = std::max(r - 1, 0), r1 = std::min(r + 1, last_row);
    const float dy_scale = inv_pixel / static_cast<float>(r1 - r0);
    const float* up = gel_mm.ptr<float>(r0);
    const float* mid = gel_mm.ptr<float>(r);
    const float* down = gel_mm.ptr<float>(r1);
    const float* b_up = blurred.ptr<float>(r0 - region.y);
    const float* b_mid = blurred.ptr<float>(r - region.y);
    const float* b_down = blurred.ptr<float>(r1 - region.y);
    float* out[kShadingFeatureCount];
    for (int f = 0; f < kShadingFeatureCount; ++f) out[f] = features[f].ptr<float>(j);
    for (int i = 0; i < box.width; ++i) {
      const int c = box.x + i;
      const int c0 = std::max(c - 1, 0), c1 = std::min(c + 1, last_col);
      const float dx_scale = inv_pixel / static_cast<float>(c1 - c0);
      float gx = (mid[c1] - mid[c0]) * dx_scale;
      float gy = (down[c] - up[c]) * dy_scale;
      if (inv_saturation_sq > 0.0f) saturateSlopes(1, inv_saturation_sq, &gx, &gy);
      const int bc = c - region.x, bc0 = c0 - region.x, bc1 = c1 - region.x;
      out[0][i] = gx;
      out[1][i] = gy;
      out[2][i] = gx * gx;
      out[3][i] = gx * gy;
      out[4][i] = gy * gy;
      out[5][i] = mid[c];
      const float rim = b_mid[bc] - mid[c];
      out[6][i] = std::max(rim, 0.0f);
      out[7][i] = std::min(rim, 0.0f);
      float bx = (b_mid[bc1] - b_mid[bc0]) * dx_scale;
      float by = (b_down[bc] - b_up[bc]) * dy_scale;
      if (inv_saturation_sq > 0.0f) saturateSlopes(1, inv_saturation_sq, &bx, &by);
      out[8][i] = std::max(bx, 0.0f);
      out[9][i] = std::max(-bx, 0.0f);
      out[10][i] = std::max(by, 0.0f);
      out[11][i] = std::max(-by, 0.0f);
      const float u = (c + 0.5f) * inv_half_cols - 1.0f, v = (r + 0.5f) * inv_half_rows - 1.0f;
      out[12][i] = gx * u;
      out[13][i] = gx * v;
      out[14][i] = gy * u;
      out[15][i] = gy * v;
      for (int q = 0; q < 4; ++q) {
        out[16 + 2 * q][i] = out[8 + q][i] * u;
        out[17 + 2 * q][i] = out[8 + q][i] * v;
      }
    }
  }
}

void computeShadingDifference(const cv::Mat1f& gel_mm, double mm_per_pixel,
                              const ShadingOptions& shading, const cv::Rect& box, cv::Mat3f& diff) {
  if ((box & cv::Rect(0, 0, gel_mm.cols, gel_mm.rows)) != box || box.empty()) {
    throw Error("computeShadingDifference: box outside the image");
  }
  diff.create(box.size());
  const float inv_pixel = static_cast<float>(1.0 / mm_per_pixel);
  const int last_row = gel_mm.rows - 1, last_col = gel_mm.cols - 1;
  const float inv_half_cols = 2.0f / gel_mm.cols, inv_half_rows = 2.0f / gel_mm.rows;
  const double sigma_mm = shading.shadow_sigma_mm;
  const float inv_saturation_sq = slopeSaturationFactor(shading);
  const int radius = blurRadiusPixels(mm_per_pixel, sigma_mm);
  cv::Rect region(box.x - radius - 1, box.y - radius - 1, box.width + 2 * radius + 2,
                  box.height + 2 * radius + 2);
  region &= cv::Rect(0, 0, gel_mm.cols, gel_mm.rows);
  thread_local cv::Mat1f blurred;
  blurWide(gel_mm, region, sigma_mm / mm_per_pixel, blurred);

  float w[3][kShadingFeatureCount];
  for (int k = 0; k < 3; ++k) {
    for (int f = 0; f < kShadingFeatureCount; ++f) {
      w[k][f] = static_cast<float>(shading.gain * shading.response_bgr[k][f]);
    }
  }
  // Base features whose coefficient varies with the position: slope_x, slope_y, rim_right,
  // rim_left, rim_down, rim_up, with their u- and v-terms.
  const int base[kVarying] = {0, 1, 8, 9, 10, 11};
  const int u_term[kVarying] = {12, 14, 16, 18, 20, 22};

  const int width = box.width;
  // Row buffers, reused per thread.
  thread_local std::vector<float> rows_scratch;
  rows_scratch.resize(9 * static_cast<std::size_t>(width));
  float* gx = rows_scratch.data();
  float* gy = gx + width;
  float* hh = gy + width;
  float* rim = hh + width;
  float* bx = rim + width;
  float* by = bx + width;
  float* out_b = by + width;
  float* out_g = out_b + width;
  float* out_r = out_g + width;
  RowCoefficients k;
  for (int c = 0; c < 3; ++c) {
    for (int q = 0; q < kConstant; ++q) k.fixed[c][q] = w[c][2 + q];  // features 2-7
    for (int q = 0; q < kVarying; ++q) k.b[c][q] = w[c][u_term[q]];
  }
  const float u0 = (box.x + 0.5f) * inv_half_cols - 1.0f;

  for (int j = 0; j < box.height; ++j) {
    const int r = box.y + j;
    const int r0 = std::max(r - 1, 0), r1 = std::min(r + 1, last_row);
    const float dy_scale = inv_pixel / static_cast<float>(r1 - r0);
    const float* up = gel_mm.ptr<float>(r0);
    const float* mid = gel_mm.ptr<float>(r);
    const float* down = gel_mm.ptr<float>(r1);
    const float* b_up = blurred.ptr<float>(r0 - region.y);
    const float* b_mid = blurred.ptr<float>(r - region.y);
    const float* b_down = blurred.ptr<float>(r1 - region.y);
    // Interior columns without clamping (so the compiler vectorises them); the image's first
    // and last columns take one-sided differences.
    const float half_inv_pixel = 0.5f * inv_pixel;
    const float* h_row = mid + box.x;
    const float* h_up = up + box.x;
    const float* h_down = down + box.x;
    const float* b_row = b_mid + (box.x - region.x);
    const float* b_row_up = b_up + (box.x - region.x);
    const float* b_row_down = b_down + (box.x - region.x);
    const int first = box.x == 0 ? 1 : 0;
    const int last = box.x + width - 1 == last_col ? width - 1 : width;
    differences(first, last, h_row, h_up, h_down, b_row, b_row_up, b_row_down, half_inv_pixel,
                dy_scale, gx, gy, hh, rim, bx, by);
    for (const int i : {0, width - 1}) {
      if (i >= first && i < last) continue;
      const int c = box.x + i;
      const int c0 = std::max(c - 1, 0), c1 = std::min(c + 1, last_col);
      const float dx_scale = inv_pixel / static_cast<float>(c1 - c0);
      const int bc = c - region.x, bc0 = c0 - region.x, bc1 = c1 - region.x;
      gx[i] = (mid[c1] - mid[c0]) * dx_scale;
      gy[i] = (down[c] - up[c]) * dy_scale;
      hh[i] = mid[c];
      rim[i] = b_mid[bc] - mid[c];
      bx[i] = (b_mid[bc1] - b_mid[bc0]) * dx_scale;
      by[i] = (b_down[bc] - b_up[bc]) * dy_scale;
    }
    const float v = (r + 0.5f) * inv_half_rows - 1.0f;
    for (int c = 0; c < 3; ++c) {
      for (int q = 0; q < kVarying; ++q) k.a[c][q] = w[c][base[q]] + w[c][u_term[q] + 1] * v;
    }
    if (inv_saturation_sq > 0.0f) {
      saturateSlopes(width, inv_saturation_sq, gx, gy);
      saturateSlopes(width, inv_saturation_sq, bx, by);
    }
    shadeRow(width, gx, gy, hh, rim, bx, by, u0, inv_half_cols, k, out_b, out_g, out_r);
    cv::Vec3f* row = diff.ptr<cv::Vec3f>(j);
    for (int i = 0; i < width; ++i) row[i] = cv::Vec3f(out_b[i], out_g[i], out_r[i]);
  }
}

void applyShadingResponse(const ShadingFeatureArray& features, const ShadingOptions& shading,
                          cv::Mat3f& diff) {
  const cv::Size size = features[0].size();
  diff.create(size);
  float weight[3][kShadingFeatureCount];
  for (int k = 0; k < 3; ++k) {
    for (int f = 0; f < kShadingFeatureCount; ++f) {
      weight[k][f] = static_cast<float>(shading.gain * shading.response_bgr[k][f]);
    }
  }
  for (int r = 0; r < size.height; ++r) {
    const float* in[kShadingFeatureCount];
    for (int f = 0; f < kShadingFeatureCount; ++f) in[f] = features[f].ptr<float>(r);
    float* out = diff.ptr<float>(r);
    for (int c = 0; c < size.width; ++c) {
      float b = 0.0f, g = 0.0f, red = 0.0f;
      for (int f = 0; f < kShadingFeatureCount; ++f) {
        const float value = in[f][c];
        b += weight[0][f] * value;
        g += weight[1][f] * value;
        red += weight[2][f] * value;
      }
      out[3 * c] = b;
      out[3 * c + 1] = g;
      out[3 * c + 2] = red;
    }
  }
}

}  // namespace norm2tex
