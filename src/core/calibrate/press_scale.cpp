#include "norm2tex/calibrate/press_scale.hpp"

#include <cmath>
#include <sstream>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

constexpr double kMinBaselinePx = 20.0;

PressCircle findPress(const cv::Mat3b& background, const cv::Mat3b& frame,
                      const std::string& name) {
  if (frame.size() != background.size()) {
    throw Error("scale press '" + name + "' is " + std::to_string(frame.cols) + " x " +
                std::to_string(frame.rows) + " but the background is " +
                std::to_string(background.cols) + " x " + std::to_string(background.rows));
  }
  cv::Mat3f diff, base;
  frame.convertTo(diff, CV_32F);
  background.convertTo(base, CV_32F);
  diff -= base;
  return detectPress(diff, name);
}

}  // namespace

PressScale measureScaleFromTwoPresses(const cv::Mat3b& background, const cv::Mat3b& first,
                                      const std::string& first_name, const cv::Mat3b& second,
                                      const std::string& second_name, double distance_mm) {
  if (!(std::isfinite(distance_mm) && distance_mm > 0.0)) {
    std::ostringstream message;
    message << "the distance between the scale presses is " << distance_mm
            << " mm; give the distance the ball moved, finite and > 0";
    throw Error(message.str());
  }
  PressScale scale;
  scale.first = findPress(background, first, first_name);
  scale.second = findPress(background, second, second_name);
  scale.distance_px = cv::norm(scale.first.centre_px - scale.second.centre_px);
  if (scale.distance_px < kMinBaselinePx) {
    std::ostringstream message;
    message << "the scale presses '" << first_name << "' and '" << second_name << "' are "
            << scale.distance_px << " px apart: too close to measure a scale on (at least "
            << kMinBaselinePx << " px; move the ball several mm between them)";
    throw Error(message.str());
  }
  scale.mm_per_pixel = distance_mm / scale.distance_px;
  return scale;
}

}  // namespace norm2tex
