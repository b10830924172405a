#include "norm2tex/mesh/textured_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

// Leaves hold at most this many triangles: small enough that the per-triangle test at a leaf
// stays cheap, large enough that the node array (and the 8-corner test per node) stays small.
constexpr int kMaxLeafTriangles = 4;
// Bins per axis of the binned surface-area heuristic.
constexpr int kSahBins = 12;

float halfArea(const Eigen::AlignedBox3f& box) {
  if (box.isEmpty()) return 0.0f;
  const Eigen::Vector3f d = box.sizes();
  return d.x() * d.y() + d.y() * d.z() + d.z() * d.x();
}

// Float rounding in `pose * p` is a few ulps of |R p| + |t|: growing the mapped boxes by
// kSlack times that keeps every test at least as conservative as exact arithmetic (and as any
// float transform of the vertices a caller may compare against).
constexpr float kSlack = 4e-6f;

float magnitude(const Eigen::AlignedBox3f& box) {
  return std::max(box.min().cwiseAbs().maxCoeff(), box.max().cwiseAbs().maxCoeff());
}

Eigen::AlignedBox3f padded(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, float slack) {
  return Eigen::AlignedBox3f(lo.array() - slack, hi.array() + slack);
}

// AABB, in the gel frame, of `box` mapped by `pose`. |R| * half-extent around the mapped
// centre is exactly the AABB of the 8 mapped corners (Arvo), at a fraction of the cost.
Eigen::AlignedBox3f mappedBox(const Eigen::Isometry3f& pose, float translation_magnitude,
                              const Eigen::AlignedBox3f& box) {
  const Eigen::Vector3f centre = pose * box.center();
  const Eigen::Vector3f half = pose.linear().cwiseAbs() * (0.5f * box.sizes());
  return padded(centre - half, centre + half,
                kSlack * (2.0f * magnitude(box) + translation_magnitude) + 1e-30f);
}

// AABB, in the gel frame, of a triangle's mapped vertices: tighter than mapping its box.
Eigen::AlignedBox3f mappedTriangle(const Eigen::Isometry3f& pose, float translation_magnitude,
                                   const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                                   const Eigen::Vector3f& c) {
  const Eigen::Vector3f pa = pose * a, pb = pose * b, pc = pose * c;
  const float input = a.cwiseAbs().cwiseMax(b.cwiseAbs()).cwiseMax(c.cwiseAbs()).maxCoeff();
  return padded(pa.cwiseMin(pb).cwiseMin(pc), pa.cwiseMax(pb).cwiseMax(pc),
                kSlack * (2.0f * input + translation_magnitude) + 1e-30f);
}

}  // namespace

TexturedMesh::TexturedMesh(std::vector<Eigen::Vector3f> vertices,
                           std::vector<Eigen::Vector3i> triangles, std::vector<Eigen::Vector2f> uvs)
    : vertices_(std::move(vertices)), triangles_(std::move(triangles)), uvs_(std::move(uvs)) {
  if (triangles_.empty()) throw Error("mesh: no triangles");
  if (vertices_.size() > static_cast<size_t>(std::numeric_limits<int>::max())) {
    throw Error("mesh: " + std::to_string(vertices_.size()) + " vertices is more than supported");
  }
  if (triangles_.size() > static_cast<size_t>(std::numeric_limits<int>::max() / 2)) {
    throw Error("mesh: " + std::to_string(triangles_.size()) + " triangles is more than supported");
  }
  if (!uvs_.empty() && uvs_.size() != vertices_.size()) {
    throw Error("mesh: " + std::to_string(uvs_.size()) + " UVs for " +
                std::to_string(vertices_.size()) + " vertices; need none or one per vertex");
  }
  const int vertex_count = static_cast<int>(vertices_.size());
  for (size_t i = 0; i < triangles_.size(); ++i) {
    const Eigen::Vector3i& t = triangles_[i];
    for (int k = 0; k < 3; ++k) {
      if (t[k] < 0 || t[k] >= vertex_count) {
        throw Error("mesh: triangle " + std::to_string(i) + " has vertex index " +
                    std::to_string(t[k]) + "; valid: 0.." + std::to_string(vertex_count - 1));
      }
    }
  }
  bounds_.setEmpty();
  for (size_t i = 0; i < vertices_.size(); ++i) {
    if (!vertices_[i].allFinite()) {
      throw Error("mesh: vertex " + std::to_string(i) + " has a non-finite coordinate");
    }
    bounds_.extend(vertices_[i]);
  }
  for (size_t i = 0; i < uvs_.size(); ++i) {
    if (!uvs_[i].allFinite()) {
      throw Error("mesh: UV " + std::to_string(i) + " is not finite");
    }
  }
  buildBvh();
}

