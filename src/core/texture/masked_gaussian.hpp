#pragma once
// The smoothing step of each bake pass, fused with the slopes it feeds.

#include <opencv2/core.hpp>

#include "texture/scratch_buffer.hpp"

namespace norm2tex {
namespace detail {

/// Adds weight * (dx, dy) of the mask-aware Gaussian of `normals` to `dx` and `dy` on the
/// texels where `mask` != 0 (others are left alone).
///
/// Each smoothed normal is the Gaussian-weighted mean of the island's normals around it
/// (normalised convolution: texels outside the mask contribute nothing, so the flat "outside"
/// or a neighbouring island never drags an island's border); its slopes are dx = -nx/nz,
/// dy = -ny/nz, 0 where its normalised nz <= min_nz. sigma <= 0 uses the normals as they are.
/// The kernel radius is ceil(3 sigma) texels. `scratch` is reused between calls.
void addMaskedGaussianSlopes(const cv::Mat3f& normals, const cv::Mat1b& mask, double sigma,
                             double min_nz, float weight, cv::Mat1f& dx, cv::Mat1f& dy,
                             ScratchBuffer<cv::Vec3f>& scratch);

}  // namespace detail
}  // namespace norm2tex
