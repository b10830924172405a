#include "norm2tex/materials/material_texture.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/common/huge_pages.hpp"
#include "norm2tex/texture/height_atlas_baker.hpp"
#include "norm2tex/texture/normal_encoding.hpp"

namespace norm2tex {
namespace {

/// A texture-sized matrix filled with `value`, on huge pages: a 2048^2 texture's buffers are
/// 4-16 MB each, and a background thread's fresh 4 KB pages cost ~13 us each to fault in.
template <typename T>
cv::Mat_<T> filled(cv::Size size, const T& value) {
  cv::Mat_<T> matrix;
  createWithHugePages(matrix, size.height, size.width);
  matrix.setTo(value);
  return matrix;
}

/// 255 where `keep(label)` holds for the island map's label, else 0; on huge pages, unlike
/// `island == id`, which also faulted in a full-size int matrix of `id`.
template <typename Keep>
cv::Mat1b islandMask(const cv::Mat1i& island, Keep keep) {
  cv::Mat1b mask;
  createWithHugePages(mask, island.rows, island.cols);
  for (int r = 0; r < island.rows; ++r) {
    const int* in = island.ptr<int>(r);
    uchar* out = mask.ptr<uchar>(r);
    for (int c = 0; c < island.cols; ++c) out[c] = keep(in[c]) ? 255 : 0;
  }
  return mask;
}

/// Normal map (BGRA, alpha = valid) from a height field in mm with a per-texel resolution.
cv::Mat encodeWithAlpha(const cv::Mat1f& height_mm, const cv::Mat1f& mm_per_texel,
                        const cv::Mat1b& valid, int depth) {
  if (depth != CV_8U && depth != CV_16U) throw Error("normal map depth must be 8 or 16 bit");
  cv::Mat1f height_texels;
  createWithHugePages(height_texels, height_mm.rows, height_mm.cols);
  for (int r = 0; r < height_mm.rows; ++r) {
    const float* h = height_mm.ptr<float>(r);
    const float* s = mm_per_texel.ptr<float>(r);
    const uchar* ok = valid.ptr<uchar>(r);
    float* out = height_texels.ptr<float>(r);
    for (int c = 0; c < height_mm.cols; ++c) out[c] = ok[c] ? h[c] / s[c] : 0.0f;
  }
  return encodeNormalMapFromHeight(height_texels, NormalConvention::kOpenGL, depth, valid,
                                   /*with_alpha=*/true);
}

/// Alpha back to the validity after padding copied whole texels outwards.
void restoreAlpha(cv::Mat& bgra, const cv::Mat1b& valid) {
  for (int r = 0; r < bgra.rows; ++r) {
    const uchar* ok = valid.ptr<uchar>(r);
    if (bgra.depth() == CV_8U) {
      uchar* texel = bgra.ptr<uchar>(r);
      for (int c = 0; c < bgra.cols; ++c) texel[4 * c + 3] = ok[c] ? 255 : 0;
    } else {
      ushort* texel = bgra.ptr<ushort>(r);
      for (int c = 0; c < bgra.cols; ++c) texel[4 * c + 3] = ok[c] ? 65535 : 0;
    }
  }
}

}  // namespace

MaterialTexture renderMaterialTexture(const ProceduralMaterial& material, int size,
                                      double mm_per_texel, int depth) {
  if (size < 2 || size > 16384) throw Error("texture size must be in [2, 16384] texels");
  if (!(mm_per_texel > 0.0 && mm_per_texel <= 10.0)) {
    throw Error("mm_per_texel = " + std::to_string(mm_per_texel) +
                " is out of range; valid: (0, 10]");
  }
  MaterialTexture texture;
  const cv::Size extent(size, size);
  texture.height_mm = material.renderHeightMm(extent, mm_per_texel);
  texture.albedo = material.renderAlbedo(extent, mm_per_texel);
  texture.valid = filled<uchar>(extent, 255);
  texture.mm_per_texel = filled<float>(extent, static_cast<float>(mm_per_texel));
  texture.normal_map =
      encodeWithAlpha(texture.height_mm, texture.mm_per_texel, texture.valid, depth);
  return texture;
}

MaterialTexture renderMaterialTexture(const ProceduralMaterial& material, const UvLayout& layout,
                                      int depth, int padding_texels, bool with_albedo) {
  const cv::Size extent = layout.island.size();
  if (extent.width != extent.height || extent.width < 2) {
    throw Error("renderMaterialTexture: the UV layout must be square");
  }
  MaterialTexture texture;
  texture.height_mm = filled<float>(extent, 0.0f);
  if (with_albedo) texture.albedo = filled<cv::Vec3b>(extent, cv::Vec3b(0, 0, 0));
  texture.valid = islandMask(layout.island, [](int label) { return label > 0; });
  texture.mm_per_texel = filled<float>(extent, 0.0f);
  // Bounding box of each island, to evaluate the material only where that island lies.
  const int islands = static_cast<int>(layout.metres_per_uv.size());
  // Per island its column range per row, merged into the box once per row: a cv::Rect union
  // per texel was 20 ms of a 2048^2 texture.
  std::vector<cv::Rect> boxes(islands);
  std::vector<int> first(islands), last(islands);
  std::vector<int> seen;  // islands on the current row, in order of appearance
  for (int r = 0; r < extent.height; ++r) {
    const int* row = layout.island.ptr<int>(r);
    seen.clear();
    for (int c = 0; c < extent.width; ++c) {
      const int id = row[c];
      if (id <= 0 || id >= islands) continue;
      // Runs of one island are the rule: the last one seen answers without a search.
      const bool known = !seen.empty() && (seen.back() == id ||
                                           std::find(seen.begin(), seen.end(), id) != seen.end());
      if (!known) {
        seen.push_back(id);
        first[id] = c;
      }
      last[id] = c;
    }
    for (int id : seen) boxes[id] |= cv::Rect(first[id], r, last[id] - first[id] + 1, 1);
  }
  for (int id = 1; id < islands; ++id) {
    if (boxes[id].empty()) continue;
    // Texel (r, c) sits at u = (c + 0.5) / W, 1 - v = (r + 0.5) / H: in this island's mm
    // coordinates that is ((c + 0.5) * s, (r + 0.5) * s) with s = mm per UV unit / W.
    const double mm_per_texel = layout.metres_per_uv[id] * 1e3 / extent.width;
    const cv::Rect box = boxes[id];
    const cv::Point2d origin(box.x * mm_per_texel, box.y * mm_per_texel);
    const cv::Mat1b mask = islandMask(layout.island(box), [id](int label) { return label == id; });
    material.renderHeightMm(box.size(), mm_per_texel, origin).copyTo(texture.height_mm(box), mask);
    if (with_albedo) {
      material.renderAlbedo(box.size(), mm_per_texel, origin).copyTo(texture.albedo(box), mask);
    }
    texture.mm_per_texel(box).setTo(static_cast<float>(mm_per_texel), mask);
  }
  texture.normal_map =
      encodeWithAlpha(texture.height_mm, texture.mm_per_texel, texture.valid, depth);

  // Padding: colours (not alpha) grow outwards so bilinear look-ups at borders stay on-island.
  // Whole texels are copied, then alpha is set back to the validity.
  if (padding_texels > 0 &&
      cv::countNonZero(texture.valid) < static_cast<int>(texture.valid.total())) {
    padIslands(texture.normal_map, layout.island, padding_texels);
    restoreAlpha(texture.normal_map, texture.valid);
    if (with_albedo) {
      cv::Mat albedo = texture.albedo;
      padIslands(albedo, layout.island, padding_texels);
    }
  }
  return texture;
}

int materialAtlasSize(const MaterialConfig& config, const TexturedMesh& mesh) {
  if (!mesh.hasUvs()) return config.size;
  // metres per UV unit does not depend on the raster: a tiny layout gives it.
  const UvLayout layout = computeUvLayout(mesh, cv::Size(16, 16));
  double mm_per_uv = 0.0;
  for (const double metres : layout.metres_per_uv) mm_per_uv = std::max(mm_per_uv, 1e3 * metres);
  // No UV area (nothing to scale by) or a degenerate island (infinite): keep size.
  if (!(mm_per_uv > 0.0) || !std::isfinite(mm_per_uv)) return config.size;
  int size = config.size;
  while (size / 2 >= 16 && mm_per_uv / (size / 2) <= config.mm_per_texel) size /= 2;
  return size;
}

HeightAtlas bakeMaterialAtlas(const MaterialConfig& config, std::uint64_t seed, TexturedMesh& mesh,
                              int padding_texels, int variant) {
  // Before unwrapping: an automatic atlas is packed (padding included) for config.size.
  const int size = materialAtlasSize(config, mesh);
  if (!mesh.hasUvs()) {
    UnwrapOptions options;
    options.texture_size = config.size;
    options.padding_texels = padding_texels;
    mesh = unwrapUvs(mesh, options).mesh;
  }
  const auto material = makeMaterialVariant(config, variant, seed);
  const MaterialTexture texture =
      renderMaterialTexture(*material, computeUvLayout(mesh, cv::Size(size, size)), CV_16U,
                            padding_texels, /*with_albedo=*/false);
  BakeOptions options;
  options.range = config.range;
  // No relief high-pass: a procedural normal map is the exact slope of a designed height, so
  // integration accumulates no drift, and its long features (wood rings mm apart) are texture.
  options.relief_cutoff_mm = 0.0;
  options.relief_cutoff_texels = 0.0;
  return bakeHeightAtlas(NormalMap::fromImage(texture.normal_map, options.normal_map), options);
}

}  // namespace norm2tex
