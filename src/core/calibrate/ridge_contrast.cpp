#include "norm2tex/calibrate/ridge_contrast.hpp"

#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A 1-D Gaussian kernel of `sigma` px (radius 4 sigma), normalised.
cv::Mat1f gaussianKernel(double sigma) {
  const int radius = static_cast<int>(std::ceil(4.0 * sigma));
  return cv::getGaussianKernel(2 * radius + 1, sigma, CV_32F);
}

// Sum over the channels of the band's mean square in `box`.
double meanSquare(const cv::Mat3f& band, const cv::Rect& box) {
  cv::Mat3f squared;
  cv::multiply(band(box), band(box), squared);
  const cv::Scalar mean = cv::mean(squared);
  return mean[0] + mean[1] + mean[2];
}

}  // namespace

RidgeContrast measureRidgeContrast(const cv::Mat3b& frame, const cv::Mat3b& background,
                                   const cv::Rect& box, const cv::Rect& noise_box,
                                   const RidgeContrastOptions& options) {
  if (frame.empty() || frame.size() != background.size()) {
    throw Error("ridge contrast: the frame and the background differ in size (or are empty)");
  }
  const cv::Rect image(0, 0, frame.cols, frame.rows);
  if (box.empty() || (box & image) != box) {
    throw Error("ridge contrast: the box is empty or not inside the " + std::to_string(frame.cols) +
                " x " + std::to_string(frame.rows) + " frame");
  }
  if (!noise_box.empty() && (noise_box & image) != noise_box) {
    throw Error("ridge contrast: the noise box is not inside the frame");
  }
  if (!(options.fine_sigma_px > 0.0 && options.coarse_sigma_px > options.fine_sigma_px &&
        std::isfinite(options.coarse_sigma_px))) {
    throw Error("ridge contrast: sigmas " + std::to_string(options.fine_sigma_px) + " and " +
                std::to_string(options.coarse_sigma_px) + " px; valid: 0 < fine < coarse");
  }
  cv::Mat3f difference;
  cv::subtract(frame, background, difference, cv::noArray(), CV_32FC3);
  // Rotated about the frame's centre so that the ridges' normal is the x axis: the filter then
  // runs along rows only. Linear interpolation smooths a little; an axis-aligned normal (0,
  // pi/2, ...) is not resampled.
  cv::Rect at = box, noise_at = noise_box;
  const double turns = options.normal_angle_rad / (kPi / 2.0);
  const bool quarter = std::abs(turns - std::round(turns)) < 1e-9;
  if (quarter && static_cast<int>(std::lround(turns)) % 2 != 0) {
    // Horizontal ridges: filter along columns instead (transpose, boxes transposed with it).
    cv::transpose(difference, difference);
    at = cv::Rect(box.y, box.x, box.height, box.width);
    if (!noise_box.empty())
      noise_at = cv::Rect(noise_box.y, noise_box.x, noise_box.height, noise_box.width);
  } else if (!quarter) {
    const cv::Point2f centre(0.5f * (frame.cols - 1), 0.5f * (frame.rows - 1));
    const cv::Mat rotation =
        cv::getRotationMatrix2D(centre, options.normal_angle_rad * 180.0 / kPi, 1.0);
    cv::warpAffine(difference, difference, rotation, difference.size(), cv::INTER_LINEAR,
                   cv::BORDER_REFLECT);
    // The boxes are given in the frame: their centres move with the rotation, their sizes stay.
    const auto moved = [&](const cv::Rect& r) {
      if (r.empty()) return r;
      const cv::Point2d c(r.x + 0.5 * r.width, r.y + 0.5 * r.height);
      const double* m = rotation.ptr<double>();
      const cv::Point2d d(m[0] * c.x + m[1] * c.y + m[2], m[3] * c.x + m[4] * c.y + m[5]);
      cv::Rect out(static_cast<int>(std::lround(d.x - 0.5 * r.width)),
                   static_cast<int>(std::lround(d.y - 0.5 * r.height)), r.width, r.height);
      return out & image;
    };
    at = moved(box);
    noise_at = moved(noise_box);
  }
  const cv::Mat1f delta = (cv::Mat1f(1, 1) << 1.0f);
  cv::Mat3f fine, coarse;
  cv::sepFilter2D(difference, fine, CV_32F, gaussianKernel(options.fine_sigma_px), delta,
                  cv::Point(-1, -1), 0.0, cv::BORDER_REFLECT);
  cv::sepFilter2D(difference, coarse, CV_32F, gaussianKernel(options.coarse_sigma_px), delta,
                  cv::Point(-1, -1), 0.0, cv::BORDER_REFLECT);
  const cv::Mat3f band = fine - coarse;
  RidgeContrast out;
  out.raw = std::sqrt(meanSquare(band, at));
  if (!noise_at.empty()) out.noise = std::sqrt(meanSquare(band, noise_at));
  out.contrast = std::sqrt(std::max(0.0, out.raw * out.raw - out.noise * out.noise));
  return out;
}

}  // namespace norm2tex
