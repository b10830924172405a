// Runs the real norm2tex_texgen executable: files, determinism, meshes, variants, errors.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

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
  EXPECT_EQ(cv::imread(path("n.png"), cv::IMREAD_UNCHANGED).type(), CV_8UC4);
  EXPECT_EQ(cv::imread(path("a.png"), cv::IMREAD_UNCHANGED).type(), CV_8UC3);
  EXPECT_EQ(cv::imread(path("h.tiff"), cv::IMREAD_UNCHANGED).type(), CV_32FC1);
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
  const cv::Mat gallery = cv::imread(path("gallery.png"));
  EXPECT_GT(gallery.rows, 5 * 320);
  EXPECT_GT(gallery.cols, 4 * 240);
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
