#pragma once
// The exact least-squares height of one island: conjugate gradients on the island's own
// normal equations, preconditioned by the cosine-transform Poisson solve of its box.

#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/texture/frankot_chellappa.hpp"
#include "texture/neumann_poisson.hpp"
#include "texture/scratch_buffer.hpp"

namespace norm2tex {
namespace detail {

class IslandLeastSquares {
 public:
  /// See integrateFrankotChellappa (kNeumann). `height` must be dx's size, CV_32F.
  void solve(const cv::Mat1f& dx, const cv::Mat1f& dy, const cv::Mat1b& mask, double tolerance,
             int max_iterations, cv::Mat1f& height, IntegrationReport& report);

 private:
  /// Edge flags per texel and the right-hand side b = -div(g) of the normal equations A h = b,
  /// written into `rhs` (which may be dx or dy); returns the number of island texels.
  int buildSystem(const cv::Mat1f& dx, const cv::Mat1f& dy, const cv::Mat1b& mask, cv::Mat1f& rhs);
  /// q = A p, A the graph Laplacian of the island's edges (0 outside the island).
  void applyLaplacian(const cv::Mat1f& p, cv::Mat1f& q) const;
  /// z = M r: r put into the padded transform box (0 elsewhere), solved, read back on the
  /// island with zero island mean.
  void precondition(const cv::Mat1f& r, cv::Mat1f& z);
  /// Subtracts the island mean of v (texels outside stay 0).
  void removeIslandMean(cv::Mat1f& v) const;

  // Flags per texel: bit 0 in the island, bit 1 edge to the right, bit 2 edge downwards.
  cv::Mat1b flags_;
  int island_texels_ = 0;
  cv::Mat1f residual_, direction_, preconditioned_, product_, padded_;
  std::vector<float> gx_row_, gy_row_, gy_above_;  // original slope rows while b overwrites them
  ScratchBuffer<uchar> flag_buffer_;
  ScratchBuffer<float> residual_buffer_, direction_buffer_, preconditioned_buffer_, product_buffer_,
      padded_buffer_;
  NeumannPoissonSolver poisson_;
};

}  // namespace detail
}  // namespace norm2tex
