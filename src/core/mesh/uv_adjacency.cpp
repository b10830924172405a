// unwrapUvs' faces, welding and adjacency (see uv_adjacency.hpp).
#include "mesh/uv_adjacency.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <string>
#include <unordered_map>
#include <utility>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace uv_unwrap_detail {
namespace {

// A face whose |cross product| is below this times its longest edge squared has no usable
// normal (all three corners on a line, up to double rounding of exact float inputs).
constexpr double kDegenerateSine = 1e-10;

// A position's float bits (-0 read as +0), the welding's hash key.
struct PositionKey {
  uint32_t x, y, z;
  bool operator==(const PositionKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct PositionKeyHash {
  size_t operator()(const PositionKey& k) const {
    uint64_t h = k.x * 0x9E3779B97F4A7C15ull;
    h ^= (k.y + 0x7F4A7C15ull + (h << 6) + (h >> 2)) * 0xBF58476D1CE4E5B9ull;
    h ^= (k.z + 0x94D049BBull + (h << 6) + (h >> 2)) * 0x94D049BB133111EBull;
    return static_cast<size_t>(h ^ (h >> 31));
  }
};

uint32_t floatBits(float f) {
  f += 0.0f;  // -0 -> +0: the same position
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  return bits;
}

}  // namespace

std::vector<int> weldVertices(const std::vector<Eigen::Vector3f>& vertices,
                              std::vector<int>& representative) {
  std::unordered_map<PositionKey, int, PositionKeyHash> ids;
  ids.reserve(vertices.size());
  std::vector<int> welded(vertices.size());
  representative.clear();
  for (size_t i = 0; i < vertices.size(); ++i) {
    const Eigen::Vector3f& p = vertices[i];
    const auto inserted =
        ids.emplace(PositionKey{floatBits(p.x()), floatBits(p.y()), floatBits(p.z())},
                    static_cast<int>(representative.size()));
    if (inserted.second) representative.push_back(static_cast<int>(i));
    welded[i] = inserted.first->second;
  }
  return welded;
}

std::vector<Vec3> weldedPositions(const std::vector<Eigen::Vector3f>& vertices,
                                  const std::vector<int>& representative) {
  std::vector<Vec3> positions(representative.size());
  for (size_t i = 0; i < representative.size(); ++i) {
    positions[i] = vertices[representative[i]].cast<double>();
  }
  return positions;
}

std::vector<Face> makeFaces(const std::vector<Eigen::Vector3i>& triangles,
                            const std::vector<int>& welded, const std::vector<Vec3>& positions,
                            const std::array<Vec3, 26>& directions, double& total_area) {
  const int face_count = static_cast<int>(triangles.size());
  std::vector<Face> faces(face_count);
  total_area = 0.0;
  for (int f = 0; f < face_count; ++f) {
    Face& face = faces[f];
    for (int k = 0; k < 3; ++k) face.v[k] = welded[triangles[f][k]];
    const Vec3& a = positions[face.v[0]];
    const Vec3& b = positions[face.v[1]];
    const Vec3& c = positions[face.v[2]];
    const Vec3 cross = (b - a).cross(c - a);
    const double longest =
        std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    const double norm = cross.norm();
    if (!(norm > kDegenerateSine * longest) || !(norm > 0.0)) continue;
    face.normal = cross / norm;
    face.area = 0.5 * norm;
    total_area += face.area;
    double best = -2.0;
    for (int d = 0; d < 26; ++d) {
      const double dot = face.normal.dot(directions[d]);
      if (dot > best) {
        best = dot;
        face.cls = d;
      }
    }
  }
  if (!(total_area > 0.0)) {
    throw Error("unwrapUvs: all " + std::to_string(face_count) +
                " triangles of the mesh are degenerate (zero area)");
  }
  return faces;
}

Adjacency buildAdjacency(const std::vector<Face>& faces, const std::vector<Vec3>& positions) {
  std::vector<std::pair<uint64_t, int>> edges;
  edges.reserve(3 * faces.size());
  for (size_t f = 0; f < faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = faces[f].v[k], b = faces[f].v[(k + 1) % 3];
      if (a == b) continue;
      const uint64_t key = (static_cast<uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
      edges.emplace_back(key, static_cast<int>(f));
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<std::array<int, 2>> pairs;
  std::vector<double> pair_length;
  for (size_t i = 0; i < edges.size();) {
    size_t j = i + 1;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    const int a = static_cast<int>(edges[i].first >> 32);
    const int b = static_cast<int>(edges[i].first & 0xFFFFFFFFu);
    const double length = (positions[a] - positions[b]).norm();
    const size_t fan = j - i;
    for (size_t p = i; p < j; ++p) {
      // All pairs for ordinary edges; a chain for large non-manifold fans (still connected).
      const size_t last = fan <= static_cast<size_t>(kMaxEdgeFan) ? j : std::min(j, p + 2);
      for (size_t q = p + 1; q < last; ++q) {
        if (edges[p].second == edges[q].second) continue;  // a face folded onto itself
        pairs.push_back({edges[p].second, edges[q].second});
        pair_length.push_back(length);
      }
    }
    i = j;
  }
  Adjacency adjacency;
  adjacency.offset.assign(faces.size() + 1, 0);
  for (const auto& p : pairs) {
    ++adjacency.offset[p[0] + 1];
    ++adjacency.offset[p[1] + 1];
  }
  std::partial_sum(adjacency.offset.begin(), adjacency.offset.end(), adjacency.offset.begin());
  adjacency.neighbour.resize(2 * pairs.size());
  adjacency.length.resize(2 * pairs.size());
  std::vector<int> fill(adjacency.offset.begin(), adjacency.offset.end() - 1);
  for (size_t i = 0; i < pairs.size(); ++i) {
    for (int s = 0; s < 2; ++s) {
      const int slot = fill[pairs[i][s]]++;
      adjacency.neighbour[slot] = pairs[i][1 - s];
      adjacency.length[slot] = pair_length[i];
    }
  }
  return adjacency;
}

}  // namespace uv_unwrap_detail
}  // namespace norm2tex
