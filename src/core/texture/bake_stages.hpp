#pragma once
// The two stages of a bake, shared by bakeHeightAtlas (islands from the validity mask) and
// bakeHeightAtlasForMesh (islands from the mesh's UV charts, offsets matched at seams).

#include <opencv2/core.hpp>

#include "norm2tex/texture/height_atlas_baker.hpp"
#include "norm2tex/texture/uv_islands.hpp"

namespace norm2tex {
namespace detail {

/// Per island: smoothed, blended, high-passed slopes integrated; heights in texel units, zero
/// mean per island, 0 outside. Fills the island count, texel count, solver figures and cutoff
/// of `summary`. Throws Error when there is no island.
cv::Mat1f integrateIslands(const NormalMap& normal_map, const UvIslands& islands,
                           const BakeOptions& options, const BakeProgress& progress,
                           BakeReport& summary);

/// Percentile normalisation (or physical scale) on `valid`, then the atlas with `labels`.
/// Fills the percentile values and relief amplitude of `summary`.
HeightAtlas finishAtlas(cv::Mat1f global, cv::Mat1b valid, cv::Mat1i labels,
                        const BakeOptions& options, BakeReport& summary);

}  // namespace detail
}  // namespace norm2tex
