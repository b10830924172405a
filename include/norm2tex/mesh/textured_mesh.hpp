#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace norm2tex {

struct MeshLoadOptions {
  /// Multiplies the file's coordinates to get metres: 0.001 for meshes in millimetres. Collada
  /// files with a <unit> tag come in metres already (assimp applies it), so keep 1 for them.
  double scale = 1.0;
};

/// A triangle mesh with optional per-vertex UVs (first channel), in metres, in the object frame.
///
/// Loaded with assimp (OBJ, STL, PLY, DAE, glTF/GLB, ...): triangulated, identical vertices
/// joined; all triangle meshes of the scene are merged with their node transforms applied
/// (points and lines are dropped). Coordinates are the file's own, with no up-axis conversion
/// (Collada's <up_axis> is ignored, as rviz and MoveIt do; glTF stays Y-up as written). The file's
/// normals (and colours, tangents) are not kept: nothing uses them, and dropping them first lets
/// vertices that share a position and UV be joined even in STL, which stores one normal per facet.
///
/// UVs come from channel 0 in assimp's OpenGL convention (v up; glTF's v is flipped on import),
/// see height_atlas.hpp. When only some of the merged meshes have UVs, the mesh keeps them and
/// the vertices of the meshes without get (0, 0): losing the texture of the textured parts would
/// be worse than sampling one texel on the untextured ones.
///
/// A bounding-volume hierarchy over the triangles (binned SAH, leaves of <= 4 triangles) answers
/// "which triangles can be near the gel" so large meshes (>= 200k triangles) rasterize only what
/// matters.
class TexturedMesh {
 public:
  TexturedMesh() = default;
  /// From arrays (tests, procedural meshes). `uvs` is empty or one per vertex. Throws Error
  /// when there is no triangle, an index is out of range, a coordinate or UV is not finite, or
  /// the UV count is neither 0 nor the vertex count. Builds the BVH (~0.1 s for 200k triangles).
  TexturedMesh(std::vector<Eigen::Vector3f> vertices, std::vector<Eigen::Vector3i> triangles,
               std::vector<Eigen::Vector2f> uvs = {});

  /// Throws Error naming the file: missing, unreadable, not a mesh, or no triangles.
  static TexturedMesh load(const std::string& path, const MeshLoadOptions& options = {});

  const std::vector<Eigen::Vector3f>& vertices() const { return vertices_; }
  const std::vector<Eigen::Vector3i>& triangles() const { return triangles_; }
  /// One per vertex, or empty when the file has no texture coordinates.
  const std::vector<Eigen::Vector2f>& uvs() const { return uvs_; }
  bool hasUvs() const { return !uvs_.empty(); }
  /// Absolute path of the normal texture the file's material references (glTF normalTexture,
  /// OBJ norm, else OBJ map_Bump / bump), from the first mesh whose material has one. Relative
  /// references are resolved against the mesh file's directory, for an .obj first against the
  /// directory of the .mtl that names it (where the file exists there). An .obj's .mtl is read
  /// by the package itself, so the result is the same on every assimp release. Empty when there
  /// is none or it is embedded in the file.
  const std::string& normalTexturePath() const { return normal_texture_path_; }
  /// The normal texture's reference as the file writes it ("textures/n.png", or "*0" for the
  /// first texture embedded in a GLB); empty when the material has none. For messages.
  const std::string& normalTextureReference() const { return normal_texture_reference_; }
  /// The bytes of an embedded normal texture (a PNG or JPEG file inside a GLB or glTF data
  /// URI), empty when the texture is a file of its own or there is none.
  const std::vector<unsigned char>& embeddedNormalTexture() const {
    return embedded_normal_texture_;
  }
  /// Axis-aligned bounds in the object frame, metres.
  const Eigen::AlignedBox3f& bounds() const { return bounds_; }

  /// Appends to `out` the indices of every triangle whose bounds, mapped into the gel frame by
  /// `object_in_gel`, may intersect `region` (gel frame, metres). Conservative: may return
  /// triangles outside, never misses one inside. Cost ~ log(n) + returned triangles.
  void queryTriangles(const Eigen::Isometry3f& object_in_gel, const Eigen::AlignedBox3f& region,
                      std::vector<int>& out) const;

  /// Path of the file the mesh came from, or empty.
  const std::string& sourcePath() const { return source_path_; }

 private:
  struct BvhNode {
    Eigen::AlignedBox3f box;
    int first = 0;  ///< leaf: first entry in bvh_triangles_; inner: index of the left child
    int count = 0;  ///< leaf: number of triangles; inner: 0 (right child = left + 1)
  };
  void buildBvh();

  std::vector<Eigen::Vector3f> vertices_;
  std::vector<Eigen::Vector3i> triangles_;
  std::vector<Eigen::Vector2f> uvs_;
  std::string normal_texture_path_;
  std::string normal_texture_reference_;
  std::vector<unsigned char> embedded_normal_texture_;
  std::string source_path_;
  Eigen::AlignedBox3f bounds_;
  std::vector<BvhNode> bvh_nodes_;
  std::vector<int> bvh_triangles_;
};

}  // namespace norm2tex
