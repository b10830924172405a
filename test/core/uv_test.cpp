// UV tools: unwrapUvs (no overlap, padding, uniform scale, geometry kept), computeUvLayout
// (islands, scale per island), padIslands (nearest-texel growth) and saveMesh round trips.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/mesh/uv_unwrap.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

using test::expectError;

namespace fs = std::filesystem;

constexpr double kPi = 3.14159265358979323846;

// Bound on a clean curved surface: a face at angle t to its chart's direction has 3-D / UV
// length ratios in [1, 1/cos t] * metres_per_uv, and every normal is within 27.6 deg of one of
// the 26 directions: ratio <= 1.13 (measured max: 1.117 on this sphere, 1.123 on the torus).
// Smoothing (<= 40 deg) and merged fragments (<= 60 deg) only happen on noisy or jagged meshes.
const double kCleanCurvedBound = 1.0 / std::cos(27.6 * kPi / 180.0) + 0.005;

TexturedMesh withoutUvs(const TexturedMesh& mesh) {
  return TexturedMesh(mesh.vertices(), mesh.triangles());
}

// Torus around z; (i, j) grid closed in both directions (shared vertices, no seams).
TexturedMesh makeTorus(double major, double minor, int nu, int nv) {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      const double a = 2 * kPi * i / nu, b = 2 * kPi * j / nv;
      vertices.emplace_back((major + minor * std::cos(b)) * std::cos(a),
                            (major + minor * std::cos(b)) * std::sin(a), minor * std::sin(b));
    }
  }
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      const int a = i * nv + j, b = ((i + 1) % nu) * nv + j;
      const int c = ((i + 1) % nu) * nv + (j + 1) % nv, d = i * nv + (j + 1) % nv;
      triangles.emplace_back(a, b, c);
      triangles.emplace_back(a, c, d);
    }
  }
  return TexturedMesh(vertices, triangles);
}

// A prism over a counter-clockwise outline (metres) triangulated by `cap`, `height` high,
// outward winding, turned by `rotation`.
TexturedMesh makePrism(const std::vector<Eigen::Vector2f>& outline,
                       const std::vector<Eigen::Vector3i>& cap, float height,
                       const Eigen::Matrix3f& rotation) {
  const int n = static_cast<int>(outline.size());
  std::vector<Eigen::Vector3f> vertices;
  for (float z : {0.0f, height}) {
    for (const Eigen::Vector2f& p : outline) {
      vertices.push_back(rotation * Eigen::Vector3f(p.x(), p.y(), z));
    }
  }
  std::vector<Eigen::Vector3i> triangles;
  for (const Eigen::Vector3i& t : cap) {
    triangles.emplace_back(t[0], t[2], t[1]);              // bottom, facing -z
    triangles.emplace_back(t[0] + n, t[1] + n, t[2] + n);  // top, facing +z
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    triangles.emplace_back(i, j, j + n);
    triangles.emplace_back(i, j + n, i + n);
  }
  return TexturedMesh(vertices, triangles);
}

// An L-shaped prism: outer 20 x 15 mm, arms 6 mm thick, 8 mm high; the cap is fanned from the
// inner corner (3) in convex pieces.
TexturedMesh makeLPrism(const Eigen::Matrix3f& rotation = Eigen::Matrix3f::Identity()) {
  return makePrism(
      {{0, 0}, {0.02f, 0}, {0.02f, 0.006f}, {0.006f, 0.006f}, {0.006f, 0.015f}, {0, 0.015f}},
      {{3, 0, 1}, {3, 1, 2}, {3, 4, 5}, {3, 5, 0}}, 0.008f, rotation);
}

// Charts of an unwrapped mesh as the test sees them: triangles joined through shared vertex
// indices (unwrapUvs shares vertices only inside a chart).
std::vector<int> chartsByVertex(const TexturedMesh& mesh, int* count) {
  std::vector<int> parent(mesh.vertices().size());
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (const Eigen::Vector3i& t : mesh.triangles()) {
    parent[root(t[1])] = root(t[0]);
    parent[root(t[2])] = root(t[0]);
  }
  std::map<int, int> ids;
  std::vector<int> chart(mesh.triangles().size());
  for (size_t t = 0; t < chart.size(); ++t) {
    const int r = root(mesh.triangles()[t][0]);
    chart[t] = ids.emplace(r, static_cast<int>(ids.size()) + 1).first->second;
  }
  *count = static_cast<int>(ids.size());
  return chart;
}

