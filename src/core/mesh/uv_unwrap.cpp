// unwrapUvs: chart grouping by normal direction, orthographic projection, overlap splitting
// and skyline packing at one common scale. See uv_unwrap.hpp for the contract; the steps are in
// uv_adjacency (faces, welding, adjacency), uv_charts (segmentation), uv_packing (pieces and
// packing) and uv_geometry (their geometry helpers).
#include "norm2tex/mesh/uv_unwrap.hpp"

#include <array>
#include <utility>
#include <vector>

#include "common/error_messages.hpp"
#include "mesh/uv_adjacency.hpp"
#include "mesh/uv_charts.hpp"
#include "mesh/uv_packing.hpp"
#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

// The steps of unwrapUvs (src/core/mesh/uv_*.hpp).
using uv_unwrap_detail::Adjacency;
using uv_unwrap_detail::buildAdjacency;
using uv_unwrap_detail::chartDirections;
using uv_unwrap_detail::Face;
using uv_unwrap_detail::makeFaces;
using uv_unwrap_detail::makePieces;
using uv_unwrap_detail::Packing;
using uv_unwrap_detail::packPieces;
using uv_unwrap_detail::Piece;
using uv_unwrap_detail::Placement;
using uv_unwrap_detail::Segmentation;
using uv_unwrap_detail::segmentCharts;
using uv_unwrap_detail::Vec2;
using uv_unwrap_detail::Vec3;
using uv_unwrap_detail::weldedPositions;
using uv_unwrap_detail::weldVertices;

// Checks the options' ranges and that the mesh has triangles at all.
void checkInputs(const TexturedMesh& mesh, const UnwrapOptions& options) {
  detail::requireParameter(options.texture_size >= 8 && options.texture_size <= 65536,
                           "unwrapUvs: texture_size", options.texture_size, "8..65536");
  detail::requireParameter(
      options.padding_texels >= 0 && options.padding_texels <= options.texture_size / 4,
      "unwrapUvs: padding_texels", options.padding_texels, "0..texture_size / 4");
  if (mesh.triangles().empty()) throw Error("unwrapUvs: the mesh is empty (no triangles)");
}

// Writes the result mesh: per piece its own vertices (the original positions) with their UVs in
// the packed texture; triangles keep their index and corner order.
UnwrapResult makeResult(const TexturedMesh& mesh, const std::vector<int>& representative,
                        const std::vector<Face>& faces, const std::vector<Piece>& pieces,
                        const Packing& packing, const UnwrapOptions& options) {
  const double texture = options.texture_size;
  const double scale = packing.scale;
  const int piece_count = static_cast<int>(pieces.size());
  std::vector<int> local_index(representative.size(), -1);
  std::vector<Eigen::Vector3f> out_vertices;
  std::vector<Eigen::Vector2f> out_uvs;
  std::vector<Eigen::Vector3i> out_triangles(faces.size());
  for (int i = 0; i < piece_count; ++i) {
    const Piece& piece = pieces[i];
    const Placement& placement = packing.placements[i];
    const int base = static_cast<int>(out_vertices.size());
    const Vec2 size = placement.rotated ? Vec2(piece.size.y(), piece.size.x()) : piece.size;
    const double left = packing.border + placement.x;
    const double top = packing.border + placement.y;
    for (size_t k = 0; k < piece.vertices.size(); ++k) {
      const Vec2& p = piece.local[k];
      // A quarter turn (a, b) -> (h - b, a) keeps the orientation.
      const Vec2 q = placement.rotated ? Vec2(piece.size.y() - p.y(), p.x()) : p;
      const double column = left + q.x() * scale;
      const double row = top + (size.y() - q.y()) * scale;  // v up, rows down
      out_vertices.push_back(mesh.vertices()[representative[piece.vertices[k]]]);
      out_uvs.emplace_back(static_cast<float>(column / texture),
                           static_cast<float>(1.0 - row / texture));
      local_index[piece.vertices[k]] = base + static_cast<int>(k);
    }
    for (int f : piece.faces) {
      for (int k = 0; k < 3; ++k) out_triangles[f][k] = local_index[faces[f].v[k]];
    }
    for (int v : piece.vertices) local_index[v] = -1;
  }

  UnwrapResult result;
  result.mesh = TexturedMesh(std::move(out_vertices), std::move(out_triangles), std::move(out_uvs));
  result.metres_per_uv = texture / scale;
  result.chart_count = piece_count;
  return result;
}

}  // namespace

UnwrapResult unwrapUvs(const TexturedMesh& mesh, const UnwrapOptions& options) {
  checkInputs(mesh, options);

  // Faces on welded vertices, their normals and nearest directions.
  std::vector<int> representative;
  const std::vector<int> welded = weldVertices(mesh.vertices(), representative);
  const std::vector<Vec3> positions = weldedPositions(mesh.vertices(), representative);
  const std::array<Vec3, 26> directions = chartDirections();
  double total_area = 0.0;
  std::vector<Face> faces = makeFaces(mesh.triangles(), welded, positions, directions, total_area);
  const Adjacency adjacency = buildAdjacency(faces, positions);

  // Labels smoothed over planar units, charts, fragments merged.
  const Segmentation segmentation = segmentCharts(faces, adjacency, directions, total_area);

  // Charts projected and split into non-overlapping pieces, packed and written out.
  const std::vector<Piece> pieces =
      makePieces(segmentation.charts, faces, adjacency, segmentation.units, positions, directions);
  const Packing packing = packPieces(pieces, options);
  return makeResult(mesh, representative, faces, pieces, packing, options);
}

}  // namespace norm2tex
