#include "norm2tex/shear/marker_pattern.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

namespace norm2tex {
namespace {

constexpr double kLutStep = 1.0 / 64.0;  // px^2
constexpr double kLutScale = 1.0 / kLutStep;

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
  // 3.5 edge widths out, a dot takes less than 3e-4 of the light (0.1 grey levels).
  reach_px_ = radius_px_ + 3.5 * edge_px;
  darkness_ = m.darkness;
  const int entries = static_cast<int>(std::ceil(reach_px_ * reach_px_ / kLutStep)) + 2;
  transmission_.resize(entries);
  for (int n = 0; n < entries; ++n) {
    const double r = std::sqrt(n * kLutStep);
    transmission_[n] = static_cast<std::int32_t>(
        std::lround(32768.0 * (1.0 - darkness_ * coverage(r, radius_px_, edge_px))));
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
      const double dy2 = (r - cy) * (r - cy);
      if (dy2 >= reach2) continue;
      // Only the row's chord of the reach's disc.
      const double half = std::sqrt(reach2 - dy2);
      const int first = std::max(c0, static_cast<int>(std::ceil(cx - half)));
      const int past = std::min(c1, static_cast<int>(std::floor(cx + half))) + 1;
      std::uint8_t* px = image.ptr<std::uint8_t>(r) + 3 * first;
      for (int c = first; c < past; ++c, px += 3) {
        const double d2 = dy2 + (c - cx) * (c - cx);
        const int t = transmission_[std::min(last, static_cast<int>(d2 * kLutScale + 0.5))];
        // Fixed point: t is the transmission times 2^15.
        px[0] = static_cast<std::uint8_t>((px[0] * t + (1 << 14)) >> 15);
        px[1] = static_cast<std::uint8_t>((px[1] * t + (1 << 14)) >> 15);
        px[2] = static_cast<std::uint8_t>((px[2] * t + (1 << 14)) >> 15);
      }
    }
  }
}

}  // namespace norm2tex