void TexturedMesh::buildBvh() {
  const int n = static_cast<int>(triangles_.size());
  bvh_nodes_.clear();
  bvh_triangles_.resize(n);
  if (n == 0) return;

  std::vector<Eigen::AlignedBox3f> boxes(n);
  std::vector<Eigen::Vector3f> centroids(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3i& t = triangles_[i];
    Eigen::AlignedBox3f box(vertices_[t[0]]);
    box.extend(vertices_[t[1]]).extend(vertices_[t[2]]);
    boxes[i] = box;
    centroids[i] = box.center();
    bvh_triangles_[i] = i;
  }

  // Every leaf holds >= 1 triangle, so the tree has < 2n nodes: no reallocation while building.
  bvh_nodes_.reserve(2 * static_cast<size_t>(n));
  bvh_nodes_.push_back(BvhNode{Eigen::AlignedBox3f(), 0, n});

  // Iterative: the depth of an SAH tree is not bounded by log(n), so no recursion.
  std::vector<int> pending{0};
  struct Bin {
    Eigen::AlignedBox3f box;
    int count = 0;
  };
  std::array<Bin, kSahBins> bins;
  while (!pending.empty()) {
    const int node_index = pending.back();
    pending.pop_back();
    const int first = bvh_nodes_[node_index].first;
    const int count = bvh_nodes_[node_index].count;

    Eigen::AlignedBox3f box, centroid_box;
    for (int i = first; i < first + count; ++i) {
      box.extend(boxes[bvh_triangles_[i]]);
      centroid_box.extend(centroids[bvh_triangles_[i]]);
    }
    bvh_nodes_[node_index].box = box;
    if (count <= kMaxLeafTriangles) continue;

    // Binned SAH over the centroid bounds: pick the axis and bin boundary with the least
    // sum of child half-areas times counts.
    int best_axis = -1, best_split = 0;
    float best_cost = std::numeric_limits<float>::infinity();
    const Eigen::Vector3f extent = centroid_box.sizes();
    for (int axis = 0; axis < 3; ++axis) {
      if (!(extent[axis] > 0.0f)) continue;
      const float to_bin = kSahBins / extent[axis];
      if (!std::isfinite(to_bin)) continue;  // extent so tiny the bins would be degenerate
      for (Bin& bin : bins) bin = Bin{};
      for (int i = first; i < first + count; ++i) {
        const int t = bvh_triangles_[i];
        const int b =
            std::min(kSahBins - 1,
                     static_cast<int>((centroids[t][axis] - centroid_box.min()[axis]) * to_bin));
        bins[b].box.extend(boxes[t]);
        ++bins[b].count;
      }
      // right_area[s]: half-area of bins s..end.
      std::array<float, kSahBins> right_area{};
      std::array<int, kSahBins> right_count{};
      Eigen::AlignedBox3f acc;
      int acc_count = 0;
      for (int b = kSahBins - 1; b > 0; --b) {
        acc.extend(bins[b].box);
        acc_count += bins[b].count;
        right_area[b] = halfArea(acc);
        right_count[b] = acc_count;
      }
      acc.setEmpty();
      acc_count = 0;
      for (int s = 1; s < kSahBins; ++s) {
        acc.extend(bins[s - 1].box);
        acc_count += bins[s - 1].count;
        if (acc_count == 0 || right_count[s] == 0) continue;
        const float cost = halfArea(acc) * acc_count + right_area[s] * right_count[s];
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = axis;
          best_split = s;
        }
      }
    }

    int middle;
    if (best_axis >= 0) {
      const float to_bin = kSahBins / extent[best_axis];
      const float lo = centroid_box.min()[best_axis];
      int* begin = bvh_triangles_.data() + first;
      middle = static_cast<int>(
          std::partition(begin, begin + count,
                         [&](int t) {
                           const int b =
                               std::min(kSahBins - 1,
                                        static_cast<int>((centroids[t][best_axis] - lo) * to_bin));
                           return b < best_split;
                         }) -
          bvh_triangles_.data());
    } else {
      // All centroids coincide: any split is as good as another; halve to bound the depth.
      middle = first + count / 2;
    }
    if (middle <= first || middle >= first + count) middle = first + count / 2;

    const int left = static_cast<int>(bvh_nodes_.size());
    bvh_nodes_[node_index].first = left;
    bvh_nodes_[node_index].count = 0;
    bvh_nodes_.push_back(BvhNode{Eigen::AlignedBox3f(), first, middle - first});
    bvh_nodes_.push_back(BvhNode{Eigen::AlignedBox3f(), middle, first + count - middle});
    pending.push_back(left);
    pending.push_back(left + 1);
  }
  bvh_nodes_.shrink_to_fit();
}

void TexturedMesh::queryTriangles(const Eigen::Isometry3f& object_in_gel,
                                  const Eigen::AlignedBox3f& region, std::vector<int>& out) const {
  if (bvh_nodes_.empty() || region.isEmpty()) return;
  const float translation = object_in_gel.translation().cwiseAbs().maxCoeff();
  std::vector<int> stack;
  stack.reserve(64);
  stack.push_back(0);
  while (!stack.empty()) {
    const BvhNode& node = bvh_nodes_[stack.back()];
    stack.pop_back();
    if (!mappedBox(object_in_gel, translation, node.box).intersects(region)) continue;
    if (node.count == 0) {
      stack.push_back(node.first + 1);
      stack.push_back(node.first);
      continue;
    }
    for (int i = node.first; i < node.first + node.count; ++i) {
      const int t = bvh_triangles_[i];
      const Eigen::Vector3i& tri = triangles_[t];
      if (mappedTriangle(object_in_gel, translation, vertices_[tri[0]], vertices_[tri[1]],
                         vertices_[tri[2]])
              .intersects(region)) {
        out.push_back(t);
      }
    }
  }
}

}  // namespace norm2tex