// Rasterises every triangle at size x size (texel centres, inclusive edges) into a chart-id
// image; counts texels claimed by two different charts.
cv::Mat1i rasteriseCharts(const TexturedMesh& mesh, const std::vector<int>& chart, int size,
                          int* conflicts) {
  cv::Mat1i image(size, size, 0);
  *conflicts = 0;
  for (size_t t = 0; t < mesh.triangles().size(); ++t) {
    std::array<Eigen::Vector2d, 3> p;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2f& uv = mesh.uvs()[mesh.triangles()[t][k]];
      p[k] = Eigen::Vector2d(uv.x() * size, (1.0 - uv.y()) * size);
    }
    const double area =
        (p[1] - p[0]).x() * (p[2] - p[0]).y() - (p[1] - p[0]).y() * (p[2] - p[0]).x();
    if (std::abs(area) < 1e-12) continue;
    const int c0 =
        std::max(0, static_cast<int>(std::floor(std::min({p[0].x(), p[1].x(), p[2].x()}))));
    const int c1 =
        std::min(size - 1, static_cast<int>(std::ceil(std::max({p[0].x(), p[1].x(), p[2].x()}))));
    const int r0 =
        std::max(0, static_cast<int>(std::floor(std::min({p[0].y(), p[1].y(), p[2].y()}))));
    const int r1 =
        std::min(size - 1, static_cast<int>(std::ceil(std::max({p[0].y(), p[1].y(), p[2].y()}))));
    for (int r = r0; r <= r1; ++r) {
      for (int c = c0; c <= c1; ++c) {
        const Eigen::Vector2d q(c + 0.5, r + 0.5);
        bool inside = true;
        for (int k = 0; k < 3 && inside; ++k) {
          const Eigen::Vector2d e = p[(k + 1) % 3] - p[k], d = q - p[k];
          inside = (e.x() * d.y() - e.y() * d.x()) * area >= -1e-9 * std::abs(area);
        }
        if (!inside) continue;
        int& texel = image(r, c);
        if (texel != 0 && texel != chart[t]) ++*conflicts;
        texel = chart[t];
      }
    }
  }
  return image;
}

struct AtlasCheck {
  int charts = 0;
  double min_ratio = std::numeric_limits<double>::infinity();  // (3-D / UV length) / mpu
  double max_ratio = 0.0;
  double area_above = 0.0;  // 3-D area of triangles with an edge ratio above `bound`
  double area = 0.0;
};

