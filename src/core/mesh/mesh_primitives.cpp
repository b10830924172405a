#include "norm2tex/mesh/mesh_primitives.hpp"

#include <cmath>

#include <opencv2/core.hpp>

#include "norm2tex/common/error.hpp"

namespace norm2tex {

TexturedMesh makeUvSphere(double radius_m, int rings, int segments) {
  if (!(radius_m > 0.0) || rings < 3 || segments < 3) {
    throw Error("makeUvSphere: need radius > 0, rings >= 3, segments >= 3");
  }
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector2f> uvs;
  std::vector<Eigen::Vector3i> triangles;
  // (rings + 1) x (segments + 1) grid: the seam column is duplicated so UVs do not wrap.
  for (int i = 0; i <= rings; ++i) {
    const double theta = CV_PI * i / rings;  // 0 at the south pole (z = -r)
    for (int j = 0; j <= segments; ++j) {
      const double phi = 2.0 * CV_PI * j / segments;
      vertices.emplace_back(static_cast<float>(radius_m * std::sin(theta) * std::cos(phi)),
                            static_cast<float>(radius_m * std::sin(theta) * std::sin(phi)),
                            static_cast<float>(-radius_m * std::cos(theta)));
      uvs.emplace_back(static_cast<float>(static_cast<double>(j) / segments),
                       static_cast<float>(static_cast<double>(i) / rings));
    }
  }
  const int stride = segments + 1;
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      const int a = i * stride + j, b = a + 1, c = a + stride, d = c + 1;
      if (i != 0) triangles.emplace_back(a, b, d);  // skip the degenerate pole fan
      if (i != rings - 1) triangles.emplace_back(a, d, c);
    }
  }
  return TexturedMesh(std::move(vertices), std::move(triangles), std::move(uvs));
}

TexturedMesh makeBox(const Eigen::Vector3d& size_m, double uv_period_m) {
  if (!(size_m.minCoeff() > 0.0) || uv_period_m < 0.0) {
    throw Error("makeBox: sizes must be > 0 and uv_period_m >= 0");
  }
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector2f> uvs;
  std::vector<Eigen::Vector3i> triangles;
  const Eigen::Vector3d half = 0.5 * size_m;
  for (int axis = 0; axis < 3; ++axis) {
    const int u_axis = (axis + 1) % 3, v_axis = (axis + 2) % 3;
    for (const double sign : {-1.0, 1.0}) {
      const int base = static_cast<int>(vertices.size());
      for (int corner = 0; corner < 4; ++corner) {
        const double su = (corner == 1 || corner == 2) ? 1.0 : -1.0;
        const double sv = (corner >= 2) ? 1.0 : -1.0;
        Eigen::Vector3d p;
        p[axis] = sign * half[axis];
        p[u_axis] = su * half[u_axis];
        p[v_axis] = sv * half[v_axis];
        vertices.push_back(p.cast<float>());
        const double pu = uv_period_m > 0.0 ? uv_period_m : size_m[u_axis];
        const double pv = uv_period_m > 0.0 ? uv_period_m : size_m[v_axis];
        uvs.emplace_back(static_cast<float>((p[u_axis] + half[u_axis]) / pu),
                         static_cast<float>((p[v_axis] + half[v_axis]) / pv));
      }
      // Outward winding; the rasterizer does not cull back faces, but keep meshes well-formed.
      if (sign > 0) {
        triangles.emplace_back(base, base + 1, base + 2);
        triangles.emplace_back(base, base + 2, base + 3);
      } else {
        triangles.emplace_back(base, base + 2, base + 1);
        triangles.emplace_back(base, base + 3, base + 2);
      }
    }
  }
  return TexturedMesh(std::move(vertices), std::move(triangles), std::move(uvs));
}

}  // namespace norm2tex
