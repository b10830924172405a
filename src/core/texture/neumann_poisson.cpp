#include "texture/neumann_poisson.hpp"

#include <cmath>

namespace norm2tex {
namespace detail {

void NeumannPoissonSolver::prepare(int rows, int cols) {
  if (rows == rows_ && cols == cols_) return;
  const auto eigenvalues = [](int n) {
    std::vector<float> lambda(n);
    for (int k = 0; k < n; ++k) lambda[k] = static_cast<float>(2.0 * std::cos(CV_PI * k / n) - 2.0);
    return lambda;
  };
  lambda_x_ = eigenvalues(cols);
  lambda_y_ = eigenvalues(rows);
  rows_ = rows;
  cols_ = cols;
}

void NeumannPoissonSolver::solve(const cv::Mat1f& b, cv::Mat1f& z) {
  prepare(b.rows, b.cols);
  if (z.data != b.data) b.copyTo(z);            // z is the transform's working memory
  cv::Mat1f& spectrum = transform_.forward(z);  // transposed: row u, column v
  for (int u = 0; u < cols_; ++u) {
    float* row = spectrum.ptr<float>(u);
    const float lambda_u = lambda_x_[u];
    for (int v = 0; v < rows_; ++v) {
      const float lambda = lambda_u + lambda_y_[v];
      // L = -Laplace: divide by -lambda; the constant mode (lambda 0) is set to zero mean.
      row[v] = lambda != 0.0f ? -row[v] / lambda : 0.0f;
    }
  }
  transform_.inverse(spectrum, z);
}

}  // namespace detail
}  // namespace norm2tex
