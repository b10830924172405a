#include "norm2tex/calibrate/texture_sample.hpp"

#include <algorithm>
#include <memory>

#include <opencv2/imgcodecs.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/common/image_io.hpp"
#include "norm2tex/materials/material_texture.hpp"
#include "norm2tex/texture/height_atlas_baker.hpp"
#include "norm2tex/texture/normal_map.hpp"

namespace norm2tex {

TextureSample makeMaterialSample(const MaterialConfig& config, std::uint64_t seed) {
  validate(config);
  const auto material = makeMaterialVariant(config, 0, seed);
  const MaterialTexture texture =
      renderMaterialTexture(*material, config.size, config.mm_per_texel, CV_16U);
  BakeOptions options;
  options.range = config.range;
  // As bakeMaterialAtlas: a procedural normal map is an exact slope field, so integrating it
  // accumulates no drift, and its long features (wood rings mm apart) are texture.
  options.relief_cutoff_mm = 0.0;
  options.relief_cutoff_texels = 0.0;
  TextureSample sample;
  sample.atlas = std::make_shared<const HeightAtlas>(
      bakeHeightAtlas(NormalMap::fromImage(texture.normal_map, options.normal_map), options));
  sample.period_mm = config.size * config.mm_per_texel;
  sample.beta_mm = config.beta_mm;
  return sample;
}

TextureSample makeNormalMapSample(const std::string& path, double mm_per_texel, double beta_mm) {
  if (!(mm_per_texel > 0.0 && mm_per_texel <= 1.0)) {
    throw Error("normal map '" + path + "': mm_per_texel " + std::to_string(mm_per_texel) +
                " is outside (0, 1] mm");
  }
  if (!(beta_mm > 0.0 && beta_mm <= 2.0)) {
    throw Error("normal map '" + path + "': beta " + std::to_string(beta_mm) +
                " mm is outside (0, 2] mm");
  }
  const cv::Mat image = readImage(path, cv::IMREAD_UNCHANGED, "normal map");
  const int side = std::min(image.rows, image.cols);
  const cv::Rect square((image.cols - side) / 2, (image.rows - side) / 2, side, side);
  BakeOptions options;
  options.mm_per_texel = mm_per_texel;
  NormalMap normals = [&] {
    try {
      return NormalMap::fromImage(image(square), options.normal_map);
    } catch (const Error& e) {
      throw Error("normal map '" + path + "': " + e.what());
    }
  }();
  TextureSample sample;
  sample.atlas = std::make_shared<const HeightAtlas>(bakeHeightAtlas(normals, options));
  sample.period_mm = side * mm_per_texel;
  sample.beta_mm = beta_mm;
  return sample;
}

}  // namespace norm2tex
