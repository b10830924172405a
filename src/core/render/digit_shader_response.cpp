#include "norm2tex/render/digit_shader_response.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

const char* const kFeatureNames[kShadingFeatureCount] = {
    "slope_x", "slope_y", "slope_xx", "slope_xy", "slope_yy",
    "depth",   "rim_out", "rim_in", "rim_right", "rim_left", "rim_down", "rim_up",
    "slope_x*u", "slope_x*v", "slope_y*u", "slope_y*v",
    "rim_right*u", "rim_right*v", "rim_left*u", "rim_left*v", "rim_down*u", "rim_down*v", "rim_up*u", "rim_up*v"};


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

cv::Mat1f blurWide(const cv::Mat1f& gel_mm, const cv::Rect& region, double sigma_px) {
  const int factor = reductionFactor(sigma_px);
  // The region snapped outwards to the reduced grid, padded by replication past the image.
  const int x0 = region.x / factor * factor, y0 = region.y / factor * factor;
  const int x1 = (region.x + region.width + factor - 1) / factor * factor;
  const int y1 = (region.y + region.height + factor - 1) / factor * factor;
  const cv::Rect inside = cv::Rect(x0, y0, x1 - x0, y1 - y0) & cv::Rect(0, 0, gel_mm.cols, gel_mm.rows);
  cv::Mat1f snapped;
  cv::copyMakeBorder(gel_mm(inside), snapped, 0, y1 - y0 - inside.height, 0,
                     x1 - x0 - inside.width, cv::BORDER_REPLICATE);
  cv::Mat1f small = snapped;
  if (factor > 1) {
    cv::resize(snapped, small, cv::Size(snapped.cols / factor, snapped.rows / factor), 0, 0,
               cv::INTER_AREA);
  }
  const double sigma_small = sigma_px / factor;
  const int radius = std::max(1, static_cast<int>(std::ceil(3.0 * sigma_small)));
  cv::GaussianBlur(small, small, cv::Size(2 * radius + 1, 2 * radius + 1), sigma_small,
                   sigma_small, cv::BORDER_REPLICATE);
  cv::Mat1f full = small;
  if (factor > 1) cv::resize(small, full, snapped.size(), 0, 0, cv::INTER_LINEAR);
  return full(cv::Rect(region.x - x0, region.y - y0, region.width, region.height)).clone();
}

}  // namespace

std::string shadingFeatureNames() {
  std::string names;
  for (const char* name : kFeatureNames) names += (names.empty() ? "" : ", ") + std::string(name);
  return names;
}

std::array<std::array<double, kShadingFeatureCount>, 3> defaultShadingResponse() {
  // Fitted by norm2tex_calibrate on digit_calibration_s09 (see config/digit.yaml, which holds
  // the same numbers, and README "Calibrate your own DIGIT").
  // Rows B, G, R; columns in the order of shadingFeatureNames().
  return {{
      {{ // blue
       -3.6166, -26.2962, -23.5339, 19.5477, 25.0835, 1.1766,
       -61.4783, -23.3168, -1.0589, 40.9249, -172.7516, 142.9430,
       -7.3757, 42.1034, -16.4764, -15.1360, 30.5700, -46.4823,
       -38.9442, -28.6223, 74.1642, -83.1572, -89.1423, 106.7472
      }},
      {{ // green
       17.4984, -13.0831, 10.3890, 9.4435, -9.5117, -1.5107,
       4.7807, -15.6215, 34.5059, -70.0997, 63.1788, -33.9835,
       28.5503, -39.5099, 40.3749, -44.6347, 49.6234, -19.7042,
       -12.6004, -38.2827, -28.8037, 107.4135, 45.2342, -85.6666
      }},
      {{ // red
       -39.3929, 34.2037, 44.6670, -25.9116, -2.9154, 5.4930,
       75.1308, -15.8227, -148.2101, 73.2994, 94.1257, -77.5468,
       38.7029, 40.9097, -69.1293, -57.1095, 167.2225, 84.5907,
       -131.6373, -86.4209, -24.2894, 138.3149, -26.1234, -98.0533
      }}
  }};
}

int shadingReachPixels(double mm_per_pixel, double shadow_sigma_mm) {
  // The blur spreads the deformation by its radius; the central differences of its slopes by
  // one more pixel.
  return blurRadiusPixels(mm_per_pixel, shadow_sigma_mm) + 2;
}

void computeShadingFeatures(const cv::Mat1f& gel_mm, double mm_per_pixel, double shadow_sigma_mm,
                            const cv::Rect& box, ShadingFeatureArray& features) {
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
  const cv::Mat1f blurred = blurWide(gel_mm, region, shadow_sigma_mm / mm_per_pixel);

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
      const float gx = (mid[c1] - mid[c0]) * dx_scale;
      const float gy = (down[c] - up[c]) * dy_scale;
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
      const float bx = (b_mid[bc1] - b_mid[bc0]) * dx_scale;
      const float by = (b_down[bc] - b_up[bc]) * dy_scale;
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