// Everything unwrapUvs promises about its atlas, for any mesh; returns the scale statistics.
AtlasCheck checkAtlas(const TexturedMesh& input, const UnwrapResult& result, int size, int padding,
                      double bound = 1.01) {
  AtlasCheck check;
  const TexturedMesh& mesh = result.mesh;
  EXPECT_TRUE(mesh.hasUvs());
  EXPECT_GT(result.metres_per_uv, 0.0);
  // Geometry: triangle i is input triangle i, corner for corner.
  EXPECT_EQ(mesh.triangles().size(), input.triangles().size());
  for (size_t t = 0; t < std::min(mesh.triangles().size(), input.triangles().size()); ++t) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(mesh.vertices()[mesh.triangles()[t][k]], input.vertices()[input.triangles()[t][k]])
          << "triangle " << t;
    }
  }
  for (const Eigen::Vector2f& uv : mesh.uvs()) {
    EXPECT_TRUE(uv.x() >= 0.0f && uv.x() <= 1.0f && uv.y() >= 0.0f && uv.y() <= 1.0f)
        << uv.transpose();
  }
  const std::vector<int> chart = chartsByVertex(mesh, &check.charts);
  EXPECT_EQ(check.charts, result.chart_count);

  // No texel claimed by two charts; none within `padding` texels of another chart or of the
  // border (Chebyshev distance: a square dilation).
  int conflicts = 0;
  const cv::Mat1i image = rasteriseCharts(mesh, chart, size, &conflicts);
  EXPECT_EQ(conflicts, 0);
  int too_close = 0, at_border = 0;
  for (int r = 0; r < size; ++r) {
    for (int c = 0; c < size; ++c) {
      const int a = image(r, c);
      if (a == 0) continue;
      if (r < padding || c < padding || r >= size - padding || c >= size - padding) ++at_border;
      for (int y = std::max(0, r - padding); y <= std::min(size - 1, r + padding); ++y) {
        for (int x = std::max(0, c - padding); x <= std::min(size - 1, c + padding); ++x) {
          if (image(y, x) != 0 && image(y, x) != a) ++too_close;
        }
      }
    }
  }
  EXPECT_EQ(too_close, 0);
  EXPECT_EQ(at_border, 0);

  // Orientation: UVs keep the winding (no mirrored charts, so tangent frames stay
  // right-handed); the projection direction is within 90 deg of every face's normal.
  int mirrored = 0;
  for (const Eigen::Vector3i& t : mesh.triangles()) {
    const Eigen::Vector2d e1 = (mesh.uvs()[t[1]] - mesh.uvs()[t[0]]).cast<double>();
    const Eigen::Vector2d e2 = (mesh.uvs()[t[2]] - mesh.uvs()[t[0]]).cast<double>();
    const double area_3d = (mesh.vertices()[t[1]] - mesh.vertices()[t[0]])
                               .cross(mesh.vertices()[t[2]] - mesh.vertices()[t[0]])
                               .norm();
    if (area_3d > 1e-12 && e1.x() * e2.y() - e1.y() * e2.x() <= 0.0) ++mirrored;
  }
  EXPECT_EQ(mirrored, 0);

  // Scale: every edge's 3-D / UV length ratio in [1, bound] * metres_per_uv (projection only
  // shortens).
  for (const Eigen::Vector3i& t : mesh.triangles()) {
    const Eigen::Vector3d a = mesh.vertices()[t[0]].cast<double>();
    const Eigen::Vector3d b = mesh.vertices()[t[1]].cast<double>();
    const Eigen::Vector3d c = mesh.vertices()[t[2]].cast<double>();
    const double area = 0.5 * (b - a).cross(c - a).norm();
    check.area += area;
    bool above = false;
    for (int k = 0; k < 3; ++k) {
      const double length =
          (mesh.vertices()[t[(k + 1) % 3]] - mesh.vertices()[t[k]]).cast<double>().norm();
      const double uv_length =
          (mesh.uvs()[t[(k + 1) % 3]] - mesh.uvs()[t[k]]).cast<double>().norm();
      if (length < 1e-5) continue;  // float UV rounding dominates on tiny edges
      const double ratio = length / uv_length / result.metres_per_uv;
      check.min_ratio = std::min(check.min_ratio, ratio);
      check.max_ratio = std::max(check.max_ratio, ratio);
      above = above || ratio > bound;
    }
    if (above) check.area_above += area;
  }
  EXPECT_GE(check.min_ratio, 0.99);
  return check;
}

TEST(UnwrapUvs, BoxGetsSixUndistortedChartsWithoutOverlap) {
  const TexturedMesh box = makeBox(Eigen::Vector3d(0.02, 0.01, 0.005));
  UnwrapOptions options;
  options.texture_size = 512;
  options.padding_texels = 4;
  const UnwrapResult result = unwrapUvs(box, options);
  EXPECT_EQ(result.chart_count, 6);
  const AtlasCheck check = checkAtlas(box, result, 512, 4);
  EXPECT_LE(check.max_ratio, 1.01);
  EXPECT_EQ(check.area_above, 0.0);
  // The atlas is not wasteful: the 700 mm^2 of faces cover more than half of the texture.
  const double covered = check.area / std::pow(result.metres_per_uv, 2);
  EXPECT_GT(covered, 0.5);
}

TEST(UnwrapUvs, TurnedLPrismKeepsPlanarFacesUndistorted) {
  // Turned so no face is axis-aligned: planar charts are projected onto their own plane.
  const Eigen::Matrix3f rotation = (Eigen::AngleAxisf(0.4f, Eigen::Vector3f::UnitX()) *
                                    Eigen::AngleAxisf(-0.7f, Eigen::Vector3f(0, 1, 1).normalized()))
                                       .toRotationMatrix();
  for (const Eigen::Matrix3f& r : {Eigen::Matrix3f(Eigen::Matrix3f::Identity()), rotation}) {
    const TexturedMesh prism = makeLPrism(r);
    UnwrapOptions options;
    options.texture_size = 256;
    options.padding_texels = 3;
    const UnwrapResult result = unwrapUvs(prism, options);
    EXPECT_EQ(result.chart_count, 8);  // 2 caps, 6 sides (the two +x sides are apart)
    const AtlasCheck check = checkAtlas(prism, result, 256, 3);
    EXPECT_LE(check.max_ratio, 1.01);
  }
}

