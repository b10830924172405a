#include "norm2tex/texture/frankot_chellappa.hpp"

#include <cmath>
#include <vector>

#include <opencv2/core.hpp>

#include "common/error_messages.hpp"
#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

/// A fast transform length >= n. cv::dct needs even lengths and runs a DFT of half of them.
int transformLength(int n, PoissonBoundary boundary) {
  if (boundary == PoissonBoundary::kPeriodic) return cv::getOptimalDFTSize(n);
  return 2 * cv::getOptimalDFTSize((n + 1) / 2);
}

/// Eigenvalues of the 1-D second difference along an axis of length n.
std::vector<float> axisEigenvalues(int n, PoissonBoundary boundary) {
  const double period = boundary == PoissonBoundary::kPeriodic ? n : 2.0 * n;
  std::vector<float> lambda(n);
  for (int k = 0; k < n; ++k)
    lambda[k] = static_cast<float>(2.0 * std::cos(2.0 * CV_PI * k / period) - 2.0);
  return lambda;
}

/// Edge targets of the least-squares problem. gx(r, c) is the wanted h(r, c+1) - h(r, c);
/// gy(r, c) the wanted h(r+1, c) - h(r, c). The last column/row holds the wrap-around edge in
/// the periodic model and nothing (0) in the mirror model.
struct EdgeField {
  cv::Mat1f gx, gy;
  cv::Mat1b island_x, island_y;  // edge joins two island texels: its target is data
};

EdgeField islandEdges(const cv::Mat1f& dx, const cv::Mat1f& dy, const cv::Mat1b& inside,
                      PoissonBoundary boundary) {
  const int rows = inside.rows, cols = inside.cols;
  const bool periodic = boundary == PoissonBoundary::kPeriodic;
  EdgeField edges{cv::Mat1f(rows, cols, 0.0f), cv::Mat1f(rows, cols, 0.0f),
                  cv::Mat1b(rows, cols, uchar(0)), cv::Mat1b(rows, cols, uchar(0))};
  for (int r = 0; r < rows; ++r) {
    const int r1 = r + 1 < rows ? r + 1 : (periodic ? 0 : -1);
    for (int c = 0; c < cols; ++c) {
      if (!inside(r, c)) continue;
      const int c1 = c + 1 < cols ? c + 1 : (periodic ? 0 : -1);
      if (c1 >= 0 && inside(r, c1)) {
        edges.gx(r, c) = 0.5f * (dx(r, c) + dx(r, c1));
        edges.island_x(r, c) = 1;
      }
      if (r1 >= 0 && inside(r1, c)) {
        edges.gy(r, c) = 0.5f * (dy(r, c) + dy(r1, c));
        edges.island_y(r, c) = 1;
      }
    }
  }
  return edges;
}

/// Padding texels (beyond the patch) continue the patch's last row/column unchanged: their edges
/// copy the border's edges and the edges into the padding are flat. This extension costs no
/// energy, so padding to a fast transform size never pulls on an island that fills its box.
void replicateIntoPadding(cv::Size patch, EdgeField& edges) {
  const int rows = edges.gx.rows, cols = edges.gx.cols;
  for (int r = 0; r < patch.height; ++r) {
    for (int c = patch.width; c < cols; ++c) edges.gy(r, c) = edges.gy(r, patch.width - 1);
  }
  for (int r = patch.height; r < rows; ++r) {
    for (int c = 0; c < patch.width; ++c) edges.gx(r, c) = edges.gx(patch.height - 1, c);
  }
}

/// Apron edges take the slopes of the current solution, so they stop pulling on the island.
void relaxApronEdges(const cv::Mat1f& h, PoissonBoundary boundary, EdgeField& edges) {
  const int rows = h.rows, cols = h.cols;
  const bool periodic = boundary == PoissonBoundary::kPeriodic;
  for (int r = 0; r < rows; ++r) {
    const int r1 = r + 1 < rows ? r + 1 : (periodic ? 0 : -1);
    for (int c = 0; c < cols; ++c) {
      const int c1 = c + 1 < cols ? c + 1 : (periodic ? 0 : -1);
      if (!edges.island_x(r, c) && c1 >= 0) edges.gx(r, c) = h(r, c1) - h(r, c);
      if (!edges.island_y(r, c) && r1 >= 0) edges.gy(r, c) = h(r1, c) - h(r, c);
    }
  }
}

