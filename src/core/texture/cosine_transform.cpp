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

void CosineTransform::forwardRows(const cv::Mat1f& in, cv::Mat1f& out,
                                  const std::vector<float>& cosines,
                                  const std::vector<float>& sines) {
  const int n = in.cols, half = n / 2;
  for (int r = 0; r < in.rows; ++r) {
    const float* x = in.ptr<float>(r);
    float* v = out.ptr<float>(r);
    for (int k = 0; k < half; ++k) {
      v[k] = x[2 * k];
      v[n - 1 - k] = x[2 * k + 1];
    }
  }
  // Packed (CCS) spectrum per row: Re0, Re1, Im1, ..., Re(n/2-1), Im(n/2-1), Re(n/2).
  cv::dft(out, out, cv::DFT_ROWS);
  row_.resize(n);
  for (int r = 0; r < out.rows; ++r) {
    float* p = out.ptr<float>(r);
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

void CosineTransform::inverseRows(cv::Mat1f& in, cv::Mat1f& out, const std::vector<float>& cosines,
                                  const std::vector<float>& sines) {
  const int n = in.cols, half = n / 2;
  row_.resize(n);
  for (int r = 0; r < in.rows; ++r) {
    float* p = in.ptr<float>(r);
    row_[0] = p[0];
    row_[n - 1] = p[half] * 1.41421356f;
    for (int k = 1; k < half; ++k) {
      const float a = p[k], b = p[n - k];
      row_[2 * k - 1] = a * cosines[k] + b * sines[k];
      row_[2 * k] = a * sines[k] - b * cosines[k];
    }
    std::copy(row_.begin(), row_.end(), p);
  }
  cv::dft(in, in, cv::DFT_INVERSE | cv::DFT_ROWS | cv::DFT_SCALE | cv::DFT_REAL_OUTPUT);
  for (int r = 0; r < in.rows; ++r) {
    const float* v = in.ptr<float>(r);
    float* x = out.ptr<float>(r);
    for (int k = 0; k < half; ++k) {
      x[2 * k] = v[k];
      x[2 * k + 1] = v[n - 1 - k];
    }
  }
}

cv::Mat1f& CosineTransform::forward(const cv::Mat1f& x) {
  prepare(x.rows, x.cols);
  // first_ holds rows x cols, second_ its transpose; the spectrum lives transposed (row u,
  // column v), which a diagonal operator does not mind and inverse() undoes.
  cv::Mat1f rows_pass = first_.view(rows_, cols_);
  forwardRows(x, rows_pass, cos_x_, sin_x_);
  cv::Mat1f transposed = second_.view(cols_, rows_);
  cv::transpose(rows_pass, transposed);
  spectrum_ = first_.view(cols_, rows_);
  forwardRows(transposed, spectrum_, cos_y_, sin_y_);
  return spectrum_;
}

void CosineTransform::inverse(cv::Mat1f& spectrum, cv::Mat1f& x) {
  cv::Mat1f transposed = second_.view(cols_, rows_);
  inverseRows(spectrum, transposed, cos_y_, sin_y_);
  cv::Mat1f rows_pass = first_.view(rows_, cols_);
  cv::transpose(transposed, rows_pass);
  x.create(rows_, cols_);
  inverseRows(rows_pass, x, cos_x_, sin_x_);
}

}  // namespace detail
}  // namespace norm2tex
