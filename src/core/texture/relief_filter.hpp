#pragma once
// Relief, not drift: the Gaussian high-pass that keeps an island's fine relief and drops the
// long-wavelength drift that integration of a real normal map accumulates.

#include <vector>

#include <opencv2/core.hpp>

#include "texture/cosine_transform.hpp"
#include "texture/scratch_buffer.hpp"

namespace norm2tex {
namespace detail {

class ReliefFilter {
 public:
  /// Subtracts from the slopes `dx`, `dy` their mask-aware Gaussian low-pass (normalised
  /// convolution: blur(g m) / blur(m), mirrored at the box's border, texels outside `mask`
  /// contributing nothing), on the texels where `mask` != 0. The Gaussian's gain is 1/2 at
  /// wavelength `cutoff_texels` (sigma = sqrt(ln 2 / 2) / pi * cutoff = 0.187 cutoff): longer
  /// wavelengths are removed, shorter ones kept.
  ///
  /// Why the slopes and not the height: integration is linear, so away from the border this is
  /// the same high-pass of the height; at the border, a mirrored blur reproduces a locally
  /// constant function but not a ramp, and drift is a ramp in height but nearly constant in
  /// slope.
  ///
  /// The low-pass is smooth, so it is computed on a grid `factor` times coarser (box
  /// averages, factor = sigma / 3 texels, at most 8), blurred through the cosine transform there
  /// and interpolated back bilinearly: a 2048^2 island costs a few transforms of 512^2.
  void removeLongWavelengths(cv::Mat1f& dx, cv::Mat1f& dy, const cv::Mat1b& mask,
                             double cutoff_texels);

 private:
  /// In place on a transform-sized matrix: Gaussian blur (sigma in its own texels).
  void blur(cv::Mat1f& values, double sigma);

  CosineTransform transform_;
  ScratchBuffer<float> sum_x_, sum_y_, weight_;
  std::vector<int> column_x0_, column_x1_;  // per full-resolution column: its coarse cells
  std::vector<float> column_fx_;            // and the weight of the second
};

}  // namespace detail
}  // namespace norm2tex
