#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "norm2tex/mesh/textured_mesh.hpp"
#include "norm2tex/texture/height_atlas.hpp"
#include "norm2tex/texture/normal_map.hpp"

namespace norm2tex {

/// Texture depth (mm) of a normal map or atlas given without a beta: a texture file carries no
/// depth of its own, as a material's beta_mm does.
constexpr double kFileTextureBetaMm = 0.1;

/// Where an object's texture comes from: at most one of a procedural material, a normal map or
/// a baked atlas; none of them = the mesh's own normal texture, if it has one.
struct TextureSource {
  std::string material_config;  ///< config/materials/<name>.yaml
  int variant = 0;              ///< material variant (0 = the config's own values)
  std::uint64_t seed = 0;       ///< material seed
  std::string normal_map;       ///< PNG/JPEG/TIFF normal map, baked through the AtlasCache
  NormalConvention convention = NormalConvention::kOpenGL;
  /// A baked H_global: single-channel 32-bit float TIFF; NaN texels are invalid (what
  /// norm2tex_bake writes outside every island), infinite ones an error.
  std::string atlas;
};

/// H_global for the TextureOverlay, and what it came from.
struct ObjectTexture {
  std::shared_ptr<const HeightAtlas> atlas;  ///< null: no texture
  /// The beta this texture comes with, 0 when the source has none: a material's beta (mm), or
  /// 1 for a physical-scale atlas (heights already in mm: beta is a gain).
  double beta_mm = 0.0;
  bool physical_scale = false;  ///< the atlas holds millimetres (a mesh's own texture)
  std::string description;      ///< e.g. "material wood variant 3 seed 0", "normal map X (cached)"
  std::string warning;  ///< non-empty when something worked only in part (cache not writable)
};

/// A normal map (baked through the AtlasCache), an atlas file, or with neither the mesh's own
/// normal texture: a file next to the mesh or embedded in it (GLB "*N"). The mesh's own
/// texture is baked for the mesh (bakeHeightAtlasForMesh: its UV charts as islands, offsets
/// matched at seams) at physical scale, so H_global is in mm and beta_mm is 1, through the
/// AtlasCache under a key that covers the mesh (an embedded texture keyed by its bytes). Throws
/// Error naming the file for a given normal map or atlas,
/// or when `source` names a material; the mesh's own texture, when missing or unusable, gives no
/// atlas and a warning naming it as the mesh's normal texture (the mesh still renders).
ObjectTexture loadTextureFile(const TextureSource& source, const TexturedMesh& mesh);

/// Loads or bakes the texture. A procedural material is generated for `mesh`'s UV layout (a mesh
/// without UVs is replaced by its unwrapped copy, so `mesh` may change). Throws Error naming the
/// file at fault, or when more than one source is given.
ObjectTexture loadObjectTexture(const TextureSource& source, TexturedMesh& mesh);

}  // namespace norm2tex
