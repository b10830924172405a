#include "norm2tex/render/object_texture.hpp"

#include <cmath>
#include <cstdio>

#include <opencv2/imgcodecs.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/common/image_io.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/materials/material_texture.hpp"
#include "norm2tex/texture/atlas_cache.hpp"
#include "norm2tex/texture/mesh_bake.hpp"

namespace norm2tex {
namespace {

/// A normal map file through the AtlasCache.
ObjectTexture bakeCached(const std::string& path, const BakeOptions& options,
                         const std::string& what) {
  ObjectTexture out;
  const AtlasCache cache(AtlasCache::defaultDirectory());
  AtlasCache::Result result = cache.loadOrBake(path, "", options);
  out.warning = result.store_error;
  out.atlas = std::make_shared<HeightAtlas>(std::move(result.atlas));
  out.description = what + path + (result.was_cached ? " (cached)" : " (baked)");
  return out;
}

/// " (baked on N UV charts, ... mm per texel, relief amplitude ..., seam step a% -> b%)".
std::string describeMeshBake(const MeshBakeReport& report) {
  char note[256];
  std::snprintf(note, sizeof(note),
                " (baked on %d UV charts, %.3g mm per texel, relief amplitude %.3g mm, seam "
                "step %.1f%% -> %.1f%%)",
                report.chart_count, report.mm_per_texel, report.bake.relief_amplitude_mm,
                100.0 * report.seams.step_before, 100.0 * report.seams.step_after);
  return note;
}

}  // namespace

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
                      " seed " + std::to_string(source.seed) + ", " +
                      std::to_string(out.atlas->cols()) + "^2 atlas";
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
  BakeOptions options;
  options.normal_map.convention = source.convention;
  if (!source.normal_map.empty()) return bakeCached(source.normal_map, options, "normal map ");
  // The mesh's own normal texture: a problem with it is a warning, the mesh still renders.
  const std::string& reference = mesh.normalTextureReference();
  if (reference.empty()) return out;
  const std::string what = "the mesh's normal texture '" + reference + "'";
  try {
    // The mesh's own texture on the mesh: its charts, its scale, heights in mm, beta 1.
    BakeOptions for_mesh = options;
    for_mesh.physical_scale = mesh.hasUvs();
    if (!mesh.normalTexturePath().empty()) {
      if (!mesh.hasUvs()) {
        return bakeCached(mesh.normalTexturePath(), options, "the mesh's normal texture ");
      }
      const AtlasCache cache(AtlasCache::defaultDirectory());
      AtlasCache::Result result =
          cache.loadOrBake(mesh.normalTexturePath(), "", for_mesh, {}, &mesh);
      out.warning = result.store_error;
      out.atlas = std::make_shared<HeightAtlas>(std::move(result.atlas));
      out.description = "the mesh's normal texture " + reference +
                        (result.was_cached ? " (cached)" : describeMeshBake(result.mesh_report));
    } else if (mesh.embeddedNormalTexture().empty()) {
      out.warning = what + " is embedded in a form that is not supported (only PNG/JPEG/TIFF " +
                    "files are); rendering without texture";
      return out;
    } else {
      // Embedded (GLB "*N", data URI): cached under its bytes (and the mesh), like a file.
      const AtlasCache cache(AtlasCache::defaultDirectory());
      AtlasCache::Result result =
          mesh.hasUvs() ? cache.loadOrBake(mesh.embeddedNormalTexture(), what, for_mesh, {}, &mesh)
                        : cache.loadOrBake(mesh.embeddedNormalTexture(), what, options);
      out.warning = result.store_error;
      out.atlas = std::make_shared<HeightAtlas>(std::move(result.atlas));
      out.description = "the mesh's normal texture " + reference +
                        (result.was_cached ? std::string(" (cached)")
                         : mesh.hasUvs()   ? describeMeshBake(result.mesh_report)
                                           : std::string(" (baked)"));
    }
    if (mesh.hasUvs()) {
      out.beta_mm = 1.0;
      out.physical_scale = true;
    }
    return out;
  } catch (const Error& e) {
    out = ObjectTexture();
    out.warning = what + " cannot be used (" + e.what() + "); rendering without texture";
    return out;
  }
}

}  // namespace norm2tex
