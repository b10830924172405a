#include "texture/relief_filter.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace norm2tex {
namespace detail {
namespace {

/// exp(-2 pi^2 sigma^2 f^2) for the cosine frequencies f = k / (2 n) of an axis of length n.
std::vector<float> gaussianGains(int n, double sigma) {
  std::vector<float> gains(n);
  for (int k = 0; k < n; ++k) {
    const double frequency = k / (2.0 * n);
    gains[k] =
        static_cast<float>(std::exp(-2.0 * CV_PI * CV_PI * sigma * sigma * frequency * frequency));
  }
  return gains;
}

}  // namespace

void ReliefFilter::blur(cv::Mat1f& values, double sigma) {
  cv::Mat1f& spectrum = transform_.forward(values);  // transposed: row u, column v
  const std::vector<float> gain_u = gaussianGains(values.cols, sigma);
  const std::vector<float> gain_v = gaussianGains(values.rows, sigma);
  for (int u = 0; u < spectrum.rows; ++u) {
    float* row = spectrum.ptr<float>(u);
    for (int v = 0; v < spectrum.cols; ++v) row[v] *= gain_u[u] * gain_v[v];
  }
  transform_.inverse(spectrum, values);
}

void ReliefFilter::removeLongWavelengths(cv::Mat1f& dx, cv::Mat1f& dy, const cv::Mat1b& mask,
                                         double cutoff_texels) {
  if (!(cutoff_texels > 0.0)) return;
  const double sigma = std::sqrt(std::log(2.0) / 2.0) / CV_PI * cutoff_texels;
  const int factor = std::max(1, std::min(8, static_cast<int>(sigma / 3.0)));
  const int coarse_rows = (mask.rows + factor - 1) / factor;
  const int coarse_cols = (mask.cols + factor - 1) / factor;
  const int rows = CosineTransform::transformLength(coarse_rows);
  const int cols = CosineTransform::transformLength(coarse_cols);

  // Box sums of g m and m on the coarse grid (their ratio is all that matters).
  cv::Mat1f sum_x = sum_x_.view(rows, cols), sum_y = sum_y_.view(rows, cols);
  cv::Mat1f weight = weight_.view(rows, cols);
  sum_x.setTo(0.0f);
  sum_y.setTo(0.0f);
  weight.setTo(0.0f);
  std::vector<int> cell(mask.cols);  // coarse column of each column (no division per texel)
  for (int c = 0; c < mask.cols; ++c) cell[c] = c / factor;
  for (int r = 0; r < mask.rows; ++r) {
    const uchar* in = mask.ptr<uchar>(r);
    const float* gx = dx.ptr<float>(r);
    const float* gy = dy.ptr<float>(r);
    float* sx = sum_x.ptr<float>(r / factor);
    float* sy = sum_y.ptr<float>(r / factor);
    float* w = weight.ptr<float>(r / factor);
    for (int c = 0; c < mask.cols; ++c) {
      if (!in[c]) continue;
      sx[cell[c]] += gx[c];
      sy[cell[c]] += gy[c];
      w[cell[c]] += 1.0f;
    }
  }
  const double coarse_sigma = sigma / factor;
  blur(sum_x, coarse_sigma);
  blur(sum_y, coarse_sigma);
  blur(weight, coarse_sigma);

  // Bilinear back to full resolution: coarse cell i is centred on texel factor (i + 1/2) - 1/2.
  // The columns' cells and weights are the same on every row: computed once.
  const float scale = 1.0f / static_cast<float>(factor);
  column_x0_.resize(mask.cols);
  column_x1_.resize(mask.cols);
  column_fx_.resize(mask.cols);
  for (int c = 0; c < mask.cols; ++c) {
    const float x = std::max(0.0f, (c + 0.5f) * scale - 0.5f);
    column_x0_[c] = std::min(static_cast<int>(x), cols - 1);
    column_x1_[c] = std::min(column_x0_[c] + 1, cols - 1);
    column_fx_[c] = std::min(1.0f, x - static_cast<float>(column_x0_[c]));
  }
  for (int r = 0; r < mask.rows; ++r) {
    const float y = std::max(0.0f, (r + 0.5f) * scale - 0.5f);
    const int y0 = std::min(static_cast<int>(y), rows - 1), y1 = std::min(y0 + 1, rows - 1);
    const float fy = std::min(1.0f, y - static_cast<float>(y0));
    const uchar* in = mask.ptr<uchar>(r);
    float* gx = dx.ptr<float>(r);
    float* gy = dy.ptr<float>(r);
    const float *sx0 = sum_x.ptr<float>(y0), *sx1 = sum_x.ptr<float>(y1);
    const float *sy0 = sum_y.ptr<float>(y0), *sy1 = sum_y.ptr<float>(y1);
    const float *w0 = weight.ptr<float>(y0), *w1 = weight.ptr<float>(y1);
    for (int c = 0; c < mask.cols; ++c) {
      if (!in[c]) continue;
      const int x0 = column_x0_[c], x1 = column_x1_[c];
      const float fx = column_fx_[c];
      const auto at = [&](const float* top, const float* bottom) {
        return (1 - fy) * ((1 - fx) * top[x0] + fx * top[x1]) +
               fy * ((1 - fx) * bottom[x0] + fx * bottom[x1]);
      };
      // The island's own texels keep the blurred weight above zero near them.
      const float w = std::max(at(w0, w1), 1e-12f);
      gx[c] -= at(sx0, sx1) / w;
      gy[c] -= at(sy0, sy1) / w;
    }
  }
}

}  // namespace detail
}  // namespace norm2tex
