#pragma once
// unwrapUvs' geometry helpers: the vector types of the unwrap, the projection basis of a chart
// and the 2-D tests on projected triangles (overlap, convex hull, a grid of accepted triangles).
// Private to the core (src/core/mesh/); the steps of unwrapUvs are in uv_adjacency.hpp,
// uv_charts.hpp and uv_packing.hpp.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace norm2tex {
namespace uv_unwrap_detail {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;

constexpr double kPi = 3.14159265358979323846;

/// The orthonormal basis (e1, e2) with e1 x e2 = d: a surface seen from the side
/// its normal points to keeps u to the right and v up (no mirroring).
void projectionBasis(const Vec3& d, Vec3& e1, Vec3& e2);

/// The z component of the 3-D cross product of (a, 0) and (b, 0): twice the signed area of the
/// triangle (0, a, b), positive when b lies counter-clockwise of a.
inline double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

/// True when the interiors of two 2-D triangles overlap by more than eps (separating axis test
/// over the six edge normals; touching along an edge or at a corner is no overlap).
/// Inline: the splitting of a chart calls it for every pair of nearby triangles.
inline bool interiorsOverlap(const std::array<Vec2, 3>& a, const std::array<Vec2, 3>& b,
                             double eps) {
  for (const std::array<Vec2, 3>* t : {&a, &b}) {
    for (int k = 0; k < 3; ++k) {
      const Vec2 edge = (*t)[(k + 1) % 3] - (*t)[k];
      const double length = edge.norm();
      if (!(length > 0.0)) continue;
      const Vec2 axis(-edge.y() / length, edge.x() / length);
      double min_a = std::numeric_limits<double>::infinity(), max_a = -min_a;
      double min_b = min_a, max_b = -min_a;
      for (int i = 0; i < 3; ++i) {
        const double pa = axis.dot(a[i]), pb = axis.dot(b[i]);
        min_a = std::min(min_a, pa);
        max_a = std::max(max_a, pa);
        min_b = std::min(min_b, pb);
        max_b = std::max(max_b, pb);
      }
      if (max_a <= min_b + eps || max_b <= min_a + eps) return false;
    }
  }
  return true;
}

/// Convex hull (Andrew's monotone chain), counter-clockwise, no repeated end point. Fewer than
/// three distinct points come back sorted (by x, then y), duplicates removed.
std::vector<Vec2> convexHull(std::vector<Vec2> points);

/// Uniform grid of accepted 2-D triangles for the overlap test; linked lists in flat arrays.
/// Items are stored by their bounding box in every cell it touches, so a query may visit an
/// item more than once. Defined here, inline, because it is queried once per face.
class TriangleGrid {
 public:
  /// A grid over the box [min, max] for about `triangle_count` triangles: at most 2048 x 2048
  /// cells; boxes outside the grid are clamped to its border cells.
  TriangleGrid(const Vec2& min, const Vec2& max, size_t triangle_count) : min_(min) {
    const Vec2 extent = (max - min).cwiseMax(1e-300);
    // About one triangle per cell for a chart that fills its bounding box.
    double cell = std::sqrt(extent.x() * extent.y() / std::max<size_t>(triangle_count, 1));
    cell = std::max({cell, extent.x() / 2048.0, extent.y() / 2048.0});
    if (!(cell > 0.0)) cell = 1.0;
    inverse_cell_ = 1.0 / cell;
    nx_ = std::clamp(static_cast<int>(extent.x() * inverse_cell_) + 1, 1, 2048);
    ny_ = std::clamp(static_cast<int>(extent.y() * inverse_cell_) + 1, 1, 2048);
    head_.assign(static_cast<size_t>(nx_) * ny_, -1);
  }

  /// Removes every item, touching only the cells that hold one (the grid is reused per piece).
  void clear() {
    for (int cell : touched_) head_[cell] = -1;
    touched_.clear();
    next_.clear();
    item_.clear();
  }

  /// Calls visit(item) for the items in the cells the box [lo, hi] touches until one call
  /// returns true; returns whether one did.
  template <typename Visit>
  bool anyInBox(const Vec2& lo, const Vec2& hi, Visit visit) const {
    int x0, y0, x1, y1;
    cells(lo, hi, x0, y0, x1, y1);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        for (int e = head_[static_cast<size_t>(y) * nx_ + x]; e >= 0; e = next_[e]) {
          if (visit(item_[e])) return true;
        }
      }
    }
    return false;
  }

  /// Adds `item` to every cell the box [lo, hi] touches.
  void insert(const Vec2& lo, const Vec2& hi, int item) {
    int x0, y0, x1, y1;
    cells(lo, hi, x0, y0, x1, y1);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const int cell = y * nx_ + x;
        if (head_[cell] < 0) touched_.push_back(cell);
        next_.push_back(head_[cell]);
        item_.push_back(item);
        head_[cell] = static_cast<int>(item_.size()) - 1;
      }
    }
  }

 private:
  // The cell range [x0, x1] x [y0, y1] of the box [lo, hi], clamped to the grid.
  void cells(const Vec2& lo, const Vec2& hi, int& x0, int& y0, int& x1, int& y1) const {
    auto index = [&](double value, double origin, int count) {
      return std::clamp(static_cast<int>(std::floor((value - origin) * inverse_cell_)), 0,
                        count - 1);
    };
    x0 = index(lo.x(), min_.x(), nx_);
    x1 = index(hi.x(), min_.x(), nx_);
    y0 = index(lo.y(), min_.y(), ny_);
    y1 = index(hi.y(), min_.y(), ny_);
  }

  Vec2 min_;
  double inverse_cell_ = 1.0;
  int nx_ = 1, ny_ = 1;
  std::vector<int> head_, next_, item_, touched_;
};

}  // namespace uv_unwrap_detail
}  // namespace norm2tex
