#pragma once

#include <opencv2/core.hpp>

#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/materials/procedural_material.hpp"
#include "norm2tex/mesh/textured_mesh.hpp"
#include "norm2tex/mesh/uv_unwrap.hpp"
#include "norm2tex/texture/height_atlas.hpp"

namespace norm2tex {

/// A procedural material rendered into texture images.
struct MaterialTexture {
  cv::Mat1f height_mm;     ///< relief, mm; 0 outside islands
  cv::Mat1b valid;         ///< 255 on island texels (all of them for a plain texture)
  cv::Mat normal_map;      ///< tangent-space, OpenGL convention, BGRA (alpha = valid), 8 or 16 bit
  cv::Mat3b albedo;        ///< colour preview
  cv::Mat1f mm_per_texel;  ///< per texel: the island's texture resolution (0 outside islands)
};

/// A plain square texture: `size` texels at `mm_per_texel`, every texel valid. `depth` is CV_8U
/// or CV_16U.
MaterialTexture renderMaterialTexture(const ProceduralMaterial& material, int size,
                                      double mm_per_texel, int depth);

/// A texture for a mesh's UV layout (see computeUvLayout): every island is evaluated in its own
/// millimetre coordinates, (u, 1 - v) times the island's millimetres per UV unit, so the relief
/// has the same scale in mm on every face whatever each island's UV scale. Slopes are taken
/// within islands only; then every island's normals and albedo are extended `padding_texels`
/// into the empty texels around it (alpha stays 0 there), so filtering at island borders never
/// blends in the flat background. The layout must be square. `with_albedo` false leaves
/// `albedo` empty: a bake needs only the relief, and the colour costs as much again.
MaterialTexture renderMaterialTexture(const ProceduralMaterial& material, const UvLayout& layout,
                                      int depth, int padding_texels, bool with_albedo = true);

/// The side, in texels, of a material's atlas on `mesh`: the smallest of config.size,
/// config.size / 2, config.size / 4, ... (down to 16) whose texels are no larger than
/// config.mm_per_texel on the mesh's most stretched UV island. The material's stated resolution,
/// and no finer: finer texels cost time in every bake and cache misses in every frame, and show
/// nothing a DIGIT resolves (0.053 mm/pixel). E.g. the 30 mm cube (its UVs repeat every 20 mm):
/// print3d and smooth (0.025 mm) get 1024 (0.0195 mm/texel), wood, fabric and rock (0.05 mm)
/// 512 (0.039 mm/texel); at a fixed 2048 the cube had 0.0098 mm/texel. config.size when the
/// mesh has no UVs (its automatic atlas is packed for config.size) or when even config.size is
/// coarser than mm_per_texel.
int materialAtlasSize(const MaterialConfig& config, const TexturedMesh& mesh);

/// H_global of a material as it lies on `mesh`, ready for the TextureOverlay: the material
/// (variant `variant` of the config, see makeMaterialVariant; `seed`) rendered for the mesh's UV
/// layout at materialAtlasSize texels, encoded as a 16-bit normal map and baked with
/// config.range, exactly as a user's normal map file would be. A mesh without UVs is replaced by
/// its unwrapped copy first (so `mesh` may change).
HeightAtlas bakeMaterialAtlas(const MaterialConfig& config, std::uint64_t seed, TexturedMesh& mesh,
                              int padding_texels = 4, int variant = 0);

}  // namespace norm2tex
