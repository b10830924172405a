#include "texture/island_least_squares.hpp"

#include <algorithm>
#include <cmath>

namespace norm2tex {
namespace detail {
namespace {

constexpr uchar kInside = 1, kEdgeRight = 2, kEdgeDown = 4;

double dot(const cv::Mat1f& a, const cv::Mat1f& b) {
  double sum = 0.0;
  for (int r = 0; r < a.rows; ++r) {
    const float* pa = a.ptr<float>(r);
    const float* pb = b.ptr<float>(r);
    double row_sum = 0.0;
    for (int c = 0; c < a.cols; ++c) row_sum += static_cast<double>(pa[c]) * pb[c];
    sum += row_sum;
  }
  return sum;
}

}  // namespace

int IslandLeastSquares::buildSystem(const cv::Mat1f& dx, const cv::Mat1f& dy, const cv::Mat1b& mask,
                                    cv::Mat1f& rhs) {
  const int rows = dx.rows, cols = dx.cols;
  flags_ = flag_buffer_.view(rows, cols);
  int count = 0;
  for (int r = 0; r < rows; ++r) {
    const uchar* in = mask.ptr<uchar>(r);
    const uchar* below = r + 1 < rows ? mask.ptr<uchar>(r + 1) : nullptr;
    uchar* f = flags_.ptr<uchar>(r);
    for (int c = 0; c < cols; ++c) {
      if (!in[c]) {
        f[c] = 0;
        continue;
      }
      ++count;
      f[c] = kInside | (c + 1 < cols && in[c + 1] ? kEdgeRight : 0) |
             (below != nullptr && below[c] ? kEdgeDown : 0);
    }
  }
  // b(p) = sum over edges into p of their target minus sum over edges out of p: -div(g).
  // Row r of b needs the slopes of rows r - 1 .. r + 1 only, so it is written over row r of
  // dx or dy (rhs may be either): the rows it overwrites are copied first.
  gx_row_.resize(cols);
  gy_row_.resize(cols);
  gy_above_.resize(cols);
  for (int r = 0; r < rows; ++r) {
    const uchar* f = flags_.ptr<uchar>(r);
    const uchar* f_above = r > 0 ? flags_.ptr<uchar>(r - 1) : nullptr;
    std::copy(dx.ptr<float>(r), dx.ptr<float>(r) + cols, gx_row_.begin());
    std::copy(dy.ptr<float>(r), dy.ptr<float>(r) + cols, gy_row_.begin());
    const float* gx = gx_row_.data();
    const float* gy = gy_row_.data();
    const float* gy_above = gy_above_.data();
    const float* gy_below = r + 1 < rows ? dy.ptr<float>(r + 1) : nullptr;  // not yet written
    float* b = rhs.ptr<float>(r);
    for (int c = 0; c < cols; ++c) {
      // The order of the old scatter form (edge from above, from the left, to the right,
      // downwards), so the sums round alike.
      float value = 0.0f;
      if (f_above != nullptr && (f_above[c] & kEdgeDown)) value += 0.5f * (gy_above[c] + gy[c]);
      if (c > 0 && (f[c - 1] & kEdgeRight)) value += 0.5f * (gx[c - 1] + gx[c]);
      if (f[c] & kEdgeRight) value -= 0.5f * (gx[c] + gx[c + 1]);
      if (f[c] & kEdgeDown) value -= 0.5f * (gy[c] + gy_below[c]);
      b[c] = value;
    }
    gy_above_.swap(gy_row_);
  }
  return count;
}

void IslandLeastSquares::applyLaplacian(const cv::Mat1f& p, cv::Mat1f& q) const {
  q.setTo(0.0f);
  for (int r = 0; r < p.rows; ++r) {
    const uchar* f = flags_.ptr<uchar>(r);
    const float* h = p.ptr<float>(r);
    const float* h_below = r + 1 < p.rows ? p.ptr<float>(r + 1) : nullptr;
    float* out = q.ptr<float>(r);
    float* out_below = r + 1 < p.rows ? q.ptr<float>(r + 1) : nullptr;
    for (int c = 0; c < p.cols; ++c) {
      if (f[c] & kEdgeRight) {
        const float difference = h[c] - h[c + 1];
        out[c] += difference;
        out[c + 1] -= difference;
      }
      if (f[c] & kEdgeDown) {
        const float difference = h[c] - h_below[c];
        out[c] += difference;
        out_below[c] -= difference;
      }
    }
  }
}

void IslandLeastSquares::removeIslandMean(cv::Mat1f& v) const {
  double sum = 0.0;
  for (int r = 0; r < v.rows; ++r) {
    const float* p = v.ptr<float>(r);
    for (int c = 0; c < v.cols; ++c) sum += p[c];
  }
  const float mean = static_cast<float>(sum / island_texels_);
  for (int r = 0; r < v.rows; ++r) {
    const uchar* f = flags_.ptr<uchar>(r);
    float* p = v.ptr<float>(r);
    for (int c = 0; c < v.cols; ++c) p[c] = (f[c] & kInside) ? p[c] - mean : 0.0f;
  }
}

void IslandLeastSquares::precondition(const cv::Mat1f& r, cv::Mat1f& z) {
  padded_.setTo(0.0f);
  r.copyTo(padded_(cv::Rect(0, 0, r.cols, r.rows)));
  poisson_.solve(padded_, padded_);
  padded_(cv::Rect(0, 0, r.cols, r.rows)).copyTo(z);
  removeIslandMean(z);  // also zeroes z outside the island
}

void IslandLeastSquares::solve(const cv::Mat1f& dx, const cv::Mat1f& dy, const cv::Mat1b& mask,
                               double tolerance, int max_iterations, cv::Mat1f& height,
                               IntegrationReport& report) {
  report = IntegrationReport{};
  // The right-hand side goes into height's memory (which may be dx or dy): no buffer of its own.
  island_texels_ = buildSystem(dx, dy, mask, height);
  if (island_texels_ <= 1) {
    height.setTo(0.0f);
    return;
  }
  const int rows = dx.rows, cols = dx.cols;
  const int transform_rows = NeumannPoissonSolver::transformLength(rows);
  const int transform_cols = NeumannPoissonSolver::transformLength(cols);

  // An island that fills a box of transform size has exactly the box's normal equations: the
  // cosine-transform solve is the least-squares solution, no iteration needed.
  if (island_texels_ == rows * cols && transform_rows == rows && transform_cols == cols) {
    poisson_.solve(height, height);
    report.solves = 1;
    return;
  }

  padded_ = padded_buffer_.view(transform_rows, transform_cols);
  residual_ = residual_buffer_.view(rows, cols);
  direction_ = direction_buffer_.view(rows, cols);
  preconditioned_ = preconditioned_buffer_.view(rows, cols);
  product_ = product_buffer_.view(rows, cols);

  // Preconditioned conjugate gradients from h = 0 on A h = b, A singular with the constants
  // as null space: b and every iterate are kept at zero island mean.
  height.copyTo(residual_);
  height.setTo(0.0f);
  removeIslandMean(residual_);
  precondition(residual_, preconditioned_);
  ++report.solves;
  double rz = dot(residual_, preconditioned_);
  const double rz_initial = rz;
  if (!(rz_initial > 0.0)) return;  // no slope on any edge: flat
  preconditioned_.copyTo(direction_);
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    applyLaplacian(direction_, product_);
    const double curvature = dot(direction_, product_);
    if (!(curvature > 0.0)) break;
    const float step = static_cast<float>(rz / curvature);
    cv::scaleAdd(direction_, step, height, height);
    cv::scaleAdd(product_, -step, residual_, residual_);
    precondition(residual_, preconditioned_);
    ++report.solves;
    const double rz_next = dot(residual_, preconditioned_);
    report.relative_residual = std::sqrt(std::max(rz_next, 0.0) / rz_initial);
    if (report.relative_residual < tolerance) break;
    const float beta = static_cast<float>(rz_next / rz);
    cv::scaleAdd(direction_, beta, preconditioned_, direction_);
    rz = rz_next;
  }
  report.converged = report.relative_residual < tolerance;
  removeIslandMean(height);
}

}  // namespace detail
}  // namespace norm2tex
