#include "norm2tex/calibrate/marker_detection.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <opencv2/imgproc.hpp>

namespace norm2tex {
namespace {

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// How many distinct lines the coordinates fall on, lines `tolerance` apart at least.
int countLines(std::vector<double> coordinates, double tolerance) {
  std::sort(coordinates.begin(), coordinates.end());
  int lines = 0;
  double last = -1e30;
  for (const double c : coordinates) {
    if (c - last > tolerance) ++lines;
    last = c;
  }
  return lines;
}

}  // namespace

MarkerOptions DetectedMarkers::options(const SensorModel& model, double mm_per_pixel) const {
  MarkerOptions m = model.markers;
  if (!found()) return m;
  m.enabled = true;
  m.rows = rows;
  m.cols = cols;
  m.pitch_mm = pitch_px * mm_per_pixel;
  m.dot_diameter_mm = diameter_px * mm_per_pixel;
  m.darkness = std::clamp(darkness, 0.0, 1.0);
  m.offset_mm = {(grid_centre_px.x + 0.5 - 0.5 * model.cols) * mm_per_pixel,
                 (grid_centre_px.y + 0.5 - 0.5 * model.rows) * mm_per_pixel};
  return m;
}

DetectedMarkers detectMarkers(const cv::Mat3b& frame) {
  DetectedMarkers out;
  cv::Mat1f grey;
  {
    cv::Mat1b g;
    cv::cvtColor(frame, g, cv::COLOR_BGR2GRAY);
    g.convertTo(grey, CV_32F);
  }
  // The light without the dots: a closing wider than a dot (a dot of up to 1/12 of the frame's
  // short side; GelSight Mini's are 12-16 px across at 320 x 240).
  const int k = std::max(5, std::min(frame.rows, frame.cols) / 12) | 1;
  cv::Mat1f light;
  cv::morphologyEx(grey, light, cv::MORPH_CLOSE,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k)));
  cv::Mat1f darkness = 1.0f - grey / cv::max(light, 1.0f);
  cv::Mat1b dark = darkness > kMarkerDarkness;
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(dark, labels, stats, centroids, 8, CV_32S);
  std::vector<cv::Point2f> centres;
  std::vector<double> diameters, peaks;
  for (int c = 1; c < count; ++c) {
    const int area = stats.at<int>(c, cv::CC_STAT_AREA);
    const int w = stats.at<int>(c, cv::CC_STAT_WIDTH), h = stats.at<int>(c, cv::CC_STAT_HEIGHT);
    // Dot-shaped: small, filling its box like a disc (pi/4), not elongated.
    if (area < 4 || w > k || h > k) continue;
    if (area < 0.5 * w * h || std::max(w, h) > 2 * std::min(w, h)) continue;
    const cv::Rect box(stats.at<int>(c, cv::CC_STAT_LEFT), stats.at<int>(c, cv::CC_STAT_TOP), w, h);
    const cv::Rect around = (box + cv::Size(4, 4) - cv::Point(2, 2)) & cv::Rect(cv::Point(), frame.size());
    double peak = 0.0;
    cv::minMaxLoc(darkness(around), nullptr, &peak);
    const int half = cv::countNonZero(darkness(around) > 0.5 * peak);
    centres.emplace_back(static_cast<float>(centroids.at<double>(c, 0)),
                         static_cast<float>(centroids.at<double>(c, 1)));
    diameters.push_back(2.0 * std::sqrt(half / CV_PI));
    peaks.push_back(peak);
  }
  if (centres.size() < 9) return out;
  // On a grid: the nearest neighbours mostly one pitch apart.
  std::vector<double> nearest;
  for (size_t i = 0; i < centres.size(); ++i) {
    double best = 1e30;
    for (size_t j = 0; j < centres.size(); ++j) {
      if (i != j) best = std::min(best, static_cast<double>(cv::norm(centres[i] - centres[j])));
    }
    nearest.push_back(best);
  }
  const double pitch = median(nearest);
  const auto on_pitch = std::count_if(nearest.begin(), nearest.end(), [&](double d) {
    return std::abs(d - pitch) < 0.2 * pitch;
  });
  if (on_pitch < 0.7 * static_cast<double>(nearest.size())) return out;

  out.centres_px = centres;
  out.pitch_px = pitch;
  out.diameter_px = median(diameters);
  out.darkness = median(peaks);
  std::vector<double> xs, ys;
  float x0 = 1e30f, x1 = -1e30f, y0 = 1e30f, y1 = -1e30f;
  for (const cv::Point2f& p : centres) {
    xs.push_back(p.x);
    ys.push_back(p.y);
    x0 = std::min(x0, p.x);
    x1 = std::max(x1, p.x);
    y0 = std::min(y0, p.y);
    y1 = std::max(y1, p.y);
  }
  out.cols = countLines(xs, 0.5 * pitch);
  out.rows = countLines(ys, 0.5 * pitch);
  out.grid_centre_px = {0.5f * (x0 + x1), 0.5f * (y0 + y1)};
  // The mask: each dot's disc, widened by its blur and a margin for dots a press moves a little.
  out.mask = cv::Mat1b::zeros(frame.size());
  const int radius = static_cast<int>(std::ceil(0.5 * out.diameter_px + 0.25 * out.diameter_px + 2));
  for (const cv::Point2f& p : centres) {
    cv::circle(out.mask, cv::Point(cvRound(p.x), cvRound(p.y)), radius, cv::Scalar(255), cv::FILLED);
  }
  return out;
}

