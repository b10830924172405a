// computeUvLayout (UV islands rasterised at a texture's size) and padIslands (bleeding guard).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>
#include <string>
#include <tuple>
#include <vector>

#include "common/error_messages.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/huge_pages.hpp"
#include "norm2tex/mesh/uv_unwrap.hpp"

namespace norm2tex {
namespace {

uint64_t uvKey(const Eigen::Vector2f& uv) {
  float u = uv.x() + 0.0f, v = uv.y() + 0.0f;  // -0 -> +0: the same UV
  uint32_t bu, bv;
  std::memcpy(&bu, &u, sizeof bu);
  std::memcpy(&bv, &v, sizeof bv);
  return (static_cast<uint64_t>(bu) << 32) | bv;
}

int findRoot(std::vector<int>& parent, int i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

int64_t wrapIndex(int64_t index, int64_t size) {
  const int64_t m = index % size;
  return m < 0 ? m + size : m;
}

}  // namespace

UvLayout computeUvLayout(const TexturedMesh& mesh, cv::Size size) {
  const std::string what = mesh.sourcePath().empty()
                               ? "computeUvLayout"
                               : "computeUvLayout('" + mesh.sourcePath() + "')";
  if (!mesh.hasUvs()) throw Error(what + ": the mesh has no UVs");
  if (size.width <= 0 || size.height <= 0) {
    throw Error(what + ": size " + std::to_string(size.width) + " x " +
                std::to_string(size.height) + " is out of range; valid: both > 0");
  }
  const std::vector<Eigen::Vector3i>& triangles = mesh.triangles();
  const std::vector<Eigen::Vector3f>& vertices = mesh.vertices();
  const std::vector<Eigen::Vector2f>& uvs = mesh.uvs();
  const int triangle_count = static_cast<int>(triangles.size());

  // Islands: triangles joined through edges with the same two UVs (bit-exact).
  std::vector<std::tuple<uint64_t, uint64_t, int>> edges;
  edges.reserve(3 * triangles.size());
  for (int t = 0; t < triangle_count; ++t) {
    for (int k = 0; k < 3; ++k) {
      const uint64_t a = uvKey(uvs[triangles[t][k]]), b = uvKey(uvs[triangles[t][(k + 1) % 3]]);
      if (a != b) edges.emplace_back(std::min(a, b), std::max(a, b), t);
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<int> parent(triangle_count);
  std::iota(parent.begin(), parent.end(), 0);
  for (size_t i = 1; i < edges.size(); ++i) {
    if (std::get<0>(edges[i]) == std::get<0>(edges[i - 1]) &&
        std::get<1>(edges[i]) == std::get<1>(edges[i - 1])) {
      const int a = findRoot(parent, std::get<2>(edges[i]));
      const int b = findRoot(parent, std::get<2>(edges[i - 1]));
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  std::vector<int> island_of(triangle_count);
  std::vector<int> id_of_root(triangle_count, 0);
  int island_count = 0;
  for (int t = 0; t < triangle_count; ++t) {
    const int root = findRoot(parent, t);
    if (id_of_root[root] == 0) id_of_root[root] = ++island_count;
    island_of[t] = id_of_root[root];
  }

  // Scale per island from the summed areas.
  std::vector<double> area_3d(island_count + 1, 0.0), area_uv(island_count + 1, 0.0);
  for (int t = 0; t < triangle_count; ++t) {
    const Eigen::Vector3d a = vertices[triangles[t][0]].cast<double>();
    const Eigen::Vector3d b = vertices[triangles[t][1]].cast<double>();
    const Eigen::Vector3d c = vertices[triangles[t][2]].cast<double>();
    const Eigen::Vector2d ua = uvs[triangles[t][0]].cast<double>();
    const Eigen::Vector2d ub = uvs[triangles[t][1]].cast<double>();
    const Eigen::Vector2d uc = uvs[triangles[t][2]].cast<double>();
    area_3d[island_of[t]] += 0.5 * (b - a).cross(c - a).norm();
    const Eigen::Vector2d e1 = ub - ua, e2 = uc - ua;
    area_uv[island_of[t]] += 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
  }
  UvLayout layout;
  layout.metres_per_uv.assign(island_count + 1, 0.0);
  for (int i = 1; i <= island_count; ++i) {
    if (area_uv[i] > 0.0) layout.metres_per_uv[i] = std::sqrt(area_3d[i] / area_uv[i]);
  }

  // Rasterise: texel-space x = u W, y = (1 - v) H, centres at half-integers. Per row, the span
  // between the edges' crossings; an edge's crossing is computed from its endpoints in a fixed
  // order, so two triangles sharing the edge get the same bits and no centre falls between.
  const int W = size.width, H = size.height;
  createWithHugePages(layout.island, H, W);  // 16 MB at 2048^2: see huge_pages.hpp
  layout.island.setTo(0);
  std::vector<int> unclaimed_in_row(H, W);
  int64_t unclaimed = static_cast<int64_t>(W) * H;
  for (int t = 0; t < triangle_count && unclaimed > 0; ++t) {
    std::array<Eigen::Vector2d, 3> p;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2f& uv = uvs[triangles[t][k]];
      p[k] = Eigen::Vector2d(static_cast<double>(uv.x()) * W, (1.0 - uv.y()) * H);
    }
    const double y_min = std::min({p[0].y(), p[1].y(), p[2].y()});
    const double y_max = std::max({p[0].y(), p[1].y(), p[2].y()});
    const int64_t r0 = static_cast<int64_t>(std::ceil(y_min - 0.5));
    const int64_t r1 = static_cast<int64_t>(std::floor(y_max - 0.5));
    std::array<std::array<Eigen::Vector2d, 2>, 3> edge;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector2d a = p[k], b = p[(k + 1) % 3];
      if (b.y() < a.y() || (b.y() == a.y() && b.x() < a.x())) std::swap(a, b);
      edge[k] = {a, b};
    }
    const int id = island_of[t];
    for (int64_t r = r0; r <= r1; ++r) {
      const int row = static_cast<int>(wrapIndex(r, H));
      if (unclaimed_in_row[row] == 0) continue;
      const double y = static_cast<double>(r) + 0.5;
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (const auto& [a, b] : edge) {
        if (y < a.y() || y > b.y()) continue;
        if (a.y() == b.y()) {
          lo = std::min({lo, a.x(), b.x()});
          hi = std::max({hi, a.x(), b.x()});
        } else {
          const double x = a.x() + (y - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
          lo = std::min(lo, x);
          hi = std::max(hi, x);
        }
      }
      if (!(lo <= hi)) continue;
      int64_t c0 = static_cast<int64_t>(std::ceil(lo - 0.5));
      int64_t c1 = static_cast<int64_t>(std::floor(hi - 0.5));
      if (c1 < c0) continue;
      if (c1 - c0 + 1 >= W) {
        c0 = 0;
        c1 = W - 1;
      }
      int* out = layout.island.ptr<int>(row);
      for (int64_t c = c0; c <= c1; ++c) {
        int& texel = out[wrapIndex(c, W)];
        if (texel == 0) {
          texel = id;
          --unclaimed_in_row[row];
          --unclaimed;
        }
      }
    }
  }
  return layout;
}

cv::Mat1i padIslands(cv::Mat& image, const cv::Mat1i& island, int texels) {
  if (island.empty()) throw Error("padIslands: the island map is empty");
  if (image.size() != island.size()) {
    throw Error("padIslands: image " + std::to_string(image.cols) + " x " +
                std::to_string(image.rows) + " does not match the island map " +
                std::to_string(island.cols) + " x " + std::to_string(island.rows));
  }
  detail::requireParameter(texels >= 0, "padIslands: texels", texels, ">= 0");
  cv::Mat1i grown = island.clone();
  const int rows = island.rows, cols = island.cols;
  // A layout that covers every texel (a tiling texture) has nothing to pad.
  bool any_empty = false;
  for (int r = 0; r < rows && !any_empty; ++r) {
    const int* in = island.ptr<int>(r);
    any_empty = std::find(in, in + cols, 0) != in + cols;
  }
  if (texels == 0 || !any_empty) return grown;
  const int64_t limit = static_cast<int64_t>(texels) * texels;

  // Exact Euclidean nearest island texel within `texels`: per row the nearest island column
  // (dx <= texels), then per column the lower envelope of the parabolas dx^2 + (row - q)^2
  // (Felzenszwalb & Huttenlocher), keeping which row q is the minimum.
  cv::Mat1i nearest_column(rows, cols, -1);
  for (int r = 0; r < rows; ++r) {
    const int* in = island.ptr<int>(r);
    int* out = nearest_column.ptr<int>(r);
    int last = std::numeric_limits<int>::min() / 2;
    for (int c = 0; c < cols; ++c) {
      if (in[c] != 0) last = c;
      if (static_cast<int64_t>(c) - last <= texels) out[c] = last;
    }
    last = std::numeric_limits<int>::max() / 2;
    for (int c = cols - 1; c >= 0; --c) {
      if (in[c] != 0) last = c;
      if (static_cast<int64_t>(last) - c <= texels && (out[c] < 0 || last - c < c - out[c])) {
        out[c] = last;
      }
    }
  }
  const size_t element = image.elemSize();
  std::vector<int> hull_row(rows);
  std::vector<double> boundary(rows + 1);
  std::vector<int64_t> cost(rows);
  for (int c = 0; c < cols; ++c) {
    int k = -1;
    for (int q = 0; q < rows; ++q) {
      const int site = nearest_column(q, c);
      if (site < 0) continue;
      cost[q] = static_cast<int64_t>(c - site) * (c - site);
      const double fq = static_cast<double>(cost[q]) + static_cast<double>(q) * q;
      while (k >= 0) {
        const int v = hull_row[k];
        const double fv = static_cast<double>(cost[v]) + static_cast<double>(v) * v;
        const double s = (fq - fv) / (2.0 * (q - v));
        if (s <= boundary[k]) {
          --k;
        } else {
          hull_row[++k] = q;
          boundary[k] = s;
          break;
        }
      }
      if (k < 0) {
        k = 0;
        hull_row[0] = q;
        boundary[0] = -std::numeric_limits<double>::infinity();
      }
    }
    if (k < 0) continue;  // no island within reach of this column
    const int last = k;
    k = 0;
    for (int p = 0; p < rows; ++p) {
      while (k < last && boundary[k + 1] < p) ++k;
      if (island(p, c) != 0) continue;
      const int q = hull_row[k];
      const int64_t d2 = cost[q] + static_cast<int64_t>(p - q) * (p - q);
      if (d2 > limit) continue;
      const int site = nearest_column(q, c);
      std::memcpy(image.ptr(p) + element * c, image.ptr(q) + element * site, element);
      grown(p, c) = island(q, site);
    }
  }
  return grown;
}

}  // namespace norm2tex
