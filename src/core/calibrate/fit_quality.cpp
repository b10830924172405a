#include "norm2tex/calibrate/fit_quality.hpp"

#include <algorithm>
#include <cmath>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

constexpr int kRimSectors = 8;
constexpr double kRimOuterRadii = 1.3;
constexpr double kSideRadii = 1.2;

double percentile95(std::vector<float>& values) {
  if (values.empty()) return 0.0;
  const size_t at = static_cast<size_t>(0.95 * (values.size() - 1));
  std::nth_element(values.begin(), values.begin() + at, values.end());
  return values[at];
}

double angleDeg(const cv::Vec2d& v) { return std::atan2(v[1], v[0]) * 180.0 / CV_PI; }

// Per-press accumulators for one image (real or simulated).
struct Side {
  double contact_abs_sum = 0.0;
  std::vector<float> contact_abs;
  double rim_darkest_sum = 0.0;
  cv::Vec2d side[3];
};

}  // namespace

FitQuality compareWithReal(const std::vector<PressObservation>& real,
                           const std::vector<cv::Mat3f>& simulated,
                           const std::vector<double>& contact_radii_px) {
  if (real.size() != simulated.size() || real.size() != contact_radii_px.size() || real.empty()) {
    throw Error("compareWithReal: needs one simulated diff and one radius per real press");
  }
  FitQuality q;
  q.presses = static_cast<int>(real.size());
  Side sides[2];  // real, simulated
  double sse = 0.0, yy = 0.0, y_sum = 0.0, count = 0.0, contact_count = 0.0;
  for (size_t p = 0; p < real.size(); ++p) {
    const cv::Mat3f* images[2] = {&real[p].diff, &simulated[p]};
    const cv::Point2d centre = real[p].circle.centre_px;
    const double a = contact_radii_px[p];
    const double reach = std::max(kQualityRegionRadii, kRimOuterRadii) * a;
    const cv::Rect region = cv::Rect(cvFloor(centre.x - reach), cvFloor(centre.y - reach),
                                     cvCeil(2 * reach) + 2, cvCeil(2 * reach) + 2) &
                            cv::Rect(0, 0, real[p].diff.cols, real[p].diff.rows);
    double sector_sum[2][kRimSectors] = {}, sector_count[kRimSectors] = {};
    for (int r = region.y; r < region.y + region.height; ++r) {
      for (int c = region.x; c < region.x + region.width; ++c) {
        const double dx = c - centre.x, dy = r - centre.y;
        const double rho = std::sqrt(dx * dx + dy * dy) / a;
        const cv::Vec3f y = (*images[0])(r, c), s = (*images[1])(r, c);
        if (rho <= kQualityRegionRadii) {
          for (int k = 0; k < 3; ++k) {
            sse += (y[k] - s[k]) * (y[k] - s[k]);
            yy += y[k] * y[k];
            y_sum += y[k];
          }
          count += 3.0;
        }
        const cv::Vec2d u = rho > 0.0 ? cv::Vec2d(dx, dy) / (rho * a) : cv::Vec2d(0, 0);
        int sector = -1;
        if (rho >= 1.0 && rho < kRimOuterRadii) {
          const double angle = std::atan2(dy, dx) + CV_PI;  // [0, 2 pi]
          sector = std::min(kRimSectors - 1, static_cast<int>(angle / (2 * CV_PI) * kRimSectors));
          sector_count[sector] += 1.0;
        }
        if (rho < 1.0) contact_count += 1.0;
        for (int i = 0; i < 2; ++i) {
          const cv::Vec3f v = (*images[i])(r, c);
          if (rho < 1.0) {
            for (int k = 0; k < 3; ++k) {
              sides[i].contact_abs_sum += std::abs(v[k]);
              sides[i].contact_abs.push_back(std::abs(v[k]));
            }
          }
          if (sector >= 0) sector_sum[i][sector] += (v[0] + v[1] + v[2]) / 3.0;
          if (rho < kSideRadii) {
            for (int k = 0; k < 3; ++k) sides[i].side[k] += v[k] * u;
          }
        }
      }
    }
    for (int i = 0; i < 2; ++i) {
      double darkest = 0.0;
      bool any = false;
      for (int s = 0; s < kRimSectors; ++s) {
        if (sector_count[s] < 5) continue;  // a sector cut away by the image border
        const double mean = sector_sum[i][s] / sector_count[s];
        darkest = any ? std::min(darkest, mean) : mean;
        any = true;
      }
      sides[i].rim_darkest_sum += darkest;
    }
  }
  const double sst = yy - y_sum * y_sum / std::max(count, 1.0);
  q.variance_explained = sst > 0.0 ? 1.0 - sse / sst : 0.0;
  const double contact_values = std::max(3.0 * contact_count, 1.0);
  q.real_contact_mean = sides[0].contact_abs_sum / contact_values;
  q.sim_contact_mean = sides[1].contact_abs_sum / contact_values;
  q.real_contact_p95 = percentile95(sides[0].contact_abs);
  q.sim_contact_p95 = percentile95(sides[1].contact_abs);
  q.real_rim_darkest = sides[0].rim_darkest_sum / q.presses;
  q.sim_rim_darkest = sides[1].rim_darkest_sum / q.presses;
  for (int k = 0; k < 3; ++k) {
    q.real_side_deg[k] = angleDeg(sides[0].side[k]);
    q.sim_side_deg[k] = angleDeg(sides[1].side[k]);
    double error = std::abs(q.real_side_deg[k] - q.sim_side_deg[k]);
    if (error > 180.0) error = 360.0 - error;
    q.side_error_deg[k] = error;
  }
  return q;
}

}  // namespace norm2tex
