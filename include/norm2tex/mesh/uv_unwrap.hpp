#pragma once
// UV tools: an automatic atlas for meshes without usable UVs (unwrapUvs), where a texture lands
// on a mesh that has UVs (computeUvLayout), island padding against bleeding (padIslands) and
// mesh export (saveMesh). UV convention as in height_atlas.hpp: u along image columns, v up,
// image row 0 is v = 1.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/mesh/textured_mesh.hpp"

namespace norm2tex {

struct UnwrapOptions {
  int texture_size = 1024;  ///< texels of the (square) texture the atlas is packed for, >= 8
  int padding_texels = 4;   ///< empty texels kept between charts (and to the border), >= 0
};

struct UnwrapResult {
  /// Same geometry, new per-vertex UVs: output triangle i is input triangle i (same corner
  /// order, same positions); vertices are shared inside a chart and duplicated along chart
  /// seams. The input's normal texture path and source path are not carried over.
  TexturedMesh mesh;
  /// Metres per UV unit, the same for every chart: a texture's scale in mm is equal on every
  /// face (exactly on planar charts; curved charts are foreshortened, see unwrapUvs).
  double metres_per_uv = 0;
  int chart_count = 0;
};

/// Automatic atlas for meshes without (or with unusable) UVs; the input UVs are ignored.
///
/// Charts: each face starts with the nearest of 26 directions (cube faces, edges and corners;
/// every normal is within 27.6 deg of one) by its normal (from the winding). The labelling is
/// then smoothed: coplanar edge-connected faces move as one unit, and a unit may take any
/// direction within 40 deg of all its faces when that shortens the borders between directions
/// enough (so noisy normals do not shatter a surface into single-triangle charts); only borders
/// across smooth edges (dihedral < 25 deg) count, so a chamfer keeps its own chart. Faces of one
/// direction are split into edge-connected components (vertices joined by position, so
/// duplicated seam vertices do not split charts). Remaining fragments (< 1 % of an adjacent
/// chart and < 0.5 % of the mesh's area) whose faces are all within 60 deg of that chart's
/// direction are merged into it. Each chart is projected orthographically onto a plane: its
/// largest planar face's when that is half the chart or more (planar faces are mapped without
/// any stretch), else its direction's or its mean normal's, whichever is closer to its worst
/// face. UVs keep the winding's orientation (no mirroring). A chart whose projection would fold
/// onto itself (a ramp winding past 360 deg, say) is split where it would overlap.
/// Foreshortening: a face at angle t to its chart's projection direction has 3-D / UV length
/// ratios in [1, 1/cos t] * metres_per_uv; t = 0 on planar charts, t <= 27.6 deg (ratio <= 1.13)
/// on most of a clean curved surface, t <= 40 deg (ratio <= 1.31) along smoothed borders and
/// t <= 60 deg (ratio <= 2) on merged fragments.
///
/// Packing: each chart is turned to its minimum-area bounding rectangle, then all are packed at
/// one common scale, largest first, on a skyline (bottom-left rule, 90 deg turns allowed); the
/// largest scale that fits is found by bisection. Charts keep padding_texels empty texels
/// between each other and to the texture's border, counting texels by their centres as
/// computeUvLayout does.
///
/// Cost: ~0.2 s for 200k triangles on one core (Release), including the result's BVH.
///
/// Throws Error for an empty mesh, a mesh whose triangles all have zero area, out-of-range
/// options, or when the charts cannot fit (their padding alone needs more room than the texture
/// has: use a larger texture_size or fewer padding_texels).
UnwrapResult unwrapUvs(const TexturedMesh& mesh, const UnwrapOptions& options = {});

/// Where a texture of `size` lands on a mesh that has UVs.
struct UvLayout {
  /// Per texel the UV island (1..N) of the triangle containing the texel's centre; 0 = none.
  cv::Mat1i island;
  /// Indexed by island id: sqrt(3-D area / UV area) of the island's triangles (0 when the
  /// island has no UV area); element 0 unused (0).
  std::vector<double> metres_per_uv;
};

/// Islands are sets of triangles connected through shared edges in UV space: two triangles are
/// connected when they have an edge with the same two UV coordinates (bit-exact), whatever the
/// vertex indices or 3-D positions. Island ids follow the order of each island's first
/// triangle; islands too small to contain a texel centre still get an id.
/// Texel (r, c) centre = UV (u = (c + 0.5) / W, v = 1 - (r + 0.5) / H). UVs outside [0, 1]
/// wrap (repeat, as HeightAtlas's default). Where triangles overlap in UV space, the one with
/// the lowest index owns the texel; a texel centre on an edge shared by two triangles belongs to
/// one of them (no cracks). Throws Error if the mesh has no UVs or `size` is empty.
UvLayout computeUvLayout(const TexturedMesh& mesh, cv::Size size);

/// Extends every island's pixels outward into empty texels (island == 0) by up to `texels`
/// (Euclidean distance between texel centres, exact): each such texel gets a copy of its
/// nearest island texel's value, so bilinear look-ups at island borders never see background.
/// Texels farther away are left untouched; islands are not wrapped across the texture's border.
/// Works on any image type (CV_8UC3, CV_16UC3, CV_32FC1, ...) of the island map's size. Returns
/// the grown island map (the island id of each filled texel's source). Throws Error for an
/// empty or mismatched image, or texels < 0.
cv::Mat1i padIslands(cv::Mat& image, const cv::Mat1i& island, int texels);

/// Writes the mesh (positions, UVs when present, triangles): glTF itself, the rest with assimp's
/// Exporter. The format comes from the extension (case-insensitive): .obj, .ply (ASCII), .stl
/// (binary, no UVs), .dae, .glb, .gltf (+ .bin next to it; embedded when the name needs URI
/// escaping). UVs are written in each format's own convention, so TexturedMesh::load gives back the
/// same UVs: glTF stores v downwards (v_file = 1 - v) and assimp's importer flips it back. glTF is
/// written by the package itself (glTF 2.0, with vertex normals), not by assimp, whose exporter
/// does not flip v before 5.1: the file is the same on every platform. A non-empty `normal_texture`
/// is referenced by the material as a path relative to the file's directory (absolute when there is
/// no relative path), so TexturedMesh::load finds it again: for .obj in <stem>.mtl (written,
/// overwriting) with `map_Bump` and `norm`; for .dae, .glb and .gltf as the normal texture (glTF
/// normalTexture, a percent-encoded URI, not embedded); .ply and .stl have no materials and drop
/// it. Throws Error (naming the file) for an unknown extension, an unwritable path or an assimp
/// failure.
void saveMesh(const TexturedMesh& mesh, const std::string& path,
              const std::string& normal_texture = "");

}  // namespace norm2tex
