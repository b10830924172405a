#include "norm2tex/render/digit_shader.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core/hal/intrin.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/render/digit_shader_response.hpp"

namespace norm2tex {
namespace {

// analytic_leds response: x = kShadingScale * (shading(H) - shading(flat)) per channel, in grey
// levels per unit of n . l, then a soft knee x / (1 + |x| / kKneeGreyLevels) and shading_gain.
// Fitted so that a ball of 8.8 mm pressed 1.5 mm into the gel, through the GelModel, differs from
// the background inside the contact by 32 grey levels on average with a 95th percentile of 44 and
// a peak of 94; real DIGIT ball presses measure about 29 and 48. Our contact shading is more
// uniform than a real one (48 / 29 = 1.65 there, 1.4 here), so mean and tail cannot both
// match; a strong knee (70) matched the mean (30) but cut the tail to 36. The knee keeps steep
// rims from burning out: the brightest background channel (~135) plus 100 stays below 255.
constexpr float kShadingScale = 205.0f;
constexpr float kKneeGreyLevels = 300.0f;

// Light falls off as (d_centre / d)^kFalloffExponent, normalised to 1 at the gel centre. TACTO
// uses 1/d^2, but with the LEDs ~9 mm from the nearest image corner that makes a press near an
// LED 5x stronger than at the centre; 1/d keeps the LED-side emphasis mild (at most ~2.3x).
constexpr double kFalloffExponent = 1.0;

// analytic_leds: pixels whose shading is computed extend this far beyond the last non-zero
// indentation: the central differences of a pixel next to the contact see it.
constexpr int kAnalyticReach = 2;

// The per-pixel planes get this many spare columns so that the 4-wide SIMD loop may run past a
// box's last column without a scalar tail.
constexpr int kLanes = 4;

// Lambertian shading of the membrane's inner side with slopes (dz/dx, dz/dy) of the surface
// z(x, y): inner normal (dz/dx, dz/dy, -1) / |.|, towards the camera and the LEDs.
inline cv::Vec3f shadePixel(float dzdx, float dzdy, const cv::Vec3f* lights,
                            const cv::Vec3f* colours) {
  const float inv_norm = 1.0f / std::sqrt(dzdx * dzdx + dzdy * dzdy + 1.0f);
  cv::Vec3f result(0.0f, 0.0f, 0.0f);
  for (int i = 0; i < 3; ++i) {
    const cv::Vec3f& l = lights[i];
    const float lambert = std::max(0.0f, (dzdx * l[0] + dzdy * l[1] - l[2]) * inv_norm);
    result += colours[i] * lambert;
  }
  return result;
}

/// out[i] = background[i] + round(a[i] (+ b[i])), the float rounded half to even and the sum
/// saturated to 0..255: what cv::add(background, a, out, noArray(), CV_8U) computes (it rounds
/// the float operand to int32 first), without its conversions of whole rows. With b, a + b is
/// summed in float first (the diff added into the noise, then the noise to the background).
void addToBackground(const uchar* background, const float* a, const float* b, uchar* out, int n) {
  int i = 0;
  constexpr int kStep = cv::v_uint8x16::nlanes;
  for (; i + kStep <= n; i += kStep) {
    cv::v_uint16x8 bg16[2];
    cv::v_expand(cv::v_load(background + i), bg16[0], bg16[1]);
    cv::v_int16x8 rounded16[2];
    for (int half = 0; half < 2; ++half) {
      cv::v_uint32x4 bg32[2];
      cv::v_expand(bg16[half], bg32[0], bg32[1]);
      cv::v_int32x4 rounded[2];
      for (int quarter = 0; quarter < 2; ++quarter) {
        const int at = i + 8 * half + 4 * quarter;
        cv::v_float32x4 add = cv::v_load(a + at);
        if (b != nullptr) add = add + cv::v_load(b + at);
        rounded[quarter] = cv::v_round(add) + cv::v_reinterpret_as_s32(bg32[quarter]);
      }
      rounded16[half] = cv::v_pack(rounded[0], rounded[1]);  // saturating
    }
    cv::v_store(out + i, cv::v_pack_u(rounded16[0], rounded16[1]));  // saturating
  }
  for (; i < n; ++i) {
    const float add = b != nullptr ? a[i] + b[i] : a[i];
    out[i] = cv::saturate_cast<uchar>(static_cast<int>(background[i]) + cvRound(add));
  }
}

}  // namespace

DigitShader::DigitShader(const SensorModel& model, cv::Mat3b background, BackgroundSource source)
    : model_((validate(model), model)), background_(std::move(background)), noise_(model.noise) {
  adds_noise_ = source == BackgroundSource::kSynthetic || model_.noise.on_real_background;
  reach_px_ = model_.shading.kind == ShadingKind::kCalibrated
                  ? shadingReachPixels(model_.mm_per_pixel, model_.shading.shadow_sigma_mm)
                  : kAnalyticReach;
  if (background_.empty() || background_.type() != CV_8UC3) {
    throw Error("DigitShader: background image is empty or not 8-bit BGR (CV_8UC3)");
  }
  if (background_.size() != model_.imageSize()) {
    throw Error("DigitShader: background image is " + std::to_string(background_.cols) + " x " +
                std::to_string(background_.rows) + " (cols x rows) but the sensor image is " +
                std::to_string(model_.cols) + " x " + std::to_string(model_.rows));
  }
  // Own copy: the caller may keep writing into theirs.
  background_ = background_.clone();

  const int rows = model_.rows, cols = model_.cols;
  const auto makePlane = [&] { return cv::Mat1f(rows, cols + kLanes, 0.0f); };
  for (cv::Mat1f& plane : light_planes_) plane = makePlane();
  for (cv::Mat1f& plane : flat_planes_) plane = makePlane();
  const double dome_radius = model_.gel_curvature_radius_mm;
  if (dome_radius > 0.0) {
    for (cv::Mat1f& plane : dome_planes_) plane = makePlane();
  }
  for (int i = 0; i < 3; ++i) {
    const LedModel& led = model_.leds[i];
    led_colours_[i] = cv::Vec3f(led.color_bgr * led.intensity) * kShadingScale;
  }

  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const cv::Point2d xy = model_.pixelToGelMm(r, c);
      double z = 0.0, dzdx = 0.0, dzdy = 0.0;
      if (dome_radius > 0.0) {
        // Dome bulging towards +z; clamped short of its rim, which may lie inside the image.
        const double rim = 0.95 * dome_radius;
        const double rho2 = std::min(xy.x * xy.x + xy.y * xy.y, rim * rim);
        const double root = std::sqrt(dome_radius * dome_radius - rho2);
        z = root - dome_radius;
        dzdx = -xy.x / root;
        dzdy = -xy.y / root;
        dome_planes_[0](r, c) = static_cast<float>(dzdx);
        dome_planes_[1](r, c) = static_cast<float>(dzdy);
      }
      cv::Vec3f lights[3];
      for (int i = 0; i < 3; ++i) {
        const cv::Vec3d& led = model_.leds[i].position_mm;
        const cv::Vec3d to_led = led - cv::Vec3d(xy.x, xy.y, z);
        const double distance = std::max(cv::norm(to_led), 1e-3);
        const double weight = std::pow(std::max(cv::norm(led), 1e-3) / distance, kFalloffExponent);
        lights[i] = cv::Vec3f(to_led * (weight / distance));
        for (int k = 0; k < 3; ++k) light_planes_[3 * i + k](r, c) = lights[i][k];
      }
      const cv::Vec3f flat = shadePixel(static_cast<float>(dzdx), static_cast<float>(dzdy), lights,
                                        led_colours_.data());
      for (int k = 0; k < 3; ++k) flat_planes_[k](r, c) = flat[k];
    }
  }
}

