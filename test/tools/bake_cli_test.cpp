// Runs the real norm2tex_bake executable: outputs, exit codes and one-line errors.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "cli_runner.hpp"
#include "norm2tex/texture/analytic_surface.hpp"
#include "norm2tex/texture/normal_encoding.hpp"

namespace {
namespace fs = std::filesystem;

using norm2tex::test::CliRun;

CliRun bake(const std::string& arguments) {
  return norm2tex::test::runCommand(NORM2TEX_BAKE_EXECUTABLE, arguments);
}

class BakeCli : public norm2tex::test::CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    const cv::Size size(96, 64);
    norm2tex::AnalyticSurface s = norm2tex::makeWaves(size, {{2.0, 30.0, 0.5, 0.0}});
    const cv::Mat1b mask = norm2tex::makeIslandMask(size, 2, 4);
    cv::imwrite(
        path("normal.png"),
        norm2tex::encodeNormalMap(s.dx, s.dy, norm2tex::NormalConvention::kOpenGL, CV_16U, mask));
    cv::imwrite(path("mask.png"), mask);
  }
};

TEST_F(BakeCli, WritesAFloatTiffOfTheMapsSize) {
  const CliRun run =
      bake(path("normal.png") + " --mask " + path("mask.png") + " -o " + path("h.tiff"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("4 UV islands"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("bake "), std::string::npos) << "reports the time: " << run.output;
  const cv::Mat h = cv::imread(path("h.tiff"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(h.type(), CV_32FC1);
  EXPECT_EQ(h.size(), cv::Size(96, 64));
  // Texels outside the islands are NaN (invalid), the islands finite and in [-1, 1].
  const cv::Mat1b mask = cv::imread(path("mask.png"), cv::IMREAD_GRAYSCALE);
  const cv::Mat1b finite = h == h;  // NaN != NaN
  EXPECT_EQ(cv::countNonZero(finite != (mask != 0)), 0);
  double low, high;
  cv::minMaxLoc(h, &low, &high, nullptr, nullptr, mask);
  EXPECT_FLOAT_EQ(low, -1.0f);
  EXPECT_FLOAT_EQ(high, 1.0f);
}

TEST_F(BakeCli, RangeAndPngPreview) {
  ASSERT_EQ(bake(path("normal.png") + " --range 0,1 -o " + path("h.tif")).exit_code, 0);
  double low, high;
  cv::minMaxLoc(cv::imread(path("h.tif"), cv::IMREAD_UNCHANGED), &low, &high);
  EXPECT_FLOAT_EQ(low, 0.0f);
  EXPECT_FLOAT_EQ(high, 1.0f);
  ASSERT_EQ(bake(path("normal.png") + " --quiet -o " + path("preview.png")).exit_code, 0);
  const cv::Mat preview = cv::imread(path("preview.png"), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(preview.type(), CV_8UC1);
  cv::minMaxLoc(preview, &low, &high);
  EXPECT_EQ(high, 255.0);
}

TEST_F(BakeCli, BadInputExitsNonZeroWithOneLineReason) {
  std::ofstream(path("empty.png")).close();
  std::ofstream(path("corrupt.png")) << "\x89PNG\r\n\x1a\ngarbage";
  cv::imwrite(path("gray.png"), cv::Mat(8, 8, CV_8UC1, cv::Scalar(9)));
  cv::imwrite(path("transparent.png"), cv::Mat(8, 8, CV_8UC4, cv::Scalar(255, 128, 128, 0)));
  // The first 1000 bytes of a real JPEG: libjpeg alone would decode it with grey rows.
  cv::Mat noise(64, 96, CV_8UC3);
  cv::randu(noise, 0, 255);
  cv::imwrite(path("whole.jpg"), noise);
  std::ifstream whole(path("whole.jpg"), std::ios::binary);
  std::string bytes(1000, '\0');
  whole.read(&bytes[0], 1000);
  std::ofstream(path("truncated.jpg"), std::ios::binary) << bytes;
  // A PNG and a TIFF cut in half: refused too, not decoded with their missing rows.
  for (const std::string name : {"whole.png", "whole.tif"}) {
    cv::imwrite(path(name), noise);
    std::ifstream file(path(name), std::ios::binary);
    const std::string whole_file((std::istreambuf_iterator<char>(file)),
                                 std::istreambuf_iterator<char>());
    std::ofstream(path("truncated" + name.substr(5)), std::ios::binary)
        << whole_file.substr(0, whole_file.size() / 2);
  }
  for (const std::string input :
       {"missing.png", "empty.png", "corrupt.png", "gray.png", "transparent.png", "truncated.jpg",
        "truncated.png", "truncated.tif"}) {
    const CliRun run = bake(path(input) + " -o " + path("out.tiff"));
    EXPECT_EQ(run.exit_code, 1) << input << ": " << run.output;
    EXPECT_EQ(run.output.rfind("norm2tex_bake: error: ", 0), 0u) << run.output;
    EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
    EXPECT_FALSE(fs::exists(path("out.tiff"))) << "no output for bad input";
  }
}

TEST_F(BakeCli, ReliefOptionsPhysicalScaleAndMesh) {
  // Default: the high-pass is reported with the long-wavelength share; --paper-exact has none.
  const CliRun plain = bake(path("normal.png") + " -o " + path("h.tiff"));
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  EXPECT_NE(plain.output.find("relief high-pass at 64 texels"), std::string::npos) << plain.output;
  const CliRun paper = bake(path("normal.png") + " --paper-exact -o " + path("p.tiff"));
  ASSERT_EQ(paper.exit_code, 0) << paper.output;
  EXPECT_NE(paper.output.find("no relief high-pass"), std::string::npos) << paper.output;
  // Physical scale: heights in mm, the amplitude printed; needs a scale.
  const CliRun physical =
      bake(path("normal.png") + " --mm-per-texel 0.05 --physical -o " + path("mm.tiff"));
  ASSERT_EQ(physical.exit_code, 0) << physical.output;
  EXPECT_NE(physical.output.find("implied relief amplitude"), std::string::npos) << physical.output;
  const CliRun no_scale = bake(path("normal.png") + " --physical -o " + path("x.tiff"));
  EXPECT_EQ(no_scale.exit_code, 1) << no_scale.output;
  EXPECT_NE(no_scale.output.find("mm_per_texel"), std::string::npos) << no_scale.output;
  // With a mesh (a plate whose UVs cover the left half): texels off the chart are invalid
  // (NaN) although the map has no alpha, and the scale comes from the mesh.
  std::ofstream(path("plate.obj")) << "v 0 0 0\nv 0.0024 0 0\nv 0.0024 0.0032 0\nv 0 0.0032 0\n"
                                      "vt 0 0\nvt 0.5 0\nvt 0.5 1\nvt 0 1\n"
                                      "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
  const CliRun meshed =
      bake(path("normal.png") + " --mesh " + path("plate.obj") + " -o " + path("meshed.tiff"));
  ASSERT_EQ(meshed.exit_code, 0) << meshed.output;
  EXPECT_NE(meshed.output.find("mesh: 1 UV charts, 0.05 mm per texel"), std::string::npos)
      << meshed.output;
  const cv::Mat h = cv::imread(path("meshed.tiff"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(h.type(), CV_32FC1);
  const cv::Mat1b finite = h == h;
  EXPECT_NEAR(cv::countNonZero(finite(cv::Rect(0, 0, 48, 64))), 48 * 64, 64);
  EXPECT_EQ(cv::countNonZero(finite(cv::Rect(48, 0, 48, 64))), 0);
}

TEST_F(BakeCli, UsageErrorsExitWithTwo) {
  EXPECT_EQ(bake(path("normal.png")).exit_code, 2) << "no -o";
  EXPECT_EQ(bake(path("normal.png") + " -o " + path("x.jpg")).exit_code, 2) << "bad extension";
  EXPECT_EQ(bake(path("normal.png") + " --alpha lots -o " + path("x.tiff")).exit_code, 2);
  EXPECT_EQ(bake(path("normal.png") + " --frobnicate -o " + path("x.tiff")).exit_code, 2);
  EXPECT_EQ(bake(path("normal.png") + " --alpha 3 -o " + path("x.tiff")).exit_code, 1)
      << "a number out of range is a parameter error";
  EXPECT_EQ(bake(path("normal.png") + " --convention vulkan -o " + path("x.tiff")).exit_code, 1);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
