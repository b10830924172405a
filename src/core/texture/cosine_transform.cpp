#include "texture/cosine_transform.hpp"

#include <algorithm>
#include <cmath>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace detail {

// The cosine transform goes through one real DFT per row (Makhoul 1980): reorder the row as
// v[n] = x[2n], v[n - 1 - k] = x[2k + 1], take its real DFT V, then X[k] = Re(e^{-i pi k/2n}
// V[k]). Rows first, transpose, rows again: two real cv::dft calls over the whole matrix
// (DFT_ROWS), about twice as fast as cv::dct, which runs a complex DFT per row of half length.
// Inverse: V[k] = e^{i pi k/2n} (X[k] - i X[n-k]), inverse real DFT, undo the reordering.

namespace {

/// From this length on a square transform transposes in place (faster than out of place there,
/// and no second buffer).
constexpr int kInPlaceTransposeLength = 512;

/// In-place transpose of a square matrix, in 32 x 32 tiles swapped through two small buffers.
/// cv::transpose in place swaps single elements along whole rows and columns, which misses the
/// cache at every step: 0.12 s at 4096^2 against 0.01 s here (and 0.03 s out of place, which
/// would need a second 64 MB buffer).
void transposeSquareInPlace(cv::Mat1f& m) {
  constexpr int kTile = 32;
  alignas(64) float a[kTile][kTile];
  alignas(64) float b[kTile][kTile];
  const int n = m.rows;
  for (int i0 = 0; i0 < n; i0 += kTile) {
    const int height = std::min(kTile, n - i0);
    for (int j0 = i0; j0 < n; j0 += kTile) {
      const int width = std::min(kTile, n - j0);
      // a[j][i] = m(i0 + i, j0 + j): tile (i0, j0) transposed.
      for (int i = 0; i < height; ++i) {
        const float* row = m.ptr<float>(i0 + i) + j0;
        for (int j = 0; j < width; ++j) a[j][i] = row[j];
      }
      if (j0 == i0) {  // a diagonal tile stays where it is
        for (int j = 0; j < width; ++j) {
          float* row = m.ptr<float>(i0 + j) + i0;
          for (int i = 0; i < height; ++i) row[i] = a[j][i];
        }
        continue;
      }
      // b[i][j] = m(j0 + j, i0 + i): the mirrored tile, transposed; then the two swap.
      for (int j = 0; j < width; ++j) {
        const float* row = m.ptr<float>(j0 + j) + i0;
        for (int i = 0; i < height; ++i) b[i][j] = row[i];
      }
      for (int i = 0; i < height; ++i) {
        float* row = m.ptr<float>(i0 + i) + j0;
        for (int j = 0; j < width; ++j) row[j] = b[i][j];
      }
      for (int j = 0; j < width; ++j) {
        float* row = m.ptr<float>(j0 + j) + i0;
        for (int i = 0; i < height; ++i) row[i] = a[j][i];
      }
    }
  }
}

/// dst = src^T for a non-square src (dst has src's transposed size): cv::transpose.
/// For src and dst the same square matrix: in place, tiled.
void transposeInto(const cv::Mat1f& src, cv::Mat1f& dst) {
  if (src.data == dst.data) {
    CV_Assert(src.rows == src.cols && dst.rows == src.rows && dst.cols == src.cols);
    transposeSquareInPlace(dst);
  } else {
    cv::transpose(src, dst);
  }
}

}  // namespace

int CosineTransform::transformLength(int n) {
  int length = cv::getOptimalDFTSize(n);
  while (length % 2 != 0) length = cv::getOptimalDFTSize(length + 1);
  return length;
}

