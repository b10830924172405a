// Runs the real norm2tex_texgen executable: files, determinism, meshes, variants, errors.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cli_runner.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/mesh/textured_mesh.hpp"
#include "norm2tex/mesh/uv_unwrap.hpp"

namespace {
namespace fs = std::filesystem;
using norm2tex::test::CliRun;

CliRun texgen(const std::string& arguments) {
  return norm2tex::test::runCommand(NORM2TEX_TEXGEN_EXECUTABLE, arguments);
}

std::string readBytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  std::stringstream bytes;
  bytes << file.rdbuf();
  return bytes.str();
}

using TexgenCli = norm2tex::test::CliTest;

TEST_F(TexgenCli, ListsEveryMaterialWithItsParameters) {
  const CliRun run = texgen("--list");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  for (const char* name : {"wood", "fabric", "rock", "smooth", "print3d"}) {
    EXPECT_NE(run.output.find(std::string(name) + "\n"), std::string::npos) << name;
  }
  EXPECT_NE(run.output.find("ring_spacing_mm"), std::string::npos);
  EXPECT_NE(run.output.find("layer_pitch_mm"), std::string::npos);
}

TEST_F(TexgenCli, SameSeedSameBytesOtherSeedOtherBytes) {
  for (const char* material : {"wood", "print3d"}) {
    const std::string m(material);
    ASSERT_EQ(texgen("--material " + m + " --size 128 --seed 3 -o " + path(m + "_a.png")).exit_code,
              0);
    ASSERT_EQ(texgen("--material " + m + " --size 128 --seed 3 -o " + path(m + "_b.png")).exit_code,
              0);
    ASSERT_EQ(texgen("--material " + m + " --size 128 --seed 4 -o " + path(m + "_c.png")).exit_code,
              0);
    EXPECT_EQ(readBytes(path(m + "_a.png")), readBytes(path(m + "_b.png"))) << m;
    EXPECT_NE(readBytes(path(m + "_a.png")), readBytes(path(m + "_c.png"))) << m;
  }
  const cv::Mat normal = cv::imread(path("wood_a.png"), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(normal.type(), CV_16UC4);
  EXPECT_EQ(normal.size(), cv::Size(128, 128));
}

TEST_F(TexgenCli, WritesAlbedoHeightAndEightBit) {
  const CliRun run =
      texgen("--material rock --size 64 --bits 8 --param grain_size_mm=1.5 -o " + path("n.png") +
             " --albedo " + path("a.png") + " --height-out " + path("h.tiff"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const cv::Mat normal = cv::imread(path("n.png"), cv::IMREAD_UNCHANGED);
  const cv::Mat albedo = cv::imread(path("a.png"), cv::IMREAD_UNCHANGED);
  const cv::Mat height = cv::imread(path("h.tiff"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(normal.type(), CV_8UC4);
  ASSERT_EQ(albedo.type(), CV_8UC3);
  ASSERT_EQ(height.type(), CV_32FC1);
  ASSERT_EQ(normal.size(), cv::Size(64, 64));
  EXPECT_EQ(albedo.size(), normal.size());
  EXPECT_EQ(height.size(), normal.size());
  // The three files describe one surface: the normal map is the height's slope. Decode the
  // 8-bit normals and compare with central differences of the height (mm over mm per texel).
  double mm_per_texel = 0.0;
  {
    const auto at = run.output.find(" mm per texel");
    ASSERT_NE(at, std::string::npos) << run.output;
    const auto start = run.output.rfind(' ', at - 1);
    mm_per_texel = std::stod(run.output.substr(start + 1, at - start - 1));
  }
  ASSERT_GT(mm_per_texel, 0.0);
  cv::Mat1f predicted_x(62, 62), decoded_x(62, 62);
  for (int r = 1; r < 63; ++r) {
    for (int c = 1; c < 63; ++c) {
      const cv::Vec4b n = normal.at<cv::Vec4b>(r, c);  // B, G, R, A
      const double nx = 2.0 * n[2] / 255.0 - 1.0, nz = 2.0 * n[0] / 255.0 - 1.0;
      decoded_x(r - 1, c - 1) = static_cast<float>(-nx / nz);
      predicted_x(r - 1, c - 1) = static_cast<float>(
          (height.at<float>(r, c + 1) - height.at<float>(r, c - 1)) / (2.0 * mm_per_texel));
    }
  }
  cv::Mat correlation;
  cv::matchTemplate(decoded_x, predicted_x, correlation, cv::TM_CCOEFF_NORMED);
  EXPECT_GT(correlation.at<float>(0, 0), 0.9) << "normal map and height disagree";
  // Every texel is valid (alpha 255) and the albedo is not one flat colour.
  std::vector<cv::Mat> channels;
  cv::split(normal, channels);
  EXPECT_EQ(cv::countNonZero(channels[3] != 255), 0);
  cv::Scalar mean, deviation;
  cv::meanStdDev(albedo, mean, deviation);
  EXPECT_GT(deviation[0] + deviation[1] + deviation[2], 3.0);
}

TEST_F(TexgenCli, MeshWithoutUvsIsUnwrappedAndWrittenWithItsNormalMap) {
  const norm2tex::TexturedMesh box = norm2tex::makeBox(Eigen::Vector3d(0.02, 0.01, 0.005));
  norm2tex::saveMesh(norm2tex::TexturedMesh(box.vertices(), box.triangles()), path("box.stl"));
  const CliRun run = texgen("--material fabric --size 256 --mesh " + path("box.stl") +
                            " --out-mesh " + path("box_uv.obj") + " -o " + path("box_normal.png"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("unwrapped"), std::string::npos) << run.output;
  const norm2tex::TexturedMesh reloaded = norm2tex::TexturedMesh::load(path("box_uv.obj"));
  EXPECT_TRUE(reloaded.hasUvs());
  EXPECT_EQ(reloaded.triangles().size(), box.triangles().size());
  EXPECT_EQ(fs::path(reloaded.normalTexturePath()).filename(), "box_normal.png");
  const cv::Mat normal = cv::imread(path("box_normal.png"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(normal.channels(), 4);
  std::vector<cv::Mat> channels;
  cv::split(normal, channels);
  const int island_texels = cv::countNonZero(channels[3]);
  EXPECT_GT(island_texels, 256 * 256 / 4) << "the charts cover part of the atlas";
  EXPECT_LT(island_texels, 256 * 256) << "with padding around them";
}

TEST_F(TexgenCli, MeshWithUvsGetsTheAtlasTheNodesUse) {
  // The shipped cube's UVs repeat every 20 mm: print3d (0.025 mm a texel, size 2048) gets 1024
  // texels (0.0195 mm), as bakeMaterialAtlas gives the nodes; --size forces a size.
  norm2tex::saveMesh(norm2tex::makeBox(Eigen::Vector3d(0.03, 0.03, 0.03), 0.02), path("cube.obj"));
  const CliRun run =
      texgen("--material print3d --mesh " + path("cube.obj") + " -o " + path("cube_normal.png"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("1024^2 texels"), std::string::npos) << run.output;
  EXPECT_EQ(cv::imread(path("cube_normal.png"), cv::IMREAD_UNCHANGED).size(), cv::Size(1024, 1024));
  const CliRun forced = texgen("--material print3d --size 256 --mesh " + path("cube.obj") + " -o " +
                               path("cube_256.png"));
  ASSERT_EQ(forced.exit_code, 0) << forced.output;
  EXPECT_EQ(cv::imread(path("cube_256.png"), cv::IMREAD_UNCHANGED).size(), cv::Size(256, 256));
}

TEST_F(TexgenCli, VariantsAreFilesPlusAManifest) {
  const CliRun run = texgen("--material smooth --size 64 --variants 3 --out-dir " + path("v"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  for (int k = 1; k <= 3; ++k) {
    EXPECT_TRUE(fs::exists(path("v/smooth_0" + std::to_string(k) + "_normal.png"))) << k;
    EXPECT_TRUE(fs::exists(path("v/smooth_0" + std::to_string(k) + "_albedo.png"))) << k;
  }
  const std::string manifest = readBytes(path("v/variants.yaml"));
  EXPECT_NE(manifest.find("scratch_density_per_mm2"), std::string::npos) << manifest;
  EXPECT_NE(readBytes(path("v/smooth_01_normal.png")), readBytes(path("v/smooth_02_normal.png")));
}

TEST_F(TexgenCli, GalleryHasARowPerMaterial) {
  const CliRun run = texgen("--gallery -o " + path("gallery.png"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const cv::Mat3b gallery = cv::imread(path("gallery.png"));
  // Layout of contact_sheet.cpp: 28 px of column labels, 150 px of row labels, 4 px gaps;
  // one row per material (5), columns albedo, normal map, no texture, texture.
  ASSERT_EQ(gallery.rows, 28 + 5 * (320 + 4));
  ASSERT_EQ(gallery.cols, 150 + 4 * (240 + 4));
  const auto tile = [&](int row, int column) {
    return cv::Mat3b(gallery(cv::Rect(150 + column * 244, 28 + row * 324, 240, 320)));
  };
  for (int row = 0; row < 5; ++row) {
    // The material's texture changes the pressed image (column 3 against column 2; same
    // noise seed, so without texture they would be equal; "smooth" changes it least)...
    EXPECT_GT(cv::norm(tile(row, 2), tile(row, 3), cv::NORM_L1) / (240.0 * 320.0), 0.1)
        << "row " << row;
    // ...and each row is another material.
    for (int other = 0; other < row; ++other) {
      EXPECT_GT(cv::norm(tile(row, 1), tile(other, 1), cv::NORM_L1) / (240.0 * 320.0), 1.0)
          << "rows " << other << " and " << row << " show the same normal map";
    }
  }
}

TEST_F(TexgenCli, BadInputListsTheValidChoices) {
  const CliRun unknown = texgen("--material granite --size 64 -o " + path("x.png"));
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_NE(unknown.output.find("print3d"), std::string::npos) << unknown.output;
  const CliRun bad_param = texgen("--material wood --size 64 --param grain=1 -o " + path("x.png"));
  EXPECT_EQ(bad_param.exit_code, 1);
  EXPECT_NE(bad_param.output.find("ring_spacing_mm"), std::string::npos) << bad_param.output;
  const CliRun out_of_range =
      texgen("--material wood --size 64 --param ring_spacing_mm=999 -o " + path("x.png"));
  EXPECT_EQ(out_of_range.exit_code, 1);
  EXPECT_NE(out_of_range.output.find("ring_spacing_mm"), std::string::npos) << out_of_range.output;
  EXPECT_EQ(texgen("--material wood --param ring_spacing_mm -o " + path("x.png")).exit_code, 2);
  EXPECT_EQ(texgen("--material wood --bits 12 -o " + path("x.png")).exit_code, 2);
  EXPECT_EQ(texgen("--material wood").exit_code, 2) << "no -o";
  EXPECT_FALSE(fs::exists(path("x.png")));
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
