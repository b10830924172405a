#pragma once
// Direct solve of the 5-point Poisson equation on a full rectangle with Neumann boundary: the
// preconditioner of the island least-squares solve and, for islands that fill their box, the
// solve itself.

#include <vector>

#include <opencv2/core.hpp>

#include "texture/scratch_buffer.hpp"

namespace norm2tex {
namespace detail {

class NeumannPoissonSolver {
 public:
  /// Solves L z = b for z on a rows x cols grid, L the graph Laplacian of the grid's 4-neighbour
  /// edges ((L z)(p) = sum over neighbours q of z(p) - z(q)), which the cosine transform
  /// diagonalises. b must sum to ~0 (the constant part is dropped); z has zero mean. `b` and
  /// `z` are rows x cols CV_32F and may be the same matrix. Sizes must be even: see
  /// transformLength().
  void solve(const cv::Mat1f& b, cv::Mat1f& z);

  /// The smallest even length >= n whose real DFT is fast.
  static int transformLength(int n);

 private:
  /// Cosine (DCT-II, unnormalised) of every row of `in` into `out` (out != in).
  void forwardRows(const cv::Mat1f& in, cv::Mat1f& out, const std::vector<float>& cosines,
                   const std::vector<float>& sines);
  /// Inverse of forwardRows; overwrites `in`.
  void inverseRows(cv::Mat1f& in, cv::Mat1f& out, const std::vector<float>& cosines,
                   const std::vector<float>& sines);
  void prepare(int rows, int cols);

  int rows_ = 0, cols_ = 0;
  std::vector<float> lambda_x_, lambda_y_;  // eigenvalues of the 1-D second difference, <= 0
  // Twiddles cos(pi k / 2n), sin(pi k / 2n) for k <= n / 2, per axis.
  std::vector<float> cos_x_, sin_x_, cos_y_, sin_y_;
  std::vector<float> row_;
  ScratchBuffer<float> first_, second_;
};

}  // namespace detail
}  // namespace norm2tex
