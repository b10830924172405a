#include "norm2tex/shear/marker_pattern.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace norm2tex {
namespace {

constexpr double kLutStep = 1.0 / 64.0;  // px^2

// Fraction of a pixel a disc of radius `radius` covers at distance r from its centre, its edge
// blurred by a Gaussian of `sigma` (the edge's profile across the rim: a disc much wider than the
// blur has the error function's).
double coverage(double r, double radius, double sigma) {
  if (sigma <= 0.0) return r <= radius ? 1.0 : 0.0;
  return 0.5 * std::erfc((r - radius) / (std::sqrt(2.0) * sigma));
}

}  // namespace

MarkerPattern::MarkerPattern(const SensorModel& model) {
  validate(model);
  const MarkerOptions& m = model.markers;
  const double px_per_mm = 1.0 / model.mm_per_pixel;
  radius_px_ = 0.5 * m.dot_diameter_mm * px_per_mm;
  const double sigma_px = m.blur_mm * px_per_mm;
  // A pixel is at most half a pixel (diagonal 0.71) from its centre: the sampled coverage is of
  // the pixel's centre, a quarter-pixel blur always added so an unblurred dot still moves
  // smoothly as it is carried by a fraction of a pixel.
  const double edge_px = std::hypot(sigma_px, 0.35);
  reach_px_ = radius_px_ + 4.0 * edge_px + 1.0;
  darkness_ = m.darkness;
  const int entries = static_cast<int>(std::ceil(reach_px_ * reach_px_ / kLutStep)) + 2;
  transmission_.resize(entries);
  for (int n = 0; n < entries; ++n) {
    const double r = std::sqrt(n * kLutStep);
    transmission_[n] = static_cast<float>(1.0 - darkness_ * coverage(r, radius_px_, edge_px));
  }

  std::mt19937 random(static_cast<std::uint32_t>(m.seed));
  std::uniform_real_distribution<double> jitter(-m.jitter_mm, m.jitter_mm);
  for (int row = 0; row < m.rows; ++row) {
    for (int col = 0; col < m.cols; ++col) {
      double x_mm = (col - 0.5 * (m.cols - 1)) * m.pitch_mm + m.offset_mm[0];
      double y_mm = (row - 0.5 * (m.rows - 1)) * m.pitch_mm + m.offset_mm[1];
      if (m.jitter_mm > 0.0) {
        x_mm += jitter(random);
        y_mm += jitter(random);
      }
      // Inverse of SensorModel::pixelToGelMm.
      rest_px_.emplace_back(static_cast<float>(x_mm * px_per_mm + 0.5 * model.cols - 0.5),
                            static_cast<float>(y_mm * px_per_mm + 0.5 * model.rows - 0.5));
    }
  }
}

void MarkerPattern::draw(cv::Mat3b& image, const std::vector<Marker>& markers) const {
  const int last = static_cast<int>(transmission_.size()) - 1;
  const double reach2 = reach_px_ * reach_px_;
  for (const Marker& marker : markers) {
    const double cx = marker.current_px.x;
    const double cy = marker.current_px.y;
    const int c0 = std::max(0, static_cast<int>(std::floor(cx - reach_px_)));
    const int c1 = std::min(image.cols - 1, static_cast<int>(std::ceil(cx + reach_px_)));
    const int r0 = std::max(0, static_cast<int>(std::floor(cy - reach_px_)));
    const int r1 = std::min(image.rows - 1, static_cast<int>(std::ceil(cy + reach_px_)));
    for (int r = r0; r <= r1; ++r) {
      cv::Vec3b* row = image.ptr<cv::Vec3b>(r);
      const double dy2 = (r - cy) * (r - cy);
      for (int c = c0; c <= c1; ++c) {
        const double d2 = dy2 + (c - cx) * (c - cx);
        if (d2 >= reach2) continue;
        const float t = transmission_[std::min(last, static_cast<int>(d2 / kLutStep + 0.5))];
        cv::Vec3b& px = row[c];
        for (int k = 0; k < 3; ++k) px[k] = static_cast<std::uint8_t>(px[k] * t + 0.5f);
      }
    }
  }
}

}  // namespace norm2tex