/// div(g)(r, c) = gx(r, c) - gx(r, c-1) + gy(r, c) - gy(r-1, c); missing edges contribute 0.
cv::Mat1f divergence(const EdgeField& edges, PoissonBoundary boundary) {
  const int rows = edges.gx.rows, cols = edges.gx.cols;
  const bool periodic = boundary == PoissonBoundary::kPeriodic;
  cv::Mat1f div(rows, cols);
  for (int r = 0; r < rows; ++r) {
    const int r0 = r > 0 ? r - 1 : (periodic ? rows - 1 : -1);
    for (int c = 0; c < cols; ++c) {
      const int c0 = c > 0 ? c - 1 : (periodic ? cols - 1 : -1);
      float value = edges.gx(r, c) + edges.gy(r, c);
      if (c0 >= 0) value -= edges.gx(r, c0);
      if (r0 >= 0) value -= edges.gy(r0, c);
      div(r, c) = value;
    }
  }
  return div;
}

/// Solves Laplace(h) = div with H(0,0) = 0 in the transform domain.
cv::Mat1f solvePoisson(const cv::Mat1f& div, PoissonBoundary boundary,
                       const std::vector<float>& lambda_x, const std::vector<float>& lambda_y) {
  const int rows = div.rows, cols = div.cols;
  cv::Mat1f h;
  if (boundary == PoissonBoundary::kMirror) {
    cv::Mat1f spectrum;
    cv::dct(div, spectrum);
    for (int v = 0; v < rows; ++v) {
      float* row = spectrum.ptr<float>(v);
      for (int u = 0; u < cols; ++u) {
        const float lambda = lambda_x[u] + lambda_y[v];
        row[u] = lambda != 0.0f ? row[u] / lambda : 0.0f;
      }
    }
    cv::dct(spectrum, h, cv::DCT_INVERSE);
    return h;
  }
  cv::Mat2f spectrum;
  cv::dft(div, spectrum, cv::DFT_COMPLEX_OUTPUT);
  for (int v = 0; v < rows; ++v) {
    cv::Vec2f* row = spectrum.ptr<cv::Vec2f>(v);
    for (int u = 0; u < cols; ++u) {
      const float lambda = lambda_x[u] + lambda_y[v];
      row[u] = lambda != 0.0f ? row[u] / lambda : cv::Vec2f(0.0f, 0.0f);
    }
  }
  cv::dft(spectrum, h, cv::DFT_INVERSE | cv::DFT_SCALE | cv::DFT_REAL_OUTPUT);
  return h;
}

}  // namespace

void validate(const IntegrationOptions& options) {
  detail::requireParameter(options.apron_refinements >= 0 && options.apron_refinements <= 100,
                           "apron_refinements", options.apron_refinements, "[0, 100]");
}

cv::Mat1f integrateFrankotChellappa(const cv::Mat1f& dx, const cv::Mat1f& dy, const cv::Mat1b& mask,
                                    const IntegrationOptions& options) {
  validate(options);
  if (dx.empty() || dx.size() != dy.size() || dx.size() != mask.size()) {
    throw Error("integrateFrankotChellappa: dx, dy and mask must be non-empty and of one size");
  }
  const PoissonBoundary boundary = options.boundary;
  const int rows = transformLength(dx.rows, boundary);
  const int cols = transformLength(dx.cols, boundary);

  // Pad to the transform size; padding texels are apron like any masked texel of the patch.
  cv::Mat1b inside(rows, cols, uchar(0));
  cv::Mat1f px(rows, cols, 0.0f), py(rows, cols, 0.0f);
  const cv::Rect patch(0, 0, dx.cols, dx.rows);
  cv::Mat1b(mask != 0).copyTo(inside(patch));
  dx.copyTo(px(patch));
  dy.copyTo(py(patch));

  const int island_texels = cv::countNonZero(inside);
  cv::Mat1f result(dx.size(), 0.0f);
  if (island_texels == 0) return result;

  EdgeField edges = islandEdges(px, py, inside, boundary);
  replicateIntoPadding(dx.size(), edges);
  const std::vector<float> lambda_x = axisEigenvalues(cols, boundary);
  const std::vector<float> lambda_y = axisEigenvalues(rows, boundary);
  cv::Mat1f h = solvePoisson(divergence(edges, boundary), boundary, lambda_x, lambda_y);
  // Refinement only matters when the island leaves texels of its own box empty.
  const bool has_apron = island_texels < dx.rows * dx.cols;
  for (int i = 0; has_apron && i < options.apron_refinements; ++i) {
    relaxApronEdges(h, boundary, edges);
    h = solvePoisson(divergence(edges, boundary), boundary, lambda_x, lambda_y);
  }

  // Zero mean over the island; the apron is not part of the result.
  const cv::Mat1f cropped = h(patch);
  const float mean = static_cast<float>(cv::mean(cropped, mask)[0]);
  cv::subtract(cropped, mean, result, mask);
  return result;
}

}  // namespace norm2tex