void DigitShader::checkHeight(const cv::Mat1f& h_final_mm) const {
  if (h_final_mm.empty() || h_final_mm.size() != model_.imageSize()) {
    throw Error("DigitShader: h_final_mm is " + std::to_string(h_final_mm.cols) + " x " +
                std::to_string(h_final_mm.rows) + " (cols x rows) but the sensor image is " +
                std::to_string(model_.cols) + " x " + std::to_string(model_.rows));
  }
}

cv::Rect DigitShader::contactBox(const cv::Mat1f& h) const {
  int top = h.rows, bottom = -1, left = h.cols, right = -1;
  for (int r = 0; r < h.rows; ++r) {
    const float* row = h.ptr<float>(r);
    int first = 0;
    while (first < h.cols && row[first] == 0.0f) ++first;
    if (first == h.cols) continue;
    int last = h.cols - 1;
    while (row[last] == 0.0f) --last;
    top = std::min(top, r);
    bottom = r;
    left = std::min(left, first);
    right = std::max(right, last);
  }
  if (bottom < 0) return {};
  const cv::Rect box(left - reach_px_, top - reach_px_, right - left + 1 + 2 * reach_px_,
                     bottom - top + 1 + 2 * reach_px_);
  return box & cv::Rect(0, 0, h.cols, h.rows);
}

