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

void ReliefFilter::highPass(cv::Mat1f& slope, const cv::Mat1b& mask, const cv::Mat1f& weights,
                            double sigma) {
  const int rows = CosineTransform::transformLength(slope.rows);
  const int cols = CosineTransform::transformLength(slope.cols);
  cv::Mat1f values = values_.view(rows, cols);
  values.setTo(0.0f);
  for (int r = 0; r < slope.rows; ++r) {
    const uchar* in = mask.ptr<uchar>(r);
    const float* g = slope.ptr<float>(r);
    float* out = values.ptr<float>(r);
    for (int c = 0; c < slope.cols; ++c) out[c] = in[c] ? g[c] : 0.0f;
  }
  blur(values, sigma);
  for (int r = 0; r < slope.rows; ++r) {
    const uchar* in = mask.ptr<uchar>(r);
    const float* low = values.ptr<float>(r);
    const float* weight = weights.empty() ? nullptr : weights.ptr<float>(r);
    float* g = slope.ptr<float>(r);
    for (int c = 0; c < slope.cols; ++c) {
      if (!in[c]) continue;
      // The texel's own weight is at least the kernel's centre > 0, so w never vanishes.
      g[c] -= weight == nullptr ? low[c] : low[c] / std::max(weight[c], 1e-12f);
    }
  }
}

void ReliefFilter::removeLongWavelengths(cv::Mat1f& dx, cv::Mat1f& dy, const cv::Mat1b& mask,
                                         double cutoff_texels) {
  if (!(cutoff_texels > 0.0)) return;
  const double sigma = std::sqrt(std::log(2.0) / 2.0) / CV_PI * cutoff_texels;
  const int rows = CosineTransform::transformLength(mask.rows);
  const int cols = CosineTransform::transformLength(mask.cols);
  // An island that fills the transform box has blur(m) = 1 everywhere: no normalisation.
  cv::Mat1f weights;
  if (cv::countNonZero(mask) != rows * cols) {
    weights = weights_.view(rows, cols);
    weights.setTo(0.0f);
    weights(cv::Rect(0, 0, mask.cols, mask.rows)).setTo(1.0f, mask);
    blur(weights, sigma);
  }
  highPass(dx, mask, weights, sigma);
  highPass(dy, mask, weights, sigma);
}

}  // namespace detail
}  // namespace norm2tex
