#include "norm2tex/texture/analytic_surface.hpp"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

AnalyticSurface zeros(cv::Size size) {
  if (size.width <= 0 || size.height <= 0) throw Error("analytic surface: size must be positive");
  return {cv::Mat1f(size, 0.0f), cv::Mat1f(size, 0.0f), cv::Mat1f(size, 0.0f)};
}

}  // namespace

AnalyticSurface& AnalyticSurface::operator+=(const AnalyticSurface& other) {
  height += other.height;
  dx += other.dx;
  dy += other.dy;
  return *this;
}

AnalyticSurface makeWaves(cv::Size size, const std::vector<Wave>& waves) {
  AnalyticSurface s = zeros(size);
  for (const Wave& w : waves) {
    const double k = 2.0 * CV_PI / w.wavelength;
    const double kx = k * std::cos(w.angle), ky = k * std::sin(w.angle);
    for (int r = 0; r < size.height; ++r) {
      for (int c = 0; c < size.width; ++c) {
        const double phase = kx * c + ky * r + w.phase;
        s.height(r, c) += static_cast<float>(w.amplitude * std::sin(phase));
        s.dx(r, c) += static_cast<float>(w.amplitude * kx * std::cos(phase));
        s.dy(r, c) += static_cast<float>(w.amplitude * ky * std::cos(phase));
      }
    }
  }
  return s;
}

AnalyticSurface makeBumps(cv::Size size, const std::vector<Bump>& bumps) {
  AnalyticSurface s = zeros(size);
  for (const Bump& b : bumps) {
    const double inv = 1.0 / (2.0 * b.sigma * b.sigma);
    for (int r = 0; r < size.height; ++r) {
      for (int c = 0; c < size.width; ++c) {
        const double x = c - b.centre.x, y = r - b.centre.y;
        const double h = b.amplitude * std::exp(-(x * x + y * y) * inv);
        s.height(r, c) += static_cast<float>(h);
        s.dx(r, c) += static_cast<float>(-2.0 * x * inv * h);
        s.dy(r, c) += static_cast<float>(-2.0 * y * inv * h);
      }
    }
  }
  return s;
}

AnalyticSurface makeRidges(cv::Size size, const Ridges& ridges) {
  AnalyticSurface s = zeros(size);
  const double ux = std::cos(ridges.angle), uy = std::sin(ridges.angle);
  const double inv = 1.0 / (2.0 * ridges.width * ridges.width);
  for (int r = 0; r < size.height; ++r) {
    for (int c = 0; c < size.width; ++c) {
      const double d = ux * c + uy * r;
      const double t = d - ridges.spacing * std::round(d / ridges.spacing);
      const double h = ridges.amplitude * std::exp(-t * t * inv);
      const double slope = -2.0 * t * inv * h;  // dh/dt; dt/dx = ux, dt/dy = uy
      s.height(r, c) = static_cast<float>(h);
      s.dx(r, c) = static_cast<float>(slope * ux);
      s.dy(r, c) = static_cast<float>(slope * uy);
    }
  }
  return s;
}

cv::Mat1b makeIslandMask(cv::Size size, int cells_per_side, int gap, bool irregular) {
  if (cells_per_side <= 0 || gap < 1) throw Error("makeIslandMask: need cells >= 1, gap >= 1");
  cv::Mat1b mask(size, uchar(0));
  const double cell_w = static_cast<double>(size.width) / cells_per_side;
  const double cell_h = static_cast<double>(size.height) / cells_per_side;
  const int half_gap = (gap + 1) / 2;
  for (int i = 0; i < cells_per_side; ++i) {
    for (int j = 0; j < cells_per_side; ++j) {
      const int x0 = static_cast<int>(std::ceil(j * cell_w)) + half_gap;
      const int y0 = static_cast<int>(std::ceil(i * cell_h)) + half_gap;
      const int x1 = static_cast<int>(std::floor((j + 1) * cell_w)) - half_gap - 1;
      const int y1 = static_cast<int>(std::floor((i + 1) * cell_h)) - half_gap - 1;
      if (x1 < x0 || y1 < y0) throw Error("makeIslandMask: cells too small for the gap");
      const cv::Rect box(x0, y0, x1 - x0 + 1, y1 - y0 + 1);
      const int shape = irregular ? (i * cells_per_side + j) % 3 : 0;
      if (shape == 0 || box.width < 4 || box.height < 4) {
        mask(box).setTo(255);
      } else if (shape == 1) {
        const cv::Point centre(x0 + box.width / 2, y0 + box.height / 2);
        cv::ellipse(mask, centre, cv::Size(box.width / 2, box.height / 2), 0, 0, 360, 255,
                    cv::FILLED, cv::LINE_8);
      } else {
        const std::vector<cv::Point> triangle{{x0, y1}, {x1, y1}, {x0 + box.width / 3, y0}};
        cv::fillConvexPoly(mask, triangle, 255, cv::LINE_8);
      }
    }
  }
  return mask;
}

}  // namespace norm2tex
