#include "norm2tex/calibrate/background_noise.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "norm2tex/calibrate/qvga_scale.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/render/digit_shader_noise.hpp"

namespace norm2tex {
namespace {

struct ResidualStats {
  cv::Vec3d sigma{0, 0, 0};
  double neighbour_correlation = 0.0;
  double correlation_bg = 0.0, correlation_gr = 0.0, correlation_br = 0.0;
};

cv::Mat3f highPass(const cv::Mat3f& frame) {
  const double sigma = 3.0 * qvgaScale(frame.size());
  const int radius = static_cast<int>(std::ceil(3.0 * sigma));
  cv::Mat3f blurred;
  cv::GaussianBlur(frame, blurred, cv::Size(2 * radius + 1, 2 * radius + 1), sigma, sigma,
                   cv::BORDER_REFLECT_101);
  return frame - blurred;
}

// Statistics of the residuals of several frames, pooled (the border, where the blur reflects,
// left out).
ResidualStats residualStats(const std::vector<cv::Mat3f>& residuals) {
  const int margin = 8;
  double sum[3] = {}, sq[3] = {}, cross[3] = {}, lag_sum = 0.0, lag_sq = 0.0, n = 0.0;
  for (const cv::Mat3f& r : residuals) {
    for (int y = margin; y < r.rows - margin; ++y) {
      for (int x = margin; x < r.cols - margin; ++x) {
        const cv::Vec3f v = r(y, x), right = r(y, x + 1), down = r(y + 1, x);
        for (int k = 0; k < 3; ++k) {
          sum[k] += v[k];
          sq[k] += v[k] * v[k];
          lag_sum += v[k] * (right[k] + down[k]);
        }
        lag_sq += 2.0 * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        cross[0] += v[0] * v[1];
        cross[1] += v[1] * v[2];
        cross[2] += v[0] * v[2];
        n += 1.0;
      }
    }
  }
  ResidualStats s;
  double variance[3];
  for (int k = 0; k < 3; ++k) {
    variance[k] = std::max(sq[k] / n - (sum[k] / n) * (sum[k] / n), 1e-12);
    s.sigma[k] = std::sqrt(variance[k]);
  }
  s.neighbour_correlation = lag_sq > 0.0 ? lag_sum / lag_sq : 0.0;
  s.correlation_bg = (cross[0] / n - sum[0] * sum[1] / (n * n)) / (s.sigma[0] * s.sigma[1]);
  s.correlation_gr = (cross[1] / n - sum[1] * sum[2] / (n * n)) / (s.sigma[1] * s.sigma[2]);
  s.correlation_br = (cross[2] / n - sum[0] * sum[2] / (n * n)) / (s.sigma[0] * s.sigma[2]);
  return s;
}

// Residual statistics of the model's own noise (unit sigma, independent channels).
ResidualStats modelResidual(double neighbour_correlation, cv::Size size) {
  NoiseOptions unit;
  unit.sigma_bgr = {1.0, 1.0, 1.0};
  unit.neighbour_correlation = neighbour_correlation;
  unit.correlation_bg = unit.correlation_gr = unit.correlation_br = 0.0;
  cv::Mat3f noise;
  DigitShaderNoise(unit).generate(size, 12345, noise);
  return residualStats({highPass(noise)});
}

}  // namespace

NoiseOptions measureBackgroundNoise(const std::vector<cv::Mat3b>& backgrounds) {
  if (backgrounds.empty()) throw Error("measureBackgroundNoise: no background frames");
  std::vector<cv::Mat3f> residuals;
  for (const cv::Mat3b& frame : backgrounds) {
    if (frame.size() != backgrounds[0].size() || frame.rows < 16 || frame.cols < 16) {
      throw Error(
          "measureBackgroundNoise: background frames must share one size of at least 16 "
          "x 16 pixels");
    }
    cv::Mat3f f;
    frame.convertTo(f, CV_32F);
    residuals.push_back(highPass(f));
  }
  const ResidualStats measured = residualStats(residuals);
  const cv::Size size = backgrounds[0].size();

  // Model correlation whose residual correlation matches the measured one (monotonic).
  constexpr int kSteps = 8;
  double rho[kSteps], residual_rho[kSteps], ratio[kSteps];
  for (int i = 0; i < kSteps; ++i) {
    rho[i] = 0.7 * i / (kSteps - 1);
    const ResidualStats model = modelResidual(rho[i], size);
    residual_rho[i] = model.neighbour_correlation;
    ratio[i] = (model.sigma[0] + model.sigma[1] + model.sigma[2]) / 3.0;
  }
  double chosen_rho = rho[0], chosen_ratio = ratio[0];
  if (measured.neighbour_correlation >= residual_rho[kSteps - 1]) {
    chosen_rho = rho[kSteps - 1];
    chosen_ratio = ratio[kSteps - 1];
  } else {
    for (int i = 0; i + 1 < kSteps; ++i) {
      if (measured.neighbour_correlation < residual_rho[i + 1]) {
        const double t = std::clamp((measured.neighbour_correlation - residual_rho[i]) /
                                        (residual_rho[i + 1] - residual_rho[i]),
                                    0.0, 1.0);
        chosen_rho = rho[i] + t * (rho[i + 1] - rho[i]);
        chosen_ratio = ratio[i] + t * (ratio[i + 1] - ratio[i]);
        break;
      }
    }
  }
  NoiseOptions noise;
  noise.neighbour_correlation = chosen_rho;
  for (int k = 0; k < 3; ++k) noise.sigma_bgr[k] = std::min(64.0, measured.sigma[k] / chosen_ratio);
  noise.correlation_bg = measured.correlation_bg;
  noise.correlation_gr = measured.correlation_gr;
  noise.correlation_br = measured.correlation_br;
  for (int attempt = 0; attempt < 50; ++attempt) {
    const double bg = noise.correlation_bg, gr = noise.correlation_gr, br = noise.correlation_br;
    if (1.0 + 2.0 * bg * gr * br - bg * bg - gr * gr - br * br > 1e-3) break;
    noise.correlation_bg *= 0.9;
    noise.correlation_gr *= 0.9;
    noise.correlation_br *= 0.9;
  }
  noise.on_real_background = false;
  return noise;
}

}  // namespace norm2tex
