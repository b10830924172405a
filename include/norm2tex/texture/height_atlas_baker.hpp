#pragma once

#include <functional>

#include "norm2tex/texture/frankot_chellappa.hpp"
#include "norm2tex/texture/height_atlas.hpp"
#include "norm2tex/texture/height_range.hpp"
#include "norm2tex/texture/normal_map.hpp"

namespace norm2tex {

/// Parameters of the bake (paper: "Converting RGB Normal to Height Map"), with its defaults.
struct BakeOptions {
  NormalMapOptions normal_map;     ///< convention, nz epsilon, alpha threshold
  double sigma_fine = 0.35;        ///< texels; mask-aware Gaussian on normals, fine pass
  double sigma_coarse = 1.1;       ///< texels; coarse pass
  double alpha = 0.2;              ///< H = (1 - alpha) H_fine + alpha H_coarse, in [0, 1]
  double percentile_low = 0.05;    ///< percent; maps to the range's low end (outliers clipped)
  double percentile_high = 99.95;  ///< percent; maps to the range's high end
  HeightRange range = HeightRange::kSymmetric;
  /// Subtract each island's mean slope before integrating. A constant tilt is not texture: an
  /// 8-bit map stores "flat" as 128/255, a slope of +0.004 per texel, which over a 2048-texel
  /// island would integrate into an 8-texel ramp that swamps the relief; a real tilt of the
  /// surface is the mesh's geometry, which H_sensor already has.
  bool remove_mean_slope = true;
  IntegrationOptions integration;
};

/// Throws Error naming the first parameter out of range and its valid range.
void validate(const BakeOptions& options);

/// Called with the fraction done in [0, 1] as islands complete.
using BakeProgress = std::function<void(double fraction)>;

/// Statistics of one bake, for logs and the CLI.
struct BakeReport {
  int island_count = 0;
  int valid_texels = 0;
  cv::Vec2f percentile_values;  ///< blended height at percentile_low / percentile_high
  int poisson_solves = 0;        ///< cosine/Fourier solves over all islands (1 per full box)
  double worst_relative_residual = 0.0;  ///< of the islands' conjugate-gradient solves
  int unconverged_islands = 0;   ///< islands whose solve hit max_iterations before tolerance
};

/// H_global from a decoded normal map: for every UV island on its own, a fine and a coarse
/// pass (mask-aware Gaussian of the normals, gradients), blended with alpha and integrated
/// once (Frankot-Chellappa is linear: the same as integrating each pass and blending the
/// heights); then one percentile normalisation over all valid texels into `range`. Texels
/// outside every island are 0 and invalid; the atlas gets the bake's island labels.
/// Deterministic: same input and options, same bits.
HeightAtlas bakeHeightAtlas(const NormalMap& normal_map, const BakeOptions& options = {},
                            const BakeProgress& progress = {}, BakeReport* report = nullptr);

}  // namespace norm2tex