TEST(UnwrapUvs, ChamferKeepsItsOwnUnstretchedChart) {
  // A 20 x 8 mm block whose top-right edge is cut by a planar chamfer at 30 deg to the top,
  // 6 mm wide: its own chart, not stretched into the top's (1/cos 30 = 1.15).
  const float c = std::cos(static_cast<float>(kPi) / 6), s = std::sin(static_cast<float>(kPi) / 6);
  const std::vector<Eigen::Vector2f> outline = {
      {0, 0}, {0.02f, 0}, {0.02f, 0.008f - 0.006f * s}, {0.02f - 0.006f * c, 0.008f}, {0, 0.008f}};
  const TexturedMesh block =
      makePrism(outline, {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}}, 0.01f, Eigen::Matrix3f::Identity());
  const UnwrapResult result = unwrapUvs(block, UnwrapOptions{512, 4});
  EXPECT_EQ(result.chart_count, 7);  // 2 caps, 5 sides
  const AtlasCheck check = checkAtlas(block, result, 512, 4);
  EXPECT_LE(check.max_ratio, 1.01);
}

TEST(UnwrapUvs, PlanarFaceNextToACurvedStripStaysExact) {
  // A flat 10 x 10 mm square and, along its x = 10 mm edge, a strip bending down from 0 to 15
  // deg over 8 mm: one chart (all within 27.6 deg of +z). Projected along the square's own
  // normal, the square is exact; along the mean normal (tilted ~3 deg) it would be 0.2 % off.
  std::vector<Eigen::Vector3f> vertices = {{0, 0, 0}, {0, 0.01f, 0}};
  std::vector<Eigen::Vector3i> triangles;
  const int segments = 8;
  const double radius = 0.008 / (15.0 * kPi / 180.0);
  for (int i = 0; i <= segments; ++i) {
    const double angle = (i == 0 ? 0.0 : 15.0 * kPi / 180.0 * i / segments);
    const float x = static_cast<float>(0.01 + (i == 0 ? 0.0 : radius * std::sin(angle)));
    const float z = static_cast<float>(i == 0 ? 0.0 : -radius * (1 - std::cos(angle)));
    vertices.emplace_back(x, 0.0f, z);
    vertices.emplace_back(x, 0.01f, z);
  }
  // Square: (0, 2, 3), (0, 3, 1); strip: quads between columns.
  triangles.emplace_back(0, 2, 3);
  triangles.emplace_back(0, 3, 1);
  for (int i = 0; i < segments; ++i) {
    const int a = 2 + 2 * i, b = a + 2;
    triangles.emplace_back(a, b, b + 1);
    triangles.emplace_back(a, b + 1, a + 1);
  }
  const TexturedMesh mesh(vertices, triangles);
  const UnwrapResult result = unwrapUvs(mesh, UnwrapOptions{256, 2});
  EXPECT_EQ(result.chart_count, 1);
  checkAtlas(mesh, result, 256, 2, kCleanCurvedBound);
  for (int t = 0; t < 2; ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = result.mesh.triangles()[t][k], b = result.mesh.triangles()[t][(k + 1) % 3];
      const double length = (result.mesh.vertices()[a] - result.mesh.vertices()[b]).norm();
      const double uv_length = (result.mesh.uvs()[a] - result.mesh.uvs()[b]).cast<double>().norm();
      EXPECT_NEAR(length / uv_length / result.metres_per_uv, 1.0, 1e-4) << "edge " << k;
    }
  }
}

// A torus whose vertices are moved by Gaussian noise of `alpha` times the edge length, as in a
// scan.
TexturedMesh makeNoisyTorus(int nu, int nv, double alpha) {
  const TexturedMesh clean = makeTorus(0.02, 0.007, nu, nv);
  std::vector<Eigen::Vector3f> vertices = clean.vertices();
  std::mt19937 random(7);
  std::normal_distribution<float> normal(0.0f, static_cast<float>(alpha * 2 * kPi * 0.007 / nv));
  for (Eigen::Vector3f& v : vertices)
    v += Eigen::Vector3f(normal(random), normal(random), normal(random));
  return TexturedMesh(vertices, clean.triangles());
}

TEST(UnwrapUvs, NoisySurfaceIsNotShattered) {
  // Noise of 5 % of the edge length tilts normals by ~10 deg: plain nearest-direction charts
  // give ~215 charts here (fragments along every border), the smoothed labelling ~60.
  const TexturedMesh torus = makeNoisyTorus(300, 100, 0.05);
  const UnwrapResult result = unwrapUvs(torus);
  EXPECT_LE(result.chart_count, 80);
  const AtlasCheck check = checkAtlas(torus, result, 1024, 4, 1.0 / std::cos(40.0 * kPi / 180.0));
  EXPECT_LE(check.max_ratio, 2.0 + 0.01);  // merged fragments: <= 60 deg
  EXPECT_LT(check.area_above, 0.01 * check.area);
}