cv::Mat3b withoutMarkers(const cv::Mat3b& frame, const cv::Mat1b& mask, double sigma_px) {
  if (mask.empty() || cv::countNonZero(mask) == 0) return frame.clone();
  cv::Mat1f keep;
  mask.convertTo(keep, CV_32F, -1.0 / 255.0, 1.0);  // 1 where kept, 0 in the dots
  cv::Mat3f values;
  frame.convertTo(values, CV_32F);
  cv::Mat3f weighted;
  cv::Mat keep3;
  cv::merge(std::vector<cv::Mat>{keep, keep, keep}, keep3);
  cv::multiply(values, keep3, weighted);
  const int k = 2 * static_cast<int>(std::ceil(3 * sigma_px)) + 1;
  cv::Mat3f blurred;
  cv::Mat1f weight;
  cv::GaussianBlur(weighted, blurred, cv::Size(k, k), sigma_px);
  cv::GaussianBlur(keep, weight, cv::Size(k, k), sigma_px);
  cv::Mat3b out = frame.clone();
  for (int r = 0; r < frame.rows; ++r) {
    for (int c = 0; c < frame.cols; ++c) {
      if (!mask(r, c)) continue;
      const float w = std::max(weight(r, c), 1e-6f);
      const cv::Vec3f v = blurred(r, c) / w;
      out(r, c) = cv::Vec3b(cv::saturate_cast<std::uint8_t>(v[0]),
                            cv::saturate_cast<std::uint8_t>(v[1]),
                            cv::saturate_cast<std::uint8_t>(v[2]));
    }
  }
  return out;
}

MarkerRemoval::MarkerRemoval(const cv::Mat3b& background, const DetectedMarkers& markers)
    : mask_(markers.mask), sigma_px_(std::max(1.5, 0.5 * markers.diameter_px)) {
  transmission_ = cv::Mat3f(background.size(), cv::Vec3f(1, 1, 1));
  core_ = cv::Mat1b::zeros(background.size());
  if (mask_.empty()) return;
  const cv::Mat3b filled = withoutMarkers(background, mask_, sigma_px_);
  for (int r = 0; r < background.rows; ++r) {
    for (int c = 0; c < background.cols; ++c) {
      if (!mask_(r, c)) continue;
      cv::Vec3f& t = transmission_(r, c);
      for (int k = 0; k < 3; ++k) {
        t[k] = std::min(1.0f, background(r, c)[k] / std::max(1.0f, float(filled(r, c)[k])));
        if (t[k] < kMarkerDivisible) core_(r, c) = 255;
      }
    }
  }
}

cv::Mat3b MarkerRemoval::apply(const cv::Mat3b& frame) const {
  if (mask_.empty()) return frame.clone();
  cv::Mat3b out = frame.clone();
  for (int r = 0; r < frame.rows; ++r) {
    for (int c = 0; c < frame.cols; ++c) {
      if (!mask_(r, c) || core_(r, c)) continue;
      const cv::Vec3f& t = transmission_(r, c);
      for (int k = 0; k < 3; ++k) out(r, c)[k] = cv::saturate_cast<std::uint8_t>(frame(r, c)[k] / t[k]);
    }
  }
  return withoutMarkers(out, core_, sigma_px_);
}

}  // namespace norm2tex
