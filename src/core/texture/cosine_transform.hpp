#pragma once
// The 2-D cosine transform (DCT-II, unnormalised) through one real cv::dft per pass: the basis
// that diagonalises the Neumann Laplacian and Gaussian blurs with mirrored borders.

#include <vector>

#include <opencv2/core.hpp>

#include "texture/scratch_buffer.hpp"

namespace norm2tex {
namespace detail {

class CosineTransform {
 public:
  /// Spectrum of `x` (rows x cols, both even), computed in place: `x` is overwritten. The
  /// spectrum is laid out *transposed*: spectrum(u, v) is the coefficient of
  /// cos(pi u (c + 1/2) / cols) cos(pi v (r + 1/2) / rows). Returns `x` itself for a square
  /// `x` of 512 and more (transposed in place), else internal memory valid until the next
  /// call. In place because every full-size buffer is fresh memory, and first touch is most
  /// of a large bake.
  cv::Mat1f& forward(cv::Mat1f& x);
  /// Inverse of forward(): `spectrum` must be the matrix forward() returned (it is
  /// overwritten); writes rows x cols into `x` (forward's input, or any rows x cols matrix).
  void inverse(cv::Mat1f& spectrum, cv::Mat1f& x);

  /// The smallest even length >= n whose real DFT is fast.
  static int transformLength(int n);

 private:
  void prepare(int rows, int cols);
  // Both in place, row by row through row_.
  void forwardRows(cv::Mat1f& m, const std::vector<float>& cosines,
                   const std::vector<float>& sines);
  void inverseRows(cv::Mat1f& m, const std::vector<float>& cosines,
                   const std::vector<float>& sines);

  int rows_ = 0, cols_ = 0;
  // Twiddles cos(pi k / 2n), sin(pi k / 2n) for k <= n / 2, per axis.
  std::vector<float> cos_x_, sin_x_, cos_y_, sin_y_;
  std::vector<float> row_;
  ScratchBuffer<float> transposed_;  // only for a non-square x
  cv::Mat1f spectrum_;
};

}  // namespace detail
}  // namespace norm2tex