TEST(UnwrapUvs, SphereWithoutUvsHasBoundedStretch) {
  const TexturedMesh sphere = withoutUvs(makeUvSphere(0.005, 48, 96));
  const UnwrapResult result = unwrapUvs(sphere);  // 1024 texels, padding 4
  const AtlasCheck check = checkAtlas(sphere, result, 1024, 4, kCleanCurvedBound);
  EXPECT_LE(check.max_ratio, kCleanCurvedBound);
  EXPECT_GE(result.chart_count, 26);
  EXPECT_LE(result.chart_count, 40);
}

TEST(UnwrapUvs, TorusCharts) {
  const TexturedMesh torus = makeTorus(0.02, 0.007, 96, 48);
  UnwrapOptions options;
  options.texture_size = 1024;
  options.padding_texels = 2;
  const UnwrapResult result = unwrapUvs(torus, options);
  const AtlasCheck check = checkAtlas(torus, result, 1024, 2, kCleanCurvedBound);
  EXPECT_LE(check.max_ratio, kCleanCurvedBound);
}

TEST(UnwrapUvs, HelicoidRampIsSplitWhereItWouldOverlap) {
  // A ramp winding 1.5 turns: every face looks up, but its projection covers itself.
  const TexturedMesh ramp = test::makeHelicoidRamp();
  UnwrapOptions options;
  options.texture_size = 512;
  options.padding_texels = 2;
  const UnwrapResult result = unwrapUvs(ramp, options);
  EXPECT_GE(result.chart_count, 2);
  checkAtlas(ramp, result, 512, 2);
}

TEST(UnwrapUvs, LargeMeshUnwrapsIntoFewCharts) {
  // 200k triangles; the time this takes is measured by norm2tex_bench (BM_Unwrap_200kTriangles).
  const TexturedMesh sphere = withoutUvs(makeUvSphere(0.005, 317, 317));
  ASSERT_GT(sphere.triangles().size(), 200000u);
  const UnwrapResult result = unwrapUvs(sphere);
  EXPECT_EQ(result.mesh.triangles().size(), sphere.triangles().size());
  EXPECT_LT(result.chart_count, 100) << "a smooth sphere must not shatter into tiny charts";
  EXPECT_TRUE(result.mesh.hasUvs());
}

TEST(UnwrapUvs, RejectsEmptyDegenerateAndUnfittableMeshes) {
  expectError([] { unwrapUvs(TexturedMesh()); }, {"unwrapUvs", "empty"});
  const TexturedMesh line({{0, 0, 0}, {0.001f, 0, 0}, {0.002f, 0, 0}, {0, 0, 0}},
                          {{0, 1, 2}, {0, 2, 1}, {0, 3, 1}});
  expectError([&] { unwrapUvs(line); }, {"unwrapUvs", "degenerate"});
  // 400 separate triangles, each a chart that needs its padding: no room in 64 texels.
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
  for (int i = 0; i < 400; ++i) {
    const float x = 0.01f * i;
    const int base = static_cast<int>(vertices.size());
    vertices.insert(vertices.end(), {{x, 0, 0}, {x + 0.001f, 0, 0}, {x, 0.001f, 0}});
    triangles.emplace_back(base, base + 1, base + 2);
  }
  UnwrapOptions small;
  small.texture_size = 64;
  small.padding_texels = 4;
  expectError([&] { unwrapUvs(TexturedMesh(vertices, triangles), small); },
              {"400 charts", "padding_texels", "texture_size"});
  UnwrapOptions bad;
  bad.texture_size = 4;
  expectError([&] { unwrapUvs(makeBox(Eigen::Vector3d::Constant(0.01)), bad); }, {"texture_size"});
  bad.texture_size = 64;
  bad.padding_texels = -1;
  expectError([&] { unwrapUvs(makeBox(Eigen::Vector3d::Constant(0.01)), bad); },
              {"padding_texels"});
}

