#pragma once
// Direct solve of the 5-point Poisson equation on a full rectangle with Neumann boundary: the
// preconditioner of the island least-squares solve and, for islands that fill their box, the
// solve itself.

#include <vector>

#include <opencv2/core.hpp>

#include "texture/cosine_transform.hpp"

namespace norm2tex {
namespace detail {

class NeumannPoissonSolver {
 public:
  /// Solves L z = b for z on a rows x cols grid, L the graph Laplacian of the grid's 4-neighbour
  /// edges ((L z)(p) = sum over neighbours q of z(p) - z(q)), which the cosine transform
  /// diagonalises. b must sum to ~0 (the constant part is dropped); z has zero mean. `b` and
  /// `z` are rows x cols CV_32F and may be the same matrix (then no other full-size buffer is
  /// used for a square grid, one for others). Sizes must be even: see transformLength().
  void solve(const cv::Mat1f& b, cv::Mat1f& z);

  /// The smallest even length >= n whose real DFT is fast.
  static int transformLength(int n) { return CosineTransform::transformLength(n); }

 private:
  void prepare(int rows, int cols);
  int rows_ = 0, cols_ = 0;
  std::vector<float> lambda_x_, lambda_y_;  // eigenvalues of the 1-D second difference, <= 0
  CosineTransform transform_;
};

}  // namespace detail
}  // namespace norm2tex
