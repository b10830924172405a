#pragma once

#include <optional>
#include <string>
#include <vector>

#include "norm2tex/mesh/textured_mesh.hpp"
#include "norm2tex/texture/height_atlas.hpp"
#include "norm2tex/texture/height_atlas_baker.hpp"
#include "norm2tex/texture/mesh_bake.hpp"

namespace norm2tex {

/// A disk cache of baked HeightAtlases so a node restart does not re-bake.
///
/// The key is a hash of everything the bake depends on: the bytes of the normal map and of the
/// mask file, every BakeOptions field and the cache format version (not the path: moving a file
/// keeps its entry), and for a bake for a mesh the mesh's positions, triangles and UVs. A
/// normal map held in memory (a texture embedded in a glTF/GLB, "*N") is keyed by its encoded
/// bytes the same way, so it is cached like a file. An entry is four files in the cache directory:
/// `<key>.tiff` (H_global, 32-bit float), `<key>.valid.png` (mask), `<key>.islands.png` (the bake's
/// island labels, 16-bit) and `<key>.yaml` (metadata: source path and hash, convention, parameters,
/// island count), each written to a temporary name and renamed, the yaml last, so a crash mid-write
/// leaves no entry that looks complete.
class AtlasCache {
 public:
  /// `directory` is created on first store.
  explicit AtlasCache(std::string directory);

  /// $NORM2TEX_CACHE_DIR, else $XDG_CACHE_HOME/norm2tex, else $HOME/.cache/norm2tex.
  static std::string defaultDirectory();

  /// Throws Error if a file cannot be read. With `mesh`, the key also covers the mesh's
  /// positions, triangles and UVs (a bake for the mesh: bakeHeightAtlasForMesh).
  std::string key(const std::string& normal_map_path, const std::string& mask_path,
                  const BakeOptions& options, const TexturedMesh* mesh = nullptr) const;
  /// The key of an encoded normal map held in memory (the same as that of a file holding these
  /// bytes, without a mask).
  std::string key(const std::vector<unsigned char>& encoded_normal_map, const BakeOptions& options,
                  const TexturedMesh* mesh = nullptr) const;

  /// The cached atlas for `key`, or nothing if absent or unreadable (a damaged entry is a miss).
  std::optional<HeightAtlas> load(const std::string& key) const;

  /// Stores an entry; throws Error when the directory or a file cannot be written.
  void store(const std::string& key, const HeightAtlas& atlas, const std::string& normal_map_path,
             const std::string& mask_path, const BakeOptions& options) const;

  /// What loadOrBake did.
  struct Result {
    HeightAtlas atlas;
    bool was_cached = false;
    /// Non-empty when the bake succeeded but could not be stored (read-only or full disk):
    /// the atlas is still good, the next start will bake again.
    std::string store_error;
    /// What the mesh bake did (charts, scale, seams); filled when baked for a mesh now.
    MeshBakeReport mesh_report;
  };

  /// Cached atlas if present, else NormalMap::load + bakeHeightAtlas (bakeHeightAtlasForMesh
  /// with `mesh`) + store. Throws Error for bad input (the normal map, mask or mesh cannot be
  /// used), never for a cache that cannot be written.
  Result loadOrBake(const std::string& normal_map_path, const std::string& mask_path,
                    const BakeOptions& options, const BakeProgress& progress = {},
                    const TexturedMesh* mesh = nullptr) const;

  /// loadOrBake() for an encoded PNG/JPEG/TIFF held in memory, such as a mesh's embedded normal
  /// texture (TexturedMesh::embeddedNormalTexture(), with `mesh` for a bake on its UV charts):
  /// decoded (decodeImage: truncated or corrupt bytes are refused) and baked only on a miss.
  /// `what` names it in errors and as the entry's source ("the mesh's normal texture '*0'").
  Result loadOrBake(const std::vector<unsigned char>& encoded_normal_map, const std::string& what,
                    const BakeOptions& options, const BakeProgress& progress = {},
                    const TexturedMesh* mesh = nullptr) const;

  const std::string& directory() const { return directory_; }

 private:
  void storeEntry(const std::string& key, const HeightAtlas& atlas, const std::string& source,
                  const std::string& source_hash, const std::string& mask_path,
                  const std::string& mask_hash, const BakeOptions& options) const;

  std::string directory_;
};

}  // namespace norm2tex
