#include "norm2tex/calibrate/press_detection.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "norm2tex/calibrate/qvga_scale.hpp"
#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

constexpr double kBlurSigmaAtQvgaPx = 2.0;
constexpr double kThresholdFraction = 0.25;
constexpr double kMinPeakGreyLevels = 12.0;  // sum of |B| + |G| + |R| above the baseline
constexpr int kMinRegionPixels = 30;
constexpr int kMinContourPoints = 12;

double median(cv::Mat1f values) {
  std::vector<float> v(values.begin(), values.end());
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// Kasa fit: minimise sum (x^2 + y^2 + D x + E y + F)^2, linear in D, E, F.
bool fitCircle(const std::vector<cv::Point>& points, PressCircle& circle) {
  if (points.size() < static_cast<size_t>(kMinContourPoints)) return false;
  cv::Mat1d a(static_cast<int>(points.size()), 3), b(static_cast<int>(points.size()), 1);
  for (size_t i = 0; i < points.size(); ++i) {
    const double x = points[i].x, y = points[i].y;
    a(static_cast<int>(i), 0) = x;
    a(static_cast<int>(i), 1) = y;
    a(static_cast<int>(i), 2) = 1.0;
    b(static_cast<int>(i), 0) = -(x * x + y * y);
  }
  cv::Mat1d solution;
  if (!cv::solve(a, b, solution, cv::DECOMP_SVD)) return false;
  const double cx = -solution(0) / 2.0, cy = -solution(1) / 2.0;
  const double r2 = cx * cx + cy * cy - solution(2);
  if (!(r2 > 0.0)) return false;
  circle.centre_px = {cx, cy};
  circle.radius_px = std::sqrt(r2);
  return true;
}

}  // namespace

PressCircle detectPress(const cv::Mat3f& diff, const std::string& frame_name) {
  if (diff.empty()) throw Error("press '" + frame_name + "': empty frame");
  cv::Mat1f magnitude(diff.size());
  for (int r = 0; r < diff.rows; ++r) {
    const cv::Vec3f* d = diff.ptr<cv::Vec3f>(r);
    float* m = magnitude.ptr<float>(r);
    for (int c = 0; c < diff.cols; ++c)
      m[c] = std::abs(d[c][0]) + std::abs(d[c][1]) + std::abs(d[c][2]);
  }
  const double sigma = kBlurSigmaAtQvgaPx * qvgaScale(diff.size());
  const int radius = static_cast<int>(std::ceil(3.0 * sigma));
  cv::GaussianBlur(magnitude, magnitude, cv::Size(2 * radius + 1, 2 * radius + 1), sigma);
  const double baseline = median(magnitude);
  double peak = 0.0;
  cv::minMaxLoc(magnitude, nullptr, &peak);
  if (peak - baseline < kMinPeakGreyLevels) {
    throw Error("press '" + frame_name + "': no press found (the largest change from the " +
                "background is " + std::to_string(static_cast<int>(std::lround(peak - baseline))) +
                " grey levels, summed over B, G, R; need >= " +
                std::to_string(static_cast<int>(kMinPeakGreyLevels)) +
                "); is it a no-contact frame, or from another sensor?");
  }
  const cv::Mat1b above = magnitude > baseline + kThresholdFraction * (peak - baseline);
  cv::Mat1i labels;
  cv::Mat stats, centroids;
  const int count = cv::connectedComponentsWithStats(above, labels, stats, centroids, 8);
  int best = 0, best_area = 0;
  for (int i = 1; i < count; ++i) {
    const int area = stats.at<int>(i, cv::CC_STAT_AREA);
    if (area > best_area) best = i, best_area = area;
  }
  if (best_area < kMinRegionPixels) {
    throw Error("press '" + frame_name + "': no press found (the changed region has only " +
                std::to_string(best_area) + " pixels; need >= " + std::to_string(kMinRegionPixels) +
                ")");
  }
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(cv::Mat1b(labels == best), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  std::vector<cv::Point> inner;  // contour points away from the image border
  for (const auto& contour : contours) {
    for (const cv::Point& p : contour) {
      if (p.x > 1 && p.y > 1 && p.x < diff.cols - 2 && p.y < diff.rows - 2) inner.push_back(p);
    }
  }
  PressCircle circle;
  if (!fitCircle(inner, circle)) {
    throw Error("press '" + frame_name + "': the contact's outline (" +
                std::to_string(inner.size()) + " points off the image border) admits no circle");
  }
  return circle;
}

}  // namespace norm2tex
