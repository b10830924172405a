// bakeHeightAtlasForMesh: islands from the mesh's UV charts, the surface's scale, and island
// offsets that make heights agree across the mesh's seams.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "norm2tex/texture/mesh_bake.hpp"
#include "norm2tex/texture/normal_encoding.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

constexpr int kTexture = 1024;
constexpr double kUvPerMm = 0.04;  // 20 mm of surface span 0.8 of the texture

/// Relief on the surface, mm: fine waves (wavelengths 1.2 and 1.7 mm, below the 2 mm cutoff)
/// on a broad bump centred on the left half (sigma 6 mm: geometry the high-pass removes), so
/// the halves' means differ and zero-mean islands would step at the seam.
double reliefMm(double x, double y) {
  return 0.05 * std::sin(2 * CV_PI * x / 1.2) * std::sin(2 * CV_PI * y / 1.7) +
         0.3 * std::exp(-((x + 5) * (x + 5) + y * y) / (2 * 6.0 * 6.0));
}

/// Left chart x in [-10, 0] mm at u = 0.05 + 0.04 (x + 10); right chart x in [0, 10] mm at
/// u = 0.55 + 0.04 x: a gap between them in the texture, one seam (x = 0) on the surface.
/// v = 0.5 + 0.04 y for y in [-10, 10]. Each half is a grid of 10 x 20 quads.
TexturedMesh twoChartSquare() {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector2f> uvs;
  std::vector<Eigen::Vector3i> triangles;
  for (int half = 0; half < 2; ++half) {
    const int first = static_cast<int>(vertices.size());
    for (int i = 0; i <= 20; ++i) {
      for (int j = 0; j <= 10; ++j) {
        const double x = (half == 0 ? -10.0 : 0.0) + j, y = -10.0 + i;
        vertices.emplace_back(static_cast<float>(x * 1e-3), static_cast<float>(y * 1e-3), 0.0f);
        const double u = half == 0 ? 0.05 + kUvPerMm * (x + 10) : 0.55 + kUvPerMm * x;
        uvs.emplace_back(static_cast<float>(u), static_cast<float>(0.5 + kUvPerMm * y));
      }
    }
    for (int i = 0; i < 20; ++i) {
      for (int j = 0; j < 10; ++j) {
        const int a = first + i * 11 + j;
        triangles.emplace_back(a, a + 1, a + 12);
        triangles.emplace_back(a, a + 12, a + 11);
      }
    }
  }
  return TexturedMesh(std::move(vertices), std::move(triangles), std::move(uvs));
}

/// The relief's normal map in this layout (16-bit, no alpha: every texel "valid" as far as the
/// image goes; only the mesh says where the charts are).
NormalMap twoChartNormalMap() {
  cv::Mat1f dx(kTexture, kTexture, 0.0f), dy(kTexture, kTexture, 0.0f);
  const double h = 1e-4;
  for (int r = 0; r < kTexture; ++r) {
    for (int c = 0; c < kTexture; ++c) {
      const double u = (c + 0.5) / kTexture, v = 1.0 - (r + 0.5) / kTexture;
      double x;
      if (u >= 0.05 && u <= 0.45) {
        x = (u - 0.05) / kUvPerMm - 10.0;
      } else if (u >= 0.55 && u <= 0.95) {
        x = (u - 0.55) / kUvPerMm;
      } else {
        continue;
      }
      const double y = (v - 0.5) / kUvPerMm;
      // Slopes per texel are slopes on the surface (same scale on both axes); rows run
      // against v, hence against y.
      dx(r, c) = static_cast<float>((reliefMm(x + h, y) - reliefMm(x - h, y)) / (2 * h));
      dy(r, c) = static_cast<float>(-(reliefMm(x, y + h) - reliefMm(x, y - h)) / (2 * h));
    }
  }
  return NormalMap::fromImage(encodeNormalMap(dx, dy, NormalConvention::kOpenGL, CV_16U));
}

