#pragma once
// The smoothing step of the bake's passes, fused with the slopes it feeds.

#include <vector>

#include <opencv2/core.hpp>

#include "texture/scratch_buffer.hpp"

namespace norm2tex {
namespace detail {

/// One smoothing pass of the bake: its Gaussian's sigma (texels) and its weight in the blend.
struct SlopePass {
  double sigma = 0.0;
  float weight = 1.0f;
};

/// Buffers kept between calls.
struct SlopeScratch {
  ScratchBuffer<cv::Vec3f> band, blurred;
};

/// For each pass in order, adds weight * (dx, dy) of the mask-aware Gaussian of `normals` to
/// `dx` and `dy` on the texels where `mask` != 0 (others are left alone).
///
/// Each smoothed normal is the Gaussian-weighted mean of the island's normals around it
/// (normalised convolution: texels outside the mask contribute nothing, so the flat "outside"
/// or a neighbouring island never drags an island's border); its slopes are dx = -nx/nz,
/// dy = -ny/nz, 0 where its normalised nz <= min_nz. sigma <= 0 uses the normals as they are.
/// The kernel radius is ceil(3 sigma) texels. All passes share one read of the normals, band
/// by band; each texel's sums are those of the passes one after the other.
void addMaskedGaussianSlopes(const cv::Mat3f& normals, const cv::Mat1b& mask,
                             const std::vector<SlopePass>& passes, double min_nz, cv::Mat1f& dx,
                             cv::Mat1f& dy, SlopeScratch& scratch);

}  // namespace detail
}  // namespace norm2tex
