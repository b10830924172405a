#include "texture/neumann_poisson.hpp"

#include <cmath>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace detail {

int NeumannPoissonSolver::transformLength(int n) {
  // cv::dct needs even lengths and runs a DFT of half of them, so that half must be fast.
  return 2 * cv::getOptimalDFTSize((n + 1) / 2);
}

void NeumannPoissonSolver::prepare(int rows, int cols) {
  if (rows == rows_ && cols == cols_) return;
  if (rows % 2 != 0 || cols % 2 != 0) {
    throw Error("NeumannPoissonSolver: transform sizes must be even, got " +
                std::to_string(cols) + "x" + std::to_string(rows));
  }
  const auto eigenvalues = [](int n) {
    std::vector<float> lambda(n);
    for (int k = 0; k < n; ++k)
      lambda[k] = static_cast<float>(2.0 * std::cos(CV_PI * k / n) - 2.0);
    return lambda;
  };
  lambda_x_ = eigenvalues(cols);
  lambda_y_ = eigenvalues(rows);
  rows_ = rows;
  cols_ = cols;
}

void NeumannPoissonSolver::solve(const cv::Mat1f& b, cv::Mat1f& z) {
  prepare(b.rows, b.cols);
  // OpenCV's DCT is orthonormal, so the inverse transform undoes the forward one exactly and
  // the eigenvalues of -L in the cosine basis are the sums of the 1-D ones.
  cv::Mat1f spectrum = spectrum_.view(b.rows, b.cols);
  cv::dct(b, spectrum);
  for (int v = 0; v < rows_; ++v) {
    float* row = spectrum.ptr<float>(v);
    const float lambda_v = lambda_y_[v];
    for (int u = 0; u < cols_; ++u) {
      const float lambda = lambda_x_[u] + lambda_v;
      // L = -Laplace: divide by -lambda; the constant mode (lambda 0) is set to zero mean.
      row[u] = lambda != 0.0f ? -row[u] / lambda : 0.0f;
    }
  }
  z.create(b.rows, b.cols);
  cv::dct(spectrum, z, cv::DCT_INVERSE);
}

}  // namespace detail
}  // namespace norm2tex