void DigitShader::shadeBox(const cv::Mat1f& h, const cv::Rect& box, cv::Mat3f& diff) const {
  if (model_.shading.kind == ShadingKind::kAnalyticLeds) {
    shadeBoxAnalytic(h, box, diff);
    return;
  }
  // NaN or infinity anywhere in the box would spread through the features. x - x is 0 exactly
  // for a finite x and NaN otherwise; counted in integers, the loop vectorises (cv::checkRange
  // took a tenth of the shading time).
  int non_finite = 0;
  for (int r = box.y; r < box.y + box.height; ++r) {
    const float* row = h.ptr<float>(r) + box.x;
    for (int i = 0; i < box.width; ++i) non_finite += !(row[i] - row[i] == 0.0f);
  }
  if (non_finite > 0) throw Error("DigitShader: h_final_mm contains NaN or infinite values");
  computeShadingDifference(h, model_.mm_per_pixel, model_.shading, box, diff);
}

void DigitShader::shadeBoxAnalytic(const cv::Mat1f& h, const cv::Rect& box, cv::Mat3f& diff) const {
  // Slopes in consistent units: dH (mm) over the pixel spacing (mm).
  const float inv_pixel = static_cast<float>(1.0 / model_.mm_per_pixel);
  const int last_row = h.rows - 1, last_col = h.cols - 1;
  const int width = box.width;
  const int padded = (width + kLanes - 1) / kLanes * kLanes;
  std::vector<float> hx(padded, 0.0f), hy(padded, 0.0f), out_row(3 * padded);

  using cv::v_float32x4;
  const v_float32x4 zero = cv::v_setzero_f32(), one = cv::v_setall_f32(1.0f);
  const v_float32x4 gain = cv::v_setall_f32(static_cast<float>(model_.shading.gain));
  const v_float32x4 inv_knee = cv::v_setall_f32(1.0f / kKneeGreyLevels);
  v_float32x4 colour[3][3];  // [led][channel]
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) colour[i][k] = cv::v_setall_f32(led_colours_[i][k]);
  }
  const bool dome = !dome_planes_[0].empty();
  v_float32x4 invalid = zero;  // lanes that saw NaN (from NaN or infinite indentation)

  for (int r = box.y; r < box.y + box.height; ++r) {
    const int r0 = std::max(r - 1, 0), r1 = std::min(r + 1, last_row);
    const float* up = h.ptr<float>(r0);
    const float* mid = h.ptr<float>(r);
    const float* down = h.ptr<float>(r1);
    const float dy_scale = inv_pixel / static_cast<float>(r1 - r0);
    // Central differences, one-sided at the image border.
    for (int j = 0; j < width; ++j) {
      const int c = box.x + j;
      const int c0 = std::max(c - 1, 0), c1 = std::min(c + 1, last_col);
      hx[j] = (mid[c1] - mid[c0]) * (inv_pixel / static_cast<float>(c1 - c0));
      hy[j] = (down[c] - up[c]) * dy_scale;
    }
    const float* light[9];
    for (int q = 0; q < 9; ++q) light[q] = light_planes_[q].ptr<float>(r) + box.x;
    const float* flat[3];
    for (int k = 0; k < 3; ++k) flat[k] = flat_planes_[k].ptr<float>(r) + box.x;
    const float* dome_x = dome ? dome_planes_[0].ptr<float>(r) + box.x : nullptr;
    const float* dome_y = dome ? dome_planes_[1].ptr<float>(r) + box.x : nullptr;

    for (int j = 0; j < padded; j += kLanes) {
      const v_float32x4 slope_x = cv::v_load(&hx[j]), slope_y = cv::v_load(&hy[j]);
      // The gel surface is z = dome - H: indentation moves it towards the camera (-z).
      v_float32x4 gx = zero - slope_x, gy = zero - slope_y;
      if (dome) {
        gx = gx + cv::v_load(dome_x + j);
        gy = gy + cv::v_load(dome_y + j);
      }
      const v_float32x4 inv_norm = one / cv::v_sqrt(gx * gx + gy * gy + one);
      v_float32x4 channel[3];
      for (int k = 0; k < 3; ++k) channel[k] = zero - cv::v_load(flat[k] + j);
      for (int i = 0; i < 3; ++i) {
        const v_float32x4 lx = cv::v_load(light[3 * i] + j), ly = cv::v_load(light[3 * i + 1] + j),
                          lz = cv::v_load(light[3 * i + 2] + j);
        const v_float32x4 lambert = cv::v_max(zero, (gx * lx + gy * ly - lz) * inv_norm);
        for (int k = 0; k < 3; ++k) channel[k] = channel[k] + colour[i][k] * lambert;
      }
      // Locally flat pixels get exactly 0, so the frame there is the background bit for bit.
      const v_float32x4 flat_here = (slope_x == zero) & (slope_y == zero);
      for (int k = 0; k < 3; ++k) {
        invalid = invalid | (channel[k] != channel[k]);
        const v_float32x4 knee = gain * channel[k] / (one + cv::v_abs(channel[k]) * inv_knee);
        channel[k] = cv::v_select(flat_here, zero, knee);
      }
      cv::v_store_interleave(&out_row[3 * j], channel[0], channel[1], channel[2]);
    }
    std::copy_n(out_row.data(), 3 * width, diff.ptr<float>(r - box.y));
  }
  if (cv::v_check_any(invalid)) {
    throw Error("DigitShader: h_final_mm contains NaN or infinite values");
  }
}

