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
  /// Relief, not drift. Integrating a real normal map accumulates long-wavelength drift (its
  /// small slope biases add up over hundreds of texels); normalised by percentiles, the drift
  /// takes the whole range and the fine relief inside a contact vanishes. Geometry at the
  /// scale of millimetres is the mesh's, which H_sensor already has, so wavelengths longer
  /// than the cutoff are removed from each island before normalisation (Gaussian high-pass,
  /// half gain at the cutoff). The cutoff is relief_cutoff_mm on the surface when
  /// mm_per_texel is known, else relief_cutoff_texels. 0 keeps every wavelength (the paper).
  double relief_cutoff_mm = 2.0;
  double relief_cutoff_texels = 64.0;
  /// Millimetres of surface per texel (from a mesh's UVs, or the texture's known size);
  /// 0 = unknown.
  double mm_per_texel = 0.0;
  /// Physical scale: a normal map's slopes are dh/dx, so with mm_per_texel the integrated
  /// height is in millimetres. H_global is then that height in mm (no percentile stretch; the
  /// range only sets which end is 0: peaks at 0 for 0,-1, valleys at 0 for 0,1, zero mean for
  /// -1,1), and beta becomes a gain (1 = the relief the normal map implies).
  bool physical_scale = false;
};

/// The paper's bake and nothing more: no relief high-pass, no mean-slope removal, the periodic
/// Fourier solve. For comparisons; real normal maps bake mostly to drift with it.
BakeOptions paperExactBakeOptions();

/// The relief cutoff in texels these options imply (0 = none).
double reliefCutoffTexels(const BakeOptions& options);

/// Throws Error naming the first parameter out of range and its valid range.
void validate(const BakeOptions& options);

/// Called with the fraction done in [0, 1] as islands complete.
using BakeProgress = std::function<void(double fraction)>;

/// Statistics of one bake, for logs and the CLI.
struct BakeReport {
  int island_count = 0;
  int valid_texels = 0;
  cv::Vec2f percentile_values;  ///< blended height at percentile_low / percentile_high
  int poisson_solves = 0;       ///< cosine/Fourier solves over all islands (1 per full box)
  double worst_relative_residual = 0.0;  ///< of the islands' conjugate-gradient solves
  int unconverged_islands = 0;        ///< islands whose solve hit max_iterations before tolerance
  double relief_cutoff_texels = 0.0;  ///< the high-pass cutoff used, 0 = none
  /// (percentile_high - percentile_low) value x mm_per_texel: the relief amplitude the normal
  /// map implies, mm; 0 when mm_per_texel is unknown.
  double relief_amplitude_mm = 0.0;
};

/// H_global from a decoded normal map: for every UV island on its own, a fine and a coarse
/// pass (mask-aware Gaussian of the normals, gradients), blended with alpha and integrated
/// once (Frankot-Chellappa is linear: the same as integrating each pass and blending the
/// heights), its wavelengths above the relief cutoff removed; then one percentile
/// normalisation over all valid texels into `range` (or the physical scale). Texels outside
/// every island are 0 and invalid; the atlas gets the bake's island labels.
/// Deterministic: same input and options, same bits.
HeightAtlas bakeHeightAtlas(const NormalMap& normal_map, const BakeOptions& options = {},
                            const BakeProgress& progress = {}, BakeReport* report = nullptr);

}  // namespace norm2tex