void CosineTransform::prepare(int rows, int cols) {
  if (rows == rows_ && cols == cols_) return;
  if (rows % 2 != 0 || cols % 2 != 0) {
    throw Error("CosineTransform: sizes must be even, got " + std::to_string(cols) + "x" +
                std::to_string(rows));
  }
  const auto twiddles = [](int n, std::vector<float>& cosines, std::vector<float>& sines) {
    cosines.resize(n / 2 + 1);
    sines.resize(n / 2 + 1);
    for (int k = 0; k <= n / 2; ++k) {
      cosines[k] = static_cast<float>(std::cos(CV_PI * k / (2.0 * n)));
      sines[k] = static_cast<float>(std::sin(CV_PI * k / (2.0 * n)));
    }
  };
  twiddles(cols, cos_x_, sin_x_);
  twiddles(rows, cos_y_, sin_y_);
  rows_ = rows;
  cols_ = cols;
}

void CosineTransform::forwardRows(cv::Mat1f& m, const std::vector<float>& cosines,
                                  const std::vector<float>& sines) {
  const int n = m.cols, half = n / 2;
  row_.resize(n);
  for (int r = 0; r < m.rows; ++r) {
    float* v = m.ptr<float>(r);
    std::copy(v, v + n, row_.begin());
    for (int k = 0; k < half; ++k) {
      v[k] = row_[2 * k];
      v[n - 1 - k] = row_[2 * k + 1];
    }
  }
  // Packed (CCS) spectrum per row: Re0, Re1, Im1, ..., Re(n/2-1), Im(n/2-1), Re(n/2).
  cv::dft(m, m, cv::DFT_ROWS);
  for (int r = 0; r < m.rows; ++r) {
    float* p = m.ptr<float>(r);
    row_[0] = p[0];
    row_[half] = p[n - 1] * cosines[half];
    for (int k = 1; k < half; ++k) {
      const float re = p[2 * k - 1], im = p[2 * k];
      row_[k] = re * cosines[k] + im * sines[k];
      row_[n - k] = re * sines[k] - im * cosines[k];
    }
    std::copy(row_.begin(), row_.end(), p);
  }
}

void CosineTransform::inverseRows(cv::Mat1f& m, const std::vector<float>& cosines,
                                  const std::vector<float>& sines) {
  const int n = m.cols, half = n / 2;
  row_.resize(n);
  for (int r = 0; r < m.rows; ++r) {
    float* p = m.ptr<float>(r);
    row_[0] = p[0];
    row_[n - 1] = p[half] * 1.41421356f;
    for (int k = 1; k < half; ++k) {
      const float a = p[k], b = p[n - k];
      row_[2 * k - 1] = a * cosines[k] + b * sines[k];
      row_[2 * k] = a * sines[k] - b * cosines[k];
    }
    std::copy(row_.begin(), row_.end(), p);
  }
  cv::dft(m, m, cv::DFT_INVERSE | cv::DFT_ROWS | cv::DFT_SCALE | cv::DFT_REAL_OUTPUT);
  for (int r = 0; r < m.rows; ++r) {
    float* x = m.ptr<float>(r);
    std::copy(x, x + n, row_.begin());
    for (int k = 0; k < half; ++k) {
      x[2 * k] = row_[k];
      x[2 * k + 1] = row_[n - 1 - k];
    }
  }
}

cv::Mat1f& CosineTransform::forward(cv::Mat1f& x) {
  prepare(x.rows, x.cols);
  forwardRows(x, cos_x_, sin_x_);
  // The spectrum lives transposed (row u, column v), which a diagonal operator does not
  // mind and inverse() undoes. A large square matrix transposes in place: no second buffer
  // to fault in. Small ones (the islands of an atlas) go through one: it stays in cache, and
  // cv::transpose out of place is twice as fast as the tiled swap there.
  if (rows_ == cols_ && rows_ >= kInPlaceTransposeLength) {
    spectrum_ = x;
  } else {
    spectrum_ = transposed_.view(cols_, rows_);
  }
  transposeInto(x, spectrum_);
  forwardRows(spectrum_, cos_y_, sin_y_);
  return spectrum_;
}

void CosineTransform::inverse(cv::Mat1f& spectrum, cv::Mat1f& x) {
  inverseRows(spectrum, cos_y_, sin_y_);
  x.create(rows_, cols_);
  transposeInto(spectrum, x);  // in place when x is the (square) spectrum itself
  inverseRows(x, cos_x_, sin_x_);
}

}  // namespace detail
}  // namespace norm2tex