TEST(UvLayout, IslandsOfAnUnwrappedMeshAreItsCharts) {
  for (const TexturedMesh& input :
       {makeBox(Eigen::Vector3d(0.02, 0.01, 0.005)), makeTorus(0.02, 0.007, 48, 24)}) {
    const UnwrapResult result = unwrapUvs(input);
    const cv::Size size(1024, 1024);
    const UvLayout layout = computeUvLayout(result.mesh, size);
    ASSERT_EQ(layout.island.size(), size);
    ASSERT_EQ(static_cast<int>(layout.metres_per_uv.size()), result.chart_count + 1);
    EXPECT_EQ(layout.metres_per_uv[0], 0.0);
    for (int i = 1; i <= result.chart_count; ++i) {
      // Planar islands exactly; curved ones foreshortened by at most 1/cos(40 deg).
      EXPECT_GE(layout.metres_per_uv[i], result.metres_per_uv * (1 - 1e-5)) << "island " << i;
      EXPECT_LE(layout.metres_per_uv[i], result.metres_per_uv * 1.31) << "island " << i;
    }
    // Texels: the same as the test's own rasterisation, island ids mapped one to one.
    int charts = 0, conflicts = 0;
    const std::vector<int> chart = chartsByVertex(result.mesh, &charts);
    const cv::Mat1i reference = rasteriseCharts(result.mesh, chart, size.width, &conflicts);
    std::map<int, int> island_of_chart;
    int mismatched = 0, mapping_errors = 0;
    for (int r = 0; r < size.height; ++r) {
      for (int c = 0; c < size.width; ++c) {
        if ((reference(r, c) == 0) != (layout.island(r, c) == 0)) ++mismatched;
        if (reference(r, c) == 0 || layout.island(r, c) == 0) continue;
        const auto entry = island_of_chart.emplace(reference(r, c), layout.island(r, c)).first;
        if (entry->second != layout.island(r, c)) ++mapping_errors;
      }
    }
    EXPECT_EQ(mismatched, 0);
    EXPECT_EQ(mapping_errors, 0);
  }
  // makeBox's own UVs with a period: every face is scaled to the period; opposite faces share
  // their UV rectangles exactly, so they form one island each (3 islands).
  const UvLayout box =
      computeUvLayout(makeBox(Eigen::Vector3d(0.02, 0.01, 0.005), 0.005), cv::Size(64, 64));
  ASSERT_EQ(box.metres_per_uv.size(), 4u);
  for (int i = 1; i <= 3; ++i) EXPECT_NEAR(box.metres_per_uv[i], 0.005, 1e-9);
  EXPECT_EQ(cv::countNonZero(box.island == 0), 0);  // tiled UVs cover every texel
}

TEST(UvLayout, TwoQuadsWithDifferentUvScales) {
  // Quad A: 10 mm square on UV [0, 0.25]^2; quad B: 10 mm square on [0.5, 1]^2.
  const std::vector<Eigen::Vector3f> vertices = {
      {0, 0, 0},     {0.01f, 0, 0}, {0.01f, 0.01f, 0}, {0, 0.01f, 0},
      {0.05f, 0, 0}, {0.06f, 0, 0}, {0.06f, 0.01f, 0}, {0.05f, 0.01f, 0}};
  const std::vector<Eigen::Vector2f> uvs = {{0, 0},       {0.25f, 0}, {0.25f, 0.25f}, {0, 0.25f},
                                            {0.5f, 0.5f}, {1, 0.5f},  {1, 1},         {0.5f, 1}};
  const TexturedMesh quads(vertices, {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}}, uvs);
  const UvLayout layout = computeUvLayout(quads, cv::Size(256, 256));
  ASSERT_EQ(layout.metres_per_uv.size(), 3u);
  EXPECT_NEAR(layout.metres_per_uv[1], 0.04, 0.04 * 1e-6);  // float coordinates
  EXPECT_NEAR(layout.metres_per_uv[2], 0.02, 0.02 * 1e-6);
  // A: columns 0..63, rows 192..255 (v up); B: columns 128..255, rows 0..127.
  EXPECT_EQ(cv::countNonZero(layout.island == 1), 64 * 64);
  EXPECT_EQ(cv::countNonZero(layout.island == 2), 128 * 128);
  EXPECT_EQ(layout.island(255, 0), 1);
  EXPECT_EQ(layout.island(191, 0), 0);
  EXPECT_EQ(layout.island(0, 255), 2);
  EXPECT_EQ(layout.island(0, 127), 0);

  expectError(
      [] {
        computeUvLayout(withoutUvs(makeBox(Eigen::Vector3d::Constant(0.01))), {8, 8});
      },
      {"computeUvLayout", "no UVs"});
  expectError([&] { computeUvLayout(quads, cv::Size(0, 8)); }, {"computeUvLayout", "size"});
}