cv::Mat3f DigitShader::shadingDifference(const cv::Mat1f& h_final_mm) const {
  checkHeight(h_final_mm);
  cv::Mat3f diff(h_final_mm.size(), cv::Vec3f(0.0f, 0.0f, 0.0f));
  const cv::Rect box = contactBox(h_final_mm);
  if (!box.empty()) {
    cv::Mat3f roi = diff(box);
    shadeBox(h_final_mm, box, roi);
  }
  return diff;
}

cv::Mat3b DigitShader::shade(const cv::Mat1f& h_final_mm, std::int64_t noise_seed) const {
  checkHeight(h_final_mm);
  const cv::Rect box = contactBox(h_final_mm);
  // Reused per thread: fresh pages cost ~13 us each on these VMs, a big press's box ~0.5 MB.
  thread_local cv::Mat3f diff_scratch;
  cv::Mat3f diff;
  if (!box.empty()) {
    if (diff_scratch.rows < box.height || diff_scratch.cols < box.width) {
      diff_scratch.create(std::max(box.height, diff_scratch.rows),
                          std::max(box.width, diff_scratch.cols));
    }
    diff = diff_scratch(cv::Rect(0, 0, box.width, box.height));
    shadeBox(h_final_mm, box, diff);
  }
  cv::Mat3b image(background_.size());
  const int width = background_.cols;
  if (noise_seed < 0 || !addsNoise()) {
    // background + diff in the box, rounded and saturated; the background elsewhere.
    for (int r = 0; r < image.rows; ++r) {
      const uchar* background = background_.ptr<uchar>(r);
      uchar* out = image.ptr<uchar>(r);
      if (r < box.y || r >= box.y + box.height) {
        std::copy_n(background, 3 * width, out);
        continue;
      }
      std::copy_n(background, 3 * box.x, out);
      addToBackground(background + 3 * box.x, diff.ptr<float>(r - box.y), nullptr, out + 3 * box.x,
                      3 * box.width);
      const int right = 3 * (box.x + box.width);
      std::copy_n(background + right, 3 * width - right, out + right);
    }
    return image;
  }
  // The noise covers the whole frame, independent of the box: a pixel's noise depends only on
  // the seed and its position. Background + (noise + diff), rounded and saturated.
  thread_local cv::Mat3f noise;  // reused per thread, like diff_scratch
  noise_.generate(image.size(), static_cast<std::uint64_t>(noise_seed), noise);
  for (int r = 0; r < image.rows; ++r) {
    const uchar* background = background_.ptr<uchar>(r);
    const float* row_noise = noise.ptr<float>(r);
    uchar* out = image.ptr<uchar>(r);
    if (r < box.y || r >= box.y + box.height) {
      addToBackground(background, row_noise, nullptr, out, 3 * width);
      continue;
    }
    const int left = 3 * box.x, right = 3 * (box.x + box.width);
    addToBackground(background, row_noise, nullptr, out, left);
    addToBackground(background + left, row_noise + left, diff.ptr<float>(r - box.y), out + left,
                    right - left);
    addToBackground(background + right, row_noise + right, nullptr, out + right, 3 * width - right);
  }
  return image;
}

}  // namespace norm2tex
