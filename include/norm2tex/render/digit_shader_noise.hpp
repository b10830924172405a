#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/render/sensor_model.hpp"

namespace norm2tex {

/// DIGIT pixel noise as measured on real frames: per-channel sigma, correlated between
/// neighbouring pixels and between channels (green anti-correlated with blue and red).
///
/// Per frame: unit Gaussian samples for every pixel and channel, drawn in raster order with
/// xoshiro256** from the seed through a 4096-entry inverse-CDF table (five samples per 64-bit
/// draw: fresh every frame, identical for the same seed on every standard library); each
/// channel is filtered by the separable kernel k (x) k, k = [a, 1, a] / sqrt(1 + 2 a^2), which
/// keeps unit variance and gives neighbouring pixels the correlation 2a / (1 + 2a^2) (0.6 for
/// a = 0.392; diagonal neighbours get its square); then each pixel's three values are mixed by
/// the Cholesky factor of the channel covariance built from sigma_bgr and the correlations.
class DigitShaderNoise {
 public:
  /// Throws Error (through validate) for options out of range.
  explicit DigitShaderNoise(const NoiseOptions& options);

  /// True unless every sigma is 0.
  bool enabled() const { return enabled_; }

  /// Noise (CV_32FC3, grey levels) of `size`, reproducible from `seed`.
  void generate(cv::Size size, std::uint64_t seed, cv::Mat3f& noise) const;

 private:
  bool enabled_ = false;
  std::vector<float> table_;  // unit normal quantiles
  cv::Mat1f kernel_;          // the 1-D smoothing kernel k (3 taps)
  cv::Matx33f mixing_;        // lower-triangular Cholesky factor of the channel covariance
};

}  // namespace norm2tex
