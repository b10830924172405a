// unwrapUvs' geometry helpers (see uv_geometry.hpp).
#include "mesh/uv_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace norm2tex {
namespace uv_unwrap_detail {

void projectionBasis(const Vec3& d, Vec3& e1, Vec3& e2) {
  const Vec3 a = std::abs(d.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  e1 = (a - a.dot(d) * d).normalized();
  e2 = d.cross(e1);
}

std::vector<Vec2> convexHull(std::vector<Vec2> points) {
  std::sort(points.begin(), points.end(), [](const Vec2& a, const Vec2& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  points.erase(std::unique(points.begin(), points.end()), points.end());
  if (points.size() < 3) return points;
  std::vector<Vec2> hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross2(hull[k - 1] - hull[k - 2], points[i] - hull[k - 2]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross2(hull[k - 1] - hull[k - 2], points[i] - hull[k - 2]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

}  // namespace uv_unwrap_detail
}  // namespace norm2tex
