#include "norm2tex/texture/height_atlas_baker.hpp"

#include <algorithm>

#include "common/error_messages.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/huge_pages.hpp"
#include "norm2tex/texture/uv_islands.hpp"
#include "texture/bake_stages.hpp"
#include "texture/masked_gaussian.hpp"
#include "texture/relief_filter.hpp"
#include "texture/scratch_buffer.hpp"

namespace norm2tex {
namespace {

/// Buffers of the largest island so far, reused for every island of one bake.
struct BakeWorkspace {
  explicit BakeWorkspace(const IntegrationOptions& integration) : integrator(integration) {}
  detail::ScratchBuffer<uchar> mask;
  detail::ScratchBuffer<float> dx, dy;
  detail::SlopeScratch smoothing;
  FrankotChellappaIntegrator integrator;
  detail::ReliefFilter relief;
};

/// The blended height of one island, written into `dx` (the box's size; 0 outside the island):
/// the fine and coarse passes' slopes blended with alpha, integrated once. Integration is
/// linear, so this is (1 - alpha) H_fine + alpha H_coarse without a second solve.
void integrateIsland(const cv::Mat3f& normals, const cv::Mat1b& mask, const BakeOptions& options,
                     cv::Mat1f dx, BakeWorkspace& workspace, IntegrationReport& integration) {
  cv::Mat1f dy = workspace.dy.view(mask.size());
  dx.setTo(0.0f);
  dy.setTo(0.0f);
  const double min_nz = options.normal_map.min_nz;
  // A pass with zero weight is skipped, not computed and multiplied by 0.
  std::vector<detail::SlopePass> passes;
  if (options.alpha < 1.0) {
    passes.push_back({options.sigma_fine, static_cast<float>(1.0 - options.alpha)});
  }
  if (options.alpha > 0.0)
    passes.push_back({options.sigma_coarse, static_cast<float>(options.alpha)});
  detail::addMaskedGaussianSlopes(normals, mask, passes, min_nz, dx, dy, workspace.smoothing);
  if (options.remove_mean_slope) {
    cv::subtract(dx, cv::mean(dx, mask), dx, mask);
    cv::subtract(dy, cv::mean(dy, mask), dy, mask);
  }
  workspace.relief.removeLongWavelengths(dx, dy, mask, reliefCutoffTexels(options));
  // The height goes into dx's memory: the integrator is done with the slopes before it writes
  // (one buffer fewer to fault in: 64 MB on a 4096^2 map).
  workspace.integrator.integrate(dx, dy, mask, dx, &integration);
}

/// Heights in texel units times mm per texel: millimetres. The range picks the zero: the high
/// percentile for 0,-1 (peaks at 0), the low one for 0,1, the mean for -1,1 (already 0).
void toPhysicalScale(cv::Mat1f& height, const cv::Mat1b& valid, cv::Vec2f low_high,
                     const BakeOptions& options) {
  float zero = 0.0f;
  if (options.range == HeightRange::kRemove) zero = low_high[1];
  if (options.range == HeightRange::kAdd) zero = low_high[0];
  const float scale = static_cast<float>(options.mm_per_texel);
  for (int r = 0; r < height.rows; ++r) {
    float* h = height.ptr<float>(r);
    const uchar* ok = valid.ptr<uchar>(r);
    for (int c = 0; c < height.cols; ++c) h[c] = ok[c] ? (h[c] - zero) * scale : 0.0f;
  }
}

}  // namespace

BakeOptions paperExactBakeOptions() {
  BakeOptions options;
  options.relief_cutoff_mm = 0.0;
  options.relief_cutoff_texels = 0.0;
  options.remove_mean_slope = false;
  options.integration.boundary = PoissonBoundary::kPeriodic;
  return options;
}

double reliefCutoffTexels(const BakeOptions& options) {
  if (options.mm_per_texel > 0.0) return options.relief_cutoff_mm / options.mm_per_texel;
  return options.relief_cutoff_texels;
}

void validate(const BakeOptions& options) {
  validate(options.normal_map);
  validate(options.integration);
  detail::requireParameter(options.sigma_fine >= 0.0 && options.sigma_fine <= 50.0, "sigma_fine",
                           options.sigma_fine, "[0, 50] texels");
  detail::requireParameter(options.sigma_coarse >= 0.0 && options.sigma_coarse <= 50.0,
                           "sigma_coarse", options.sigma_coarse, "[0, 50] texels");
  detail::requireParameter(options.alpha >= 0.0 && options.alpha <= 1.0, "alpha", options.alpha,
                           "[0, 1]");
  detail::requireParameter(options.percentile_low >= 0.0 && options.percentile_low < 50.0,
                           "percentile_low", options.percentile_low, "[0, 50) percent");
  detail::requireParameter(options.percentile_high > 50.0 && options.percentile_high <= 100.0,
                           "percentile_high", options.percentile_high, "(50, 100] percent");
  detail::requireParameter(options.relief_cutoff_mm >= 0.0 && options.relief_cutoff_mm <= 1000.0,
                           "relief_cutoff_mm", options.relief_cutoff_mm, "[0, 1000] mm (0 = off)");
  detail::requireParameter(
      options.relief_cutoff_texels >= 0.0 && options.relief_cutoff_texels <= 1e6,
      "relief_cutoff_texels", options.relief_cutoff_texels, "[0, 1e6] texels (0 = off)");
  detail::requireParameter(options.mm_per_texel >= 0.0 && options.mm_per_texel <= 100.0,
                           "mm_per_texel", options.mm_per_texel, "[0, 100] mm (0 = unknown)");
  if (options.physical_scale && !(options.mm_per_texel > 0.0)) {
    throw Error(
        "physical_scale needs mm_per_texel (the surface's millimetres per texel, from a mesh's "
        "UVs or the texture's size)");
  }
}

namespace detail {

cv::Mat1f integrateIslands(const NormalMap& normal_map, const UvIslands& islands,
                           const BakeOptions& options, const BakeProgress& progress,
                           BakeReport& summary) {
  validate(options);
  if (islands.islands.empty()) {
    throw Error("the normal map has no valid texel (all masked by alpha, mask or nz <= " +
                std::to_string(options.normal_map.min_nz) + ")");
  }
  long total = 0;
  for (const UvIsland& island : islands.islands) total += island.texel_count;
  cv::Mat1f global;
  createWithHugePages(global, normal_map.rows(), normal_map.cols());
  global.setTo(0.0f);
  BakeWorkspace workspace(options.integration);
  // One island (a tiling texture, the common case) is integrated straight into H_global's own
  // memory: a full-size buffer fewer to fault in (64 MB at 4096^2), and no copy.
  const bool in_place = islands.islands.size() == 1;
  long done = 0;
  for (const UvIsland& island : islands.islands) {
    const cv::Rect box = island.bounding_box;
    cv::Mat1b mask = workspace.mask.view(box.size());
    cv::compare(islands.labels(box), island.label, mask, cv::CMP_EQ);
    IntegrationReport integration;
    cv::Mat1f height = in_place ? global(box) : workspace.dx.view(box.size());
    integrateIsland(normal_map.normals()(box), mask, options, height, workspace, integration);
    if (!in_place) height.copyTo(global(box), mask);
    summary.poisson_solves += integration.solves;
    summary.worst_relative_residual =
        std::max(summary.worst_relative_residual, integration.relative_residual);
    if (!integration.converged) ++summary.unconverged_islands;
    done += island.texel_count;
    if (progress) progress(static_cast<double>(done) / total);
  }
  summary.island_count = static_cast<int>(islands.islands.size());
  summary.valid_texels = static_cast<int>(total);
  summary.relief_cutoff_texels = reliefCutoffTexels(options);
  return global;
}

HeightAtlas finishAtlas(cv::Mat1f global, cv::Mat1b valid, cv::Mat1i labels,
                        const BakeOptions& options, BakeReport& summary) {
  const cv::Vec2f low_high =
      maskedPercentiles(global, valid, options.percentile_low, options.percentile_high);
  if (options.physical_scale) {
    toPhysicalScale(global, valid, low_high, options);
  } else {
    normalizeToRange(global, valid, low_high, options.range);
  }
  summary.percentile_values = low_high;
  summary.relief_amplitude_mm = (low_high[1] - low_high[0]) * options.mm_per_texel;
  return HeightAtlas(std::move(global), std::move(valid), std::move(labels));
}

}  // namespace detail

HeightAtlas bakeHeightAtlas(const NormalMap& normal_map, const BakeOptions& options,
                            const BakeProgress& progress, BakeReport* report) {
  UvIslands islands = findUvIslands(normal_map.valid());
  BakeReport summary;
  cv::Mat1f global = detail::integrateIslands(normal_map, islands, options, progress, summary);
  cv::Mat1b valid;  // the atlas's own copy, on huge pages like its heights
  createWithHugePages(valid, normal_map.rows(), normal_map.cols());
  normal_map.valid().copyTo(valid);
  HeightAtlas atlas = detail::finishAtlas(std::move(global), std::move(valid),
                                          std::move(islands.labels), options, summary);
  if (report != nullptr) *report = summary;
  return atlas;
}

}  // namespace norm2tex
