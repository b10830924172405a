#include "norm2tex/texture/frankot_chellappa.hpp"

#include <cmath>
#include <vector>

#include "common/error_messages.hpp"
#include "norm2tex/common/error.hpp"
#include "texture/island_least_squares.hpp"

namespace norm2tex {
namespace {

/// The paper's periodic solve of one patch box at its own size (cv::dft takes any length): edges
/// between island texels, including the wrap-around ones, carry their targets; the others are
/// flat. Writes h with zero island mean, 0 outside the island.
void solvePeriodic(const cv::Mat1f& dx, const cv::Mat1f& dy, const cv::Mat1b& mask,
                   cv::Mat1f& height) {
  const int rows = dx.rows, cols = dx.cols;
  cv::Mat1f gx(rows, cols, 0.0f), gy(rows, cols, 0.0f);
  for (int r = 0; r < rows; ++r) {
    const int r1 = (r + 1) % rows;
    for (int c = 0; c < cols; ++c) {
      if (!mask(r, c)) continue;
      const int c1 = (c + 1) % cols;
      if (mask(r, c1)) gx(r, c) = 0.5f * (dx(r, c) + dx(r, c1));
      if (mask(r1, c)) gy(r, c) = 0.5f * (dy(r, c) + dy(r1, c));
    }
  }
  // Laplace(h) = div(g) with div(g)(r, c) = gx(r, c) - gx(r, c-1) + gy(r, c) - gy(r-1, c).
  cv::Mat1f div(rows, cols);
  for (int r = 0; r < rows; ++r) {
    const int r0 = (r + rows - 1) % rows;
    for (int c = 0; c < cols; ++c) {
      const int c0 = (c + cols - 1) % cols;
      div(r, c) = gx(r, c) - gx(r, c0) + gy(r, c) - gy(r0, c);
    }
  }
  cv::Mat2f spectrum;
  cv::dft(div, spectrum, cv::DFT_COMPLEX_OUTPUT);
  for (int v = 0; v < rows; ++v) {
    cv::Vec2f* row = spectrum.ptr<cv::Vec2f>(v);
    const double lambda_v = 2.0 * std::cos(2.0 * CV_PI * v / rows) - 2.0;
    for (int u = 0; u < cols; ++u) {
      const float lambda =
          static_cast<float>(2.0 * std::cos(2.0 * CV_PI * u / cols) - 2.0 + lambda_v);
      row[u] = std::fabs(lambda) > 1e-9f ? row[u] / lambda : cv::Vec2f(0.0f, 0.0f);
    }
  }
  cv::Mat1f h;
  cv::dft(spectrum, h, cv::DFT_INVERSE | cv::DFT_SCALE | cv::DFT_REAL_OUTPUT);
  const float mean = static_cast<float>(cv::mean(h, mask)[0]);
  height.setTo(0.0f);
  cv::subtract(h, mean, height, mask);
}

}  // namespace

struct FrankotChellappaIntegrator::Workspace {
  detail::IslandLeastSquares least_squares;
};

void validate(const IntegrationOptions& options) {
  detail::requireParameter(options.tolerance > 0.0 && options.tolerance <= 0.1, "tolerance",
                           options.tolerance, "(0, 0.1]");
  detail::requireParameter(options.max_iterations >= 1 && options.max_iterations <= 10000,
                           "max_iterations", options.max_iterations, "[1, 10000]");
}

FrankotChellappaIntegrator::FrankotChellappaIntegrator(const IntegrationOptions& options)
    : options_(options), workspace_(std::make_unique<Workspace>()) {
  validate(options_);
}
FrankotChellappaIntegrator::~FrankotChellappaIntegrator() = default;
FrankotChellappaIntegrator::FrankotChellappaIntegrator(FrankotChellappaIntegrator&&) noexcept =
    default;
FrankotChellappaIntegrator& FrankotChellappaIntegrator::operator=(
    FrankotChellappaIntegrator&&) noexcept = default;

void FrankotChellappaIntegrator::integrate(const cv::Mat1f& dx, const cv::Mat1f& dy,
                                           const cv::Mat1b& mask, cv::Mat1f& height,
                                           IntegrationReport* report) {
  if (dx.empty() || dx.size() != dy.size() || dx.size() != mask.size()) {
    throw Error("integrateFrankotChellappa: dx, dy and mask must be non-empty and of one size");
  }
  height.create(dx.size());
  IntegrationReport local;
  if (options_.boundary == PoissonBoundary::kPeriodic) {
    solvePeriodic(dx, dy, mask, height);
    local.solves = 1;
  } else {
    workspace_->least_squares.solve(dx, dy, mask, options_.tolerance, options_.max_iterations,
                                    height, local);
  }
  if (report != nullptr) *report = local;
}

cv::Mat1f integrateFrankotChellappa(const cv::Mat1f& dx, const cv::Mat1f& dy, const cv::Mat1b& mask,
                                    const IntegrationOptions& options, IntegrationReport* report) {
  cv::Mat1f height;
  FrankotChellappaIntegrator(options).integrate(dx, dy, mask, height, report);
  return height;
}

}  // namespace norm2tex
