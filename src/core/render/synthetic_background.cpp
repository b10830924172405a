// The synthetic no-contact frame: a few smooth analytic terms in normalised image coordinates
// (u = column / width, v = row / height, both in [0, 1]), so it looks the same at any size:
//
//   I_bgr(u, v) = vignette(u, v) * (base_bgr + sum_j colour_j * glow_j(u, v))
//
// with anisotropic, rotated Gaussian glows and a radial vignette 1 - s * (r / r_corner)^p. The
// numbers are the sensor's (SensorModel::synthetic_background, a yaml's synthetic_background
// section); the defaults below are the DIGIT's.
//
// The DIGIT's four glows (the red LED's upper-left glow, the green LED's glow on the right, a
// blue-violet lobe lower-left and a cyan-blue wash along the top edge), its base and its vignette
// (0.30, 2.2: 70 % brightness in the corners) were fitted once, by hand-run least squares with
// non-negative colours, to a real DIGIT no-contact frame (TACTO's bg_digit_240_320.jpg), then
// rounded; nothing is read at run time. Targets (BGR means of real frames; regions are thirds of
// the image) and what they reach at 240 x 320 (the same at 480 x 640):
//   global          target ( 99, 105,  99)   reached ( 98.5, 105.1,  99.0)
//   top-left        target (117, 106, 133)   reached (114.6, 101.7, 132.6)
//   top-right       target (105, 117,  73)   reached (103.4, 116.4,  75.3)
//   bottom-centre   target ( 98,  92,  70)   reached ( 97.7,  92.5,  66.6)
//   centre          target (102, 123, 134)   reached (103.6, 120.7, 130.5)
// RMS difference to the real frame (after area-downsampling it to 48 x 64): 6.7 grey levels.
// Real sensors differ from unit to unit (global means (87, 92, 90) to (104, 112, 105)), so a
// user's own frame (loadBackground) is always the better choice.

#include "norm2tex/render/synthetic_background.hpp"

#include <cmath>
#include <string>

#include "common/error_messages.hpp"
#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

constexpr std::size_t kMaxGlows = 16;  // a look is a few smooth terms, not an image
constexpr double kTwoPi = 6.283185307179586;

}  // namespace

std::vector<BackgroundGlow> digitBackgroundGlows() {
  return {
      {{0.235, 0.359}, {0.273, 0.400}, 1.014, {0.0, 0.0, 145.0}},     // red LED, upper-left
      {{0.892, 0.432}, {0.528, 0.318}, 0.228, {0.0, 51.5, 0.0}},      // green LED, right
      {{0.264, 0.690}, {0.367, 0.191}, 0.137, {73.4, 0.0, 0.0}},      // blue-violet, lower-left
      {{0.606, -0.100}, {0.900, 0.271}, -0.132, {111.5, 26.7, 0.0}},  // cyan-blue wash, top
  };
}

void validate(const SyntheticBackgroundOptions& look) {
  using detail::requireParameter;
  const std::string where = "synthetic_background.";
  for (int k = 0; k < 3; ++k) {
    requireParameter(look.base_bgr[k] >= 0.0 && look.base_bgr[k] <= 255.0, where + "base_bgr",
                     look.base_bgr[k], "[0, 255] grey levels per channel");
  }
  // At strength 1 the corners go black; beyond it the vignette would turn negative.
  requireParameter(look.vignette_strength >= 0.0 && look.vignette_strength < 1.0,
                   where + "vignette_strength", look.vignette_strength, "[0, 1)");
  requireParameter(look.vignette_power > 0.0 && look.vignette_power <= 10.0,
                   where + "vignette_power", look.vignette_power, "(0, 10]");
  requireParameter(look.glows.size() <= kMaxGlows, where + "glows", look.glows.size(),
                   "at most " + std::to_string(kMaxGlows) + " glows");
  for (std::size_t j = 0; j < look.glows.size(); ++j) {
    const BackgroundGlow& g = look.glows[j];
    const std::string name = where + "glows[" + std::to_string(j) + "].";
    for (int i = 0; i < 2; ++i) {
      requireParameter(std::isfinite(g.centre_uv[i]) && std::abs(g.centre_uv[i] - 0.5) <= 2.5,
                       name + "centre_uv", g.centre_uv[i], "[-2, 3] (image widths / heights)");
      requireParameter(g.sigma_uv[i] > 0.0 && g.sigma_uv[i] <= 10.0, name + "sigma_uv",
                       g.sigma_uv[i], "(0, 10] (image widths / heights)");
    }
    requireParameter(std::isfinite(g.angle_rad) && std::abs(g.angle_rad) <= kTwoPi,
                     name + "angle_rad", g.angle_rad, "[-2 pi, 2 pi]");
    for (int k = 0; k < 3; ++k) {
      // Glows add light; a darker region is a lower base and brighter glows elsewhere.
      requireParameter(g.color_bgr[k] >= 0.0 && g.color_bgr[k] <= 255.0, name + "color_bgr",
                       g.color_bgr[k], "[0, 255] grey levels per channel");
    }
  }
}

cv::Mat3b makeSyntheticBackground(const SyntheticBackgroundOptions& look, cv::Size size) {
  if (size.width <= 0 || size.height <= 0) {
    throw Error("makeSyntheticBackground: image size " + std::to_string(size.width) + " x " +
                std::to_string(size.height) + " is not valid; both must be > 0");
  }
  validate(look);
  cv::Mat3b image(size);
  for (int r = 0; r < size.height; ++r) {
    const double v = (r + 0.5) / size.height;
    for (int c = 0; c < size.width; ++c) {
      const double u = (c + 0.5) / size.width;
      const double du = 2.0 * u - 1.0, dv = 2.0 * v - 1.0;
      const double radius = std::sqrt((du * du + dv * dv) / 2.0);  // 1 in the corners
      const double vignette = 1.0 - look.vignette_strength * std::pow(radius, look.vignette_power);
      cv::Vec3d value = look.base_bgr;
      for (const BackgroundGlow& glow : look.glows) {
        const double x = u - glow.centre_uv[0], y = v - glow.centre_uv[1];
        const double ca = std::cos(glow.angle_rad), sa = std::sin(glow.angle_rad);
        const double a = (ca * x + sa * y) / glow.sigma_uv[0];
        const double b = (-sa * x + ca * y) / glow.sigma_uv[1];
        value += glow.color_bgr * std::exp(-0.5 * (a * a + b * b));
      }
      for (int k = 0; k < 3; ++k) image(r, c)[k] = cv::saturate_cast<uchar>(vignette * value[k]);
    }
  }
  return image;
}

cv::Mat3b makeSyntheticBackground(const SensorModel& model) {
  return makeSyntheticBackground(model.synthetic_background, model.imageSize());
}

}  // namespace norm2tex
