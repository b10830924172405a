#include "norm2tex/render/object_texture.hpp"

#include <cmath>

#include <opencv2/imgcodecs.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/common/image_io.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/materials/material_texture.hpp"
#include "norm2tex/texture/atlas_cache.hpp"

namespace norm2tex {

ObjectTexture loadObjectTexture(const TextureSource& source, TexturedMesh& mesh) {
  const int given =
      !source.material_config.empty() + !source.normal_map.empty() + !source.atlas.empty();
  if (given > 1) {
    throw Error("texture: give one of a material, a normal map or an atlas, not " +
                std::to_string(given));
  }
  ObjectTexture out;
  if (!source.material_config.empty()) {
    const MaterialConfig config = loadMaterialConfig(source.material_config);
    out.atlas = std::make_shared<HeightAtlas>(
        bakeMaterialAtlas(config, source.seed, mesh, 4, source.variant));
    out.beta_mm = config.beta_mm;
    out.description = "material " + config.name + " variant " + std::to_string(source.variant) +
                      " seed " + std::to_string(source.seed);
    return out;
  }
  return loadTextureFile(source, mesh);
}

ObjectTexture loadTextureFile(const TextureSource& source, const TexturedMesh& mesh) {
  if (!source.material_config.empty()) {
    throw Error("texture: a material is generated, not loaded from a file");
  }
  if (!source.normal_map.empty() && !source.atlas.empty()) {
    throw Error("texture: give one of a normal map or an atlas, not both");
  }
  ObjectTexture out;
  if (!source.atlas.empty()) {
    const cv::Mat heights = readImage(source.atlas, cv::IMREAD_UNCHANGED, "atlas");
    if (heights.type() != CV_32FC1) {
      throw Error("atlas '" + source.atlas +
                  "' must be a single-channel 32-bit float TIFF (norm2tex_bake -o X.tiff)");
    }
    // NaN marks an invalid texel (norm2tex_bake writes its mask so); an infinite height is
    // broken data, which would otherwise press the gel without bound.
    cv::Mat1b valid(heights.size(), 255);
    int infinite = 0;
    for (int r = 0; r < heights.rows; ++r) {
      const float* h = heights.ptr<float>(r);
      for (int c = 0; c < heights.cols; ++c) {
        if (std::isinf(h[c])) ++infinite;
        if (!std::isfinite(h[c])) valid(r, c) = 0;
      }
    }
    if (infinite > 0) {
      throw Error("atlas '" + source.atlas + "' has " + std::to_string(infinite) +
                  " infinite texels; heights must be finite (NaN marks an invalid texel)");
    }
    if (cv::countNonZero(valid) == 0) {
      throw Error("atlas '" + source.atlas + "' has no valid texel (every texel is NaN)");
    }
    out.atlas = std::make_shared<HeightAtlas>(heights, valid);
    out.description = "atlas " + source.atlas;
    return out;
  }
  const std::string normal_map =
      source.normal_map.empty() ? mesh.normalTexturePath() : source.normal_map;
  if (normal_map.empty()) return out;
  BakeOptions options;
  options.normal_map.convention = source.convention;
  const AtlasCache cache(AtlasCache::defaultDirectory());
  AtlasCache::Result result = cache.loadOrBake(normal_map, "", options);
  out.warning = result.store_error;
  out.atlas = std::make_shared<HeightAtlas>(std::move(result.atlas));
  out.description = "normal map " + normal_map + (result.was_cached ? " (cached)" : " (baked)");
  return out;
}

}  // namespace norm2tex