// Brute force: squared distance from (r, c) to the nearest island texel, and the values found
// at that distance.
struct Nearest {
  int64_t d2 = std::numeric_limits<int64_t>::max();
  std::vector<cv::Point> texels;
};
Nearest nearestIslandTexel(const cv::Mat1i& island, int r, int c) {
  Nearest nearest;
  for (int y = 0; y < island.rows; ++y) {
    for (int x = 0; x < island.cols; ++x) {
      if (island(y, x) == 0) continue;
      const int64_t d2 =
          static_cast<int64_t>(y - r) * (y - r) + static_cast<int64_t>(x - c) * (x - c);
      if (d2 < nearest.d2) {
        nearest.d2 = d2;
        nearest.texels.clear();
      }
      if (d2 == nearest.d2) nearest.texels.emplace_back(x, y);
    }
  }
  return nearest;
}

TEST(PadIslands, EmptyTexelsNearAnIslandCopyTheirNearestIslandTexel) {
  cv::Mat1i island(40, 48, 0);
  cv::circle(island, cv::Point(12, 14), 7, cv::Scalar(1), cv::FILLED);
  cv::rectangle(island, cv::Rect(28, 6, 10, 22), cv::Scalar(2), cv::FILLED);
  island(35, 5) = 3;  // a single texel
  const int texels = 4;
  cv::Mat1f image(island.size(), -1.0f);
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) {
      if (island(r, c) != 0) image(r, c) = static_cast<float>(r * 100 + c);
    }
  }
  cv::Mat padded = image.clone();
  const cv::Mat1i grown = padIslands(padded, island, texels);
  int filled = 0;
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) {
      if (island(r, c) != 0) {
        EXPECT_EQ(padded.at<float>(r, c), image(r, c));
        EXPECT_EQ(grown(r, c), island(r, c));
        continue;
      }
      const Nearest nearest = nearestIslandTexel(island, r, c);
      if (nearest.d2 > texels * texels) {
        EXPECT_EQ(padded.at<float>(r, c), -1.0f) << r << ", " << c;
        EXPECT_EQ(grown(r, c), 0) << r << ", " << c;
        continue;
      }
      ++filled;
      bool matches = false;
      for (const cv::Point& p : nearest.texels) {
        matches = matches || (padded.at<float>(r, c) == image(p) && grown(r, c) == island(p));
      }
      EXPECT_TRUE(matches) << "texel " << r << ", " << c << " got " << padded.at<float>(r, c);
    }
  }
  EXPECT_GT(filled, 300);

  // Multi-channel images copy whole texels.
  for (int type : {CV_8UC3, CV_16UC3, CV_32FC4}) {
    cv::Mat multi(island.size(), type, cv::Scalar::all(0));
    multi.setTo(cv::Scalar(10, 20, 30, 40), island != 0);
    padIslands(multi, island, texels);
    cv::Mat channels[4];
    cv::split(multi, channels);
    for (int k = 0; k < multi.channels(); ++k) {
      EXPECT_EQ(cv::countNonZero(channels[k]), cv::countNonZero(grown)) << "type " << type;
    }
  }
  expectError(
      [&] {
        cv::Mat wrong(3, 3, CV_8UC1);
        padIslands(wrong, island, 2);
      },
      {"padIslands", "does not match"});
  expectError([&] { padIslands(padded, island, -1); }, {"padIslands", "texels"});
}

TEST(PadIslands, IslandsTwiceThePaddingApartDoNotTouch) {
  const int texels = 3;
  cv::Mat1i island(20, 40, 0);
  island(cv::Rect(2, 2, 8, 16)).setTo(1);
  // Columns 2..9 and 17..24: 2 * texels + 2 = 8 columns apart (7 empty between).
  island(cv::Rect(10 + 2 * texels + 2 - 1, 2, 8, 16)).setTo(2);
  cv::Mat1b image(island.size(), 0);
  image.setTo(1, island == 1);
  image.setTo(2, island == 2);
  cv::Mat padded = image;
  const cv::Mat1i grown = padIslands(padded, island, texels);
  for (int r = 0; r < grown.rows; ++r) {
    for (int c = 0; c + 1 < grown.cols; ++c) {
      for (int dr = -1; dr <= 1; ++dr) {
        const int y = r + dr;
        if (y < 0 || y >= grown.rows) continue;
        EXPECT_FALSE(grown(r, c) != 0 && grown(y, c + 1) != 0 && grown(r, c) != grown(y, c + 1))
            << r << ", " << c;
      }
    }
  }
  EXPECT_EQ(grown(10, 9 + texels), 1);
  EXPECT_EQ(grown(10, 9 + texels + 1), 0);
  EXPECT_EQ(cv::countNonZero(grown == 1), cv::countNonZero(padded == 1));
}