/// RMS of H_global's difference between the two UVs of seam points (x = 0), relative to the
/// atlas's range.
double seamStep(const HeightAtlas& atlas) {
  double sum = 0.0;
  int count = 0;
  for (double y = -9.5; y <= 9.5; y += 0.25) {
    const double v = 0.5 + kUvPerMm * y;
    bool left_ok = false, right_ok = false;
    const double left = atlas.sample(0.45, v, &left_ok), right = atlas.sample(0.55, v, &right_ok);
    if (!left_ok || !right_ok) continue;
    sum += (left - right) * (left - right);
    ++count;
  }
  double low, high;
  cv::minMaxLoc(atlas.heights(), &low, &high, nullptr, nullptr, atlas.valid());
  return count > 0 ? std::sqrt(sum / count) / (high - low) : 1.0;
}

TEST(MeshBake, ChartsAreTheIslandsAndTheSurfaceSetsTheScale) {
  const TexturedMesh mesh = twoChartSquare();
  const NormalMap map = twoChartNormalMap();
  MeshBakeReport report;
  const HeightAtlas atlas = bakeHeightAtlasForMesh(map, mesh, {}, {}, &report);
  EXPECT_EQ(report.chart_count, 2);
  EXPECT_EQ(atlas.islandCount(), 2);
  // Texels outside both charts are invalid although the image has no alpha.
  const double chart_texels = 2 * (0.4 * kTexture) * (0.8 * kTexture);
  EXPECT_NEAR(cv::countNonZero(atlas.valid()), chart_texels, 0.03 * chart_texels);
  EXPECT_NEAR(report.mm_per_texel, 1.0 / (kUvPerMm * kTexture), 1e-3 * report.mm_per_texel);
  EXPECT_NEAR(report.bake.relief_cutoff_texels, 2.0 / report.mm_per_texel, 1e-6);
}

TEST(MeshBake, SeamOffsetsRemoveTheStepAcrossTheSeam) {
  // Without the relief high-pass: the islands' heights are the surface's up to a constant, and
  // the offsets must find it.
  const TexturedMesh mesh = twoChartSquare();
  const NormalMap map = twoChartNormalMap();
  BakeOptions unfiltered;
  unfiltered.relief_cutoff_mm = 0.0;
  MeshBakeReport report;
  const HeightAtlas matched = bakeHeightAtlasForMesh(map, mesh, unfiltered, {}, &report);
  EXPECT_GT(report.seams.seam_edges, 15);
  EXPECT_GT(report.seams.step_before, 0.05) << "zero-mean islands step at the seam";
  EXPECT_LT(report.seams.step_after, 0.02);
  const double step = seamStep(matched);
  EXPECT_LT(step, 0.02) << "sampled in the finished atlas";
  testing::Test::RecordProperty("seam_step_before", std::to_string(report.seams.step_before));
  testing::Test::RecordProperty("seam_step_after", std::to_string(report.seams.step_after));

  // With the default high-pass each island is filtered on its own, so near a seam the two
  // sides' low-passes differ in shape (not by a constant); the seam feathering must take it out.
  MeshBakeReport filtered;
  const HeightAtlas with_cutoff = bakeHeightAtlasForMesh(map, mesh, {}, {}, &filtered);
  EXPECT_GT(filtered.seams.step_before, 0.05);
  EXPECT_LT(filtered.seams.step_after, 0.05);
  const double filtered_step = seamStep(with_cutoff);
  EXPECT_LT(filtered_step, 0.05) << "sampled in the finished atlas";
  testing::Test::RecordProperty("seam_step_filtered_atlas", std::to_string(filtered_step));
  testing::Test::RecordProperty("seam_step_filtered_before",
                                std::to_string(filtered.seams.step_before));
  testing::Test::RecordProperty("seam_step_filtered_after",
                                std::to_string(filtered.seams.step_after));
}

TEST(MeshBake, MeshWithoutUvsIsAnError) {
  const TexturedMesh mesh = twoChartSquare();
  const TexturedMesh bare(mesh.vertices(), mesh.triangles());
  test::expectError([&] { bakeHeightAtlasForMesh(twoChartNormalMap(), bare); }, {"no UVs"});
}

}  // namespace
}  // namespace norm2tex
