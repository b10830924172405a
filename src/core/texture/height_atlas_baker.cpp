#include "norm2tex/texture/height_atlas_baker.hpp"

#include "common/error_messages.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/texture/masked_gaussian.hpp"
#include "norm2tex/texture/uv_islands.hpp"

namespace norm2tex {
namespace {

/// One pass of the paper: smooth the normals, take slopes, integrate.
cv::Mat1f integratePass(const cv::Mat3f& normals, const cv::Mat1b& mask, double sigma,
                        const BakeOptions& options) {
  const cv::Mat3f smoothed = maskedGaussianNormals(normals, mask, sigma);
  cv::Mat1f dx, dy;
  normalsToGradients(smoothed, mask, options.normal_map.min_nz, dx, dy);
  if (options.remove_mean_slope) {
    cv::subtract(dx, cv::mean(dx, mask), dx, mask);
    cv::subtract(dy, cv::mean(dy, mask), dy, mask);
  }
  return integrateFrankotChellappa(dx, dy, mask, options.integration);
}

}  // namespace

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
}

HeightAtlas bakeHeightAtlas(const NormalMap& normal_map, const BakeOptions& options,
                            const BakeProgress& progress, BakeReport* report) {
  validate(options);
  const UvIslands islands = findUvIslands(normal_map.valid());
  if (islands.islands.empty()) {
    throw Error("the normal map has no valid texel (all masked by alpha, mask or nz <= " +
                std::to_string(options.normal_map.min_nz) + ")");
  }
  const int valid_texels = normal_map.validCount();
  cv::Mat1f blended(normal_map.rows(), normal_map.cols(), 0.0f);
  long done = 0;
  for (const UvIsland& island : islands.islands) {
    const cv::Rect box = island.bounding_box;
    const cv::Mat1b mask = islands.labels(box) == island.label;
    const cv::Mat3f normals = normal_map.normals()(box);
    cv::Mat1f height;
    // A pass with zero weight is skipped, not computed and multiplied by 0.
    if (options.alpha < 1.0) {
      height = integratePass(normals, mask, options.sigma_fine, options) * (1.0 - options.alpha);
    }
    if (options.alpha > 0.0) {
      const cv::Mat1f coarse = integratePass(normals, mask, options.sigma_coarse, options);
      height = height.empty() ? cv::Mat1f(coarse * options.alpha)
                              : cv::Mat1f(height + coarse * options.alpha);
    }
    height.copyTo(blended(box), mask);
    done += island.texel_count;
    if (progress) progress(static_cast<double>(done) / valid_texels);
  }

  const cv::Vec2f low_high = maskedPercentiles(blended, normal_map.valid(), options.percentile_low,
                                               options.percentile_high);
  normalizeToRange(blended, normal_map.valid(), low_high, options.range);
  if (report != nullptr) {
    report->island_count = static_cast<int>(islands.islands.size());
    report->valid_texels = valid_texels;
    report->percentile_values = low_high;
  }
  return HeightAtlas(std::move(blended), normal_map.valid().clone());
}

}  // namespace norm2tex
