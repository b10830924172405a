#include "norm2tex/calibrate/press_refinement.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace norm2tex {
namespace {

constexpr double kCentreStepPx = 2.0;
constexpr double kRadiusStep = 0.04;
constexpr int kHalvings = 3;

// Sum of squared differences between the press and its render for `circle`, over `region`
// pixels within `radius` of `centre`; infinity for a circle the ball cannot make.
double residual(const DigitShader& shader, const SensorModel& model, const PressObservation& press,
                const PressCircle& circle, double ball_radius_mm, cv::Point2d centre,
                double radius) {
  const double largest = 0.99 * ball_radius_mm / model.mm_per_pixel;
  if (!(circle.radius_px > 1.0 && circle.radius_px < largest)) {
    return std::numeric_limits<double>::infinity();
  }
  const cv::Mat1f gel = simulatedPressGel(model, circle, {model.mm_per_pixel, 1.0}, ball_radius_mm);
  const cv::Mat3f render = shader.shadingDifference(gel);
  const cv::Rect region = cv::Rect(cvFloor(centre.x - radius), cvFloor(centre.y - radius),
                                   cvCeil(2 * radius) + 2, cvCeil(2 * radius) + 2) &
                          cv::Rect(0, 0, press.diff.cols, press.diff.rows);
  double sum = 0.0;
  for (int r = region.y; r < region.y + region.height; ++r) {
    const cv::Vec3f* real = press.diff.ptr<cv::Vec3f>(r);
    const cv::Vec3f* sim = render.ptr<cv::Vec3f>(r);
    for (int c = region.x; c < region.x + region.width; ++c) {
      const double dx = c - centre.x, dy = r - centre.y;
      if (dx * dx + dy * dy > radius * radius) continue;
      const cv::Vec3f d = real[c] - sim[c];
      sum += d.dot(d);
    }
  }
  return sum;
}

}  // namespace

PressCircle refinePressCircle(const DigitShader& shader, const SensorModel& model,
                              const PressObservation& press, const PressCircle& start,
                              double ball_radius_mm) {
  const cv::Point2d centre = start.centre_px;
  const double region_radius = kFitRegionRadii * start.radius_px;
  PressCircle best = start;
  double best_residual =
      residual(shader, model, press, best, ball_radius_mm, centre, region_radius);
  double step = kCentreStepPx, radius_step = kRadiusStep;
  for (int level = 0; level <= kHalvings; ++level) {
    bool improved = true;
    for (int round = 0; improved && round < 6; ++round) {
      improved = false;
      const PressCircle from = best;
      const PressCircle moves[6] = {{from.centre_px + cv::Point2d(step, 0), from.radius_px},
                                    {from.centre_px - cv::Point2d(step, 0), from.radius_px},
                                    {from.centre_px + cv::Point2d(0, step), from.radius_px},
                                    {from.centre_px - cv::Point2d(0, step), from.radius_px},
                                    {from.centre_px, from.radius_px * (1.0 + radius_step)},
                                    {from.centre_px, from.radius_px / (1.0 + radius_step)}};
      for (const PressCircle& candidate : moves) {
        const double value =
            residual(shader, model, press, candidate, ball_radius_mm, centre, region_radius);
        if (value < best_residual) {
          best_residual = value;
          best = candidate;
          improved = true;
        }
      }
    }
    step *= 0.5;
    radius_step *= 0.5;
  }
  return best;
}

}  // namespace norm2tex
