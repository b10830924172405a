// DIGIT no-contact backgrounds: a synthetic one and the user's own frame.
//
// The synthetic frame is a few smooth analytic terms in normalised image coordinates
// (u = column / width, v = row / height, both in [0, 1]), so it looks the same at any size:
//
//   I_bgr(u, v) = vignette(u, v) * (base_bgr + sum_j colour_j * glow_j(u, v))
//
// with four anisotropic, rotated Gaussian glows (the red LED's upper-left glow, the green LED's
// glow on the right, a blue-violet lobe lower-left and a cyan-blue wash along the top edge) and
// a radial vignette 1 - 0.30 * (r / r_corner)^2.2 (70 % brightness in the corners). The
// coefficients were fitted once, by hand-run least squares with non-negative colours, to a
// real DIGIT no-contact frame (TACTO's bg_digit_240_320.jpg), then rounded; nothing is read at
// run time.
//
// Targets (BGR means of real frames; regions are thirds of the image) and what this reaches
// at 240 x 320 (the same at 480 x 640):
//   global          target ( 99, 105,  99)   reached ( 98.5, 105.1,  99.0)
//   top-left        target (117, 106, 133)   reached (114.6, 101.7, 132.6)
//   top-right       target (105, 117,  73)   reached (103.4, 116.4,  75.3)
//   bottom-centre   target ( 98,  92,  70)   reached ( 97.7,  92.5,  66.6)
//   centre          target (102, 123, 134)   reached (103.6, 120.7, 130.5)
// RMS difference to the real frame (after area-downsampling it to 48 x 64): 6.7 grey levels.
// Real sensors differ from unit to unit (global means (87, 92, 90) to (104, 112, 105)), so a
// user's own frame (loadBackground) is always the better choice.

#include <cmath>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "norm2tex/render/digit_shader.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/image_io.hpp"

namespace norm2tex {
namespace {

struct Glow {
  double centre_u, centre_v;  // normalised image coordinates; may lie outside [0, 1]
  double sigma_a, sigma_b;    // along the rotated axes, normalised units
  double angle;               // radians, axis a measured from +u towards +v
  cv::Vec3d colour_bgr;       // grey levels at the glow's peak (before vignetting)
};

const Glow kGlows[] = {
    {0.235, 0.359, 0.273, 0.400, 1.014, {0.0, 0.0, 145.0}},    // red LED, upper-left
    {0.892, 0.432, 0.528, 0.318, 0.228, {0.0, 51.5, 0.0}},     // green LED, right
    {0.264, 0.690, 0.367, 0.191, 0.137, {73.4, 0.0, 0.0}},     // blue-violet lobe, lower-left
    {0.606, -0.100, 0.900, 0.271, -0.132, {111.5, 26.7, 0.0}}  // cyan-blue wash, top edge
};
const cv::Vec3d kBaseBgr(59.0, 83.9, 47.8);
constexpr double kVignetteStrength = 0.30;  // 1 - this = brightness left in the corners
constexpr double kVignettePower = 2.2;

}  // namespace

cv::Mat3b makeSyntheticBackground(cv::Size size) {
  if (size.width <= 0 || size.height <= 0) {
    throw Error("makeSyntheticBackground: image size " + std::to_string(size.width) + " x " +
                std::to_string(size.height) + " is not valid; both must be > 0");
  }
  cv::Mat3b image(size);
  for (int r = 0; r < size.height; ++r) {
    const double v = (r + 0.5) / size.height;
    for (int c = 0; c < size.width; ++c) {
      const double u = (c + 0.5) / size.width;
      const double du = 2.0 * u - 1.0, dv = 2.0 * v - 1.0;
      const double radius = std::sqrt((du * du + dv * dv) / 2.0);  // 1 in the corners
      const double vignette = 1.0 - kVignetteStrength * std::pow(radius, kVignettePower);
      cv::Vec3d value = kBaseBgr;
      for (const Glow& glow : kGlows) {
        const double x = u - glow.centre_u, y = v - glow.centre_v;
        const double ca = std::cos(glow.angle), sa = std::sin(glow.angle);
        const double a = (ca * x + sa * y) / glow.sigma_a;
        const double b = (-sa * x + ca * y) / glow.sigma_b;
        value += glow.colour_bgr * std::exp(-0.5 * (a * a + b * b));
      }
      for (int k = 0; k < 3; ++k) image(r, c)[k] = cv::saturate_cast<uchar>(vignette * value[k]);
    }
  }
  return image;
}

cv::Mat3b loadBackground(const std::string& path, cv::Size size) {
  if (size.width <= 0 || size.height <= 0) {
    throw Error("background image '" + path + "': requested size " + std::to_string(size.width) +
                " x " + std::to_string(size.height) + " is not valid");
  }
  // UNCHANGED keeps 16-bit depth and alpha so both can be handled explicitly below.
  cv::Mat image = readImage(path, cv::IMREAD_UNCHANGED, "background image");
  if (image.depth() == CV_16U) {
    image.convertTo(image, CV_8U, 255.0 / 65535.0);
  } else if (image.depth() != CV_8U) {
    throw Error("background image '" + path +
                "' has an unsupported pixel depth (only 8- and 16-bit integer images are "
                "accepted)");
  }
  switch (image.channels()) {
    case 1:
      cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);
      break;
    case 3:
      break;
    case 4:
      cv::cvtColor(image, image, cv::COLOR_BGRA2BGR);  // alpha means nothing for a frame
      break;
    default:
      throw Error("background image '" + path + "' has " + std::to_string(image.channels()) +
                  " channels; valid: 1 (gray), 3 (BGR) or 4 (BGRA)");
  }
  // Resizing between presets is fine (a VGA frame for a QVGA model), but a landscape frame for
  // a portrait sensor is a frame the driver did not transpose: stretching it would put the LED
  // glows in the wrong places without anyone noticing.
  const bool image_portrait = image.rows > image.cols, model_portrait = size.height > size.width;
  if (image.rows != image.cols && size.height != size.width && image_portrait != model_portrait) {
    throw Error("background image '" + path + "' is " + std::to_string(image.cols) + " x " +
                std::to_string(image.rows) + " (" + (image_portrait ? "portrait" : "landscape") +
                ") but the sensor image is " + std::to_string(size.width) + " x " +
                std::to_string(size.height) + " (" + (model_portrait ? "portrait" : "landscape") +
                "); rotate it the way your driver publishes frames");
  }
  if (image.size() != size) cv::resize(image, image, size, 0.0, 0.0, cv::INTER_AREA);
  return image;
}

}  // namespace norm2tex