// Compares a loaded mesh with the saved one triangle by triangle.
void expectSameMesh(const TexturedMesh& saved, const TexturedMesh& loaded, bool uvs,
                    const std::string& what) {
  ASSERT_EQ(loaded.triangles().size(), saved.triangles().size()) << what;
  ASSERT_EQ(loaded.hasUvs(), uvs) << what;
  double position_error = 0.0, uv_error = 0.0;
  for (size_t t = 0; t < saved.triangles().size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = saved.triangles()[t][k], b = loaded.triangles()[t][k];
      position_error = std::max(
          position_error, static_cast<double>((saved.vertices()[a] - loaded.vertices()[b]).norm()));
      if (uvs) {
        uv_error =
            std::max(uv_error, static_cast<double>((saved.uvs()[a] - loaded.uvs()[b]).norm()));
      }
    }
  }
  EXPECT_LE(position_error, 1e-6) << what;
  EXPECT_LE(uv_error, 1e-6) << what;
}

TEST(SaveMesh, RoundTripsThroughLoad) {
  test::ScratchDirectory scratch;
  const UnwrapResult result =
      unwrapUvs(withoutUvs(makeUvSphere(0.005, 12, 24)), UnwrapOptions{256, 2});
  const TexturedMesh& mesh = result.mesh;
  fs::create_directories(scratch.path("textures"));
  const std::string texture = scratch.path("textures/sphere normal.png");
  std::ofstream(texture) << "not read";
  const std::string texture_absolute = fs::absolute(texture).lexically_normal().string();

  for (const std::string extension : {"obj", "dae", "glb", "gltf"}) {
    const std::string path = scratch.path("mesh." + extension);
    saveMesh(mesh, path, texture);
    const TexturedMesh loaded = TexturedMesh::load(path);
    expectSameMesh(mesh, loaded, true, path);
    EXPECT_EQ(loaded.normalTexturePath(), texture_absolute) << path;
  }
  // The .mtl names the texture relative to the .obj, both ways.
  {
    std::ifstream mtl(scratch.path("mesh.mtl"));
    const std::string content((std::istreambuf_iterator<char>(mtl)), {});
    EXPECT_NE(content.find("map_Bump textures/sphere normal.png"), std::string::npos) << content;
    EXPECT_NE(content.find("norm textures/sphere normal.png"), std::string::npos) << content;
  }
  // PLY keeps UVs but has no material; STL keeps positions only.
  saveMesh(mesh, scratch.path("mesh.ply"), texture);
  expectSameMesh(mesh, TexturedMesh::load(scratch.path("mesh.ply")), true, "ply");
  saveMesh(mesh, scratch.path("mesh.STL"));
  expectSameMesh(mesh, TexturedMesh::load(scratch.path("mesh.STL")), false, "stl");
  // Without a texture the .obj has no material file and loads without one.
  saveMesh(mesh, scratch.path("plain.obj"));
  EXPECT_FALSE(fs::exists(scratch.path("plain.mtl")));
  const TexturedMesh plain = TexturedMesh::load(scratch.path("plain.obj"));
  expectSameMesh(mesh, plain, true, "plain obj");
  EXPECT_TRUE(plain.normalTexturePath().empty());
}

TEST(SaveMesh, ErrorsNameTheFile) {
  test::ScratchDirectory scratch;
  const TexturedMesh box = makeBox(Eigen::Vector3d::Constant(0.01));
  const std::string unknown = scratch.path("box.xyz");
  expectError([&] { saveMesh(box, unknown); }, {unknown, "extension"});
  const std::string missing = scratch.path("no/such/dir/box.obj");
  expectError([&] { saveMesh(box, missing); }, {missing});
  std::ofstream(scratch.path("file")) << "x";
  const std::string under_file = scratch.path("file/box.ply");
  expectError([&] { saveMesh(box, under_file); }, {under_file});
  expectError([&] { saveMesh(box, scratch.root()); }, {scratch.root()});
  expectError([&] { saveMesh(TexturedMesh(), scratch.path("empty.obj")); }, {"empty"});
}

}  // namespace
}  // namespace norm2tex
