#pragma once
// unwrapUvs' first step: the mesh's faces on welded vertices (one id per distinct position),
// their normals, areas and nearest directions, and which faces share an edge.
// Private to the core (src/core/mesh/).

#include <array>
#include <vector>

#include <Eigen/Core>

#include "mesh/uv_geometry.hpp"

namespace norm2tex {
namespace uv_unwrap_detail {

/// Non-manifold edges shared by more faces than this are linked as a chain, not all pairs.
constexpr int kMaxEdgeFan = 8;

/// A triangle of the mesh on welded vertices.
struct Face {
  std::array<int, 3> v;        ///< welded vertex ids
  Vec3 normal = Vec3::Zero();  ///< unit, or zero when degenerate
  double area = 0.0;
  int cls = -1;  ///< index into chartDirections()
};

/// Compressed adjacency: the faces sharing an edge with face f are
/// neighbour[offset[f] .. offset[f + 1]), with the shared edge's 3-D length.
struct Adjacency {
  std::vector<int> offset;
  std::vector<int> neighbour;
  std::vector<double> length;
};

/// Joins vertices with identical positions: seams duplicated for the old UVs (the UV sphere's
/// column, a box's corners) must not split charts. Returns the welded id of every vertex and,
/// per welded id, one original vertex. Positions are compared bit for bit, except that -0 and
/// +0 are equal; welded ids follow the order of each position's first vertex.
std::vector<int> weldVertices(const std::vector<Eigen::Vector3f>& vertices,
                              std::vector<int>& representative);

/// Positions of the welded vertices in double: the charts are built on these.
std::vector<Vec3> weldedPositions(const std::vector<Eigen::Vector3f>& vertices,
                                  const std::vector<int>& representative);

/// Faces on welded vertices with their unit normal (from the winding), area and nearest of the
/// 26 directions as class; degenerate faces keep a zero normal, zero area and class -1. Adds up
/// the mesh's area in total_area and throws when every face is degenerate.
std::vector<Face> makeFaces(const std::vector<Eigen::Vector3i>& triangles,
                            const std::vector<int>& welded, const std::vector<Vec3>& positions,
                            const std::array<Vec3, 26>& directions, double& total_area);

/// Which faces share an edge (two welded vertices), with the edge's length. Every pair of faces
/// on an edge is linked, both ways; on an edge of more than kMaxEdgeFan faces (non-manifold)
/// each face is linked to the next one only (still connected, not quadratic). A face is never
/// its own neighbour. Neighbours are listed in the order of their shared edges' vertex ids.
Adjacency buildAdjacency(const std::vector<Face>& faces, const std::vector<Vec3>& positions);

}  // namespace uv_unwrap_detail
}  // namespace norm2tex
