// Runs the real norm2tex_render executable: outputs, the sheet, exit codes and messages.
#include <algorithm>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cli_runner.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/texture/analytic_surface.hpp"
#include "norm2tex/texture/normal_encoding.hpp"

namespace {
namespace fs = std::filesystem;
using norm2tex::test::CliRun;

CliRun render(const std::string& arguments) {
  return norm2tex::test::runCommand(NORM2TEX_RENDER_EXECUTABLE, arguments);
}

class RenderCli : public norm2tex::test::CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    const cv::Size size(128, 128);
    const norm2tex::AnalyticSurface s = norm2tex::makeRidges(size, {0.5, 9.0, 1.5, 1.0});
    cv::imwrite(path("ridges.png"),
                norm2tex::encodeNormalMap(s.dx, s.dy, norm2tex::NormalConvention::kOpenGL, CV_8U));
    // Keep the bake cache inside the scratch directory.
    setenv("NORM2TEX_CACHE_DIR", path("cache").c_str(), 1);
  }
};

constexpr const char* kBall = "--mesh sphere:5 --pose \"0.002 0 0.005 1.5708 0 0\" --press-mm 1";

TEST_F(RenderCli, WritesImageDepthAndMask) {
  const CliRun run = render(std::string(kBall) + " --normal-map " + path("ridges.png") + " -o " +
                            path("frame.png") + " --depth-out " + path("depth.tiff") +
                            " --mask-out " + path("mask.png"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("textured"), std::string::npos) << run.output;
  const cv::Mat image = cv::imread(path("frame.png"), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(image.type(), CV_8UC3);
  EXPECT_EQ(image.size(), cv::Size(240, 320));
  const cv::Mat depth = cv::imread(path("depth.tiff"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(depth.type(), CV_32FC1);
  double max_depth = 0;
  cv::minMaxLoc(depth, nullptr, &max_depth);
  EXPECT_NEAR(max_depth, 1.0e-3, 0.15e-3) << "metres";
  const cv::Mat mask = cv::imread(path("mask.png"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(mask.type(), CV_8UC1);
  const cv::Moments m = cv::moments(mask, true);
  ASSERT_GT(m.m00, 1000);
  const double mm_per_pixel = norm2tex::makeDigitSensorModel().mm_per_pixel;  // no --sensor
  EXPECT_NEAR(m.m10 / m.m00, 119.5 + 2.0 / mm_per_pixel, 1.5) << "x = +2 mm is right of centre";
}

TEST_F(RenderCli, SheetHasOneRowPerTextureAndOneColumnPerPress) {
  const CliRun run =
      render(std::string("--sheet ") + kBall + " --presses 0.5,1 --normal-map " +
             path("ridges.png") + "," + path("ridges.png") + " -o " + path("sheet.png"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("3 x 2"), std::string::npos) << run.output;
  const cv::Mat sheet = cv::imread(path("sheet.png"));
  EXPECT_GT(sheet.cols, 2 * 240);
  EXPECT_GT(sheet.rows, 3 * 320);
}

TEST_F(RenderCli, BadInputIsAOneLineErrorOrUsage) {
  const CliRun missing =
      render("--mesh " + path("nope.obj") + " --pose \"0 0 0 0 0 0\" -o " + path("x.png"));
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_NE(missing.output.find("nope.obj"), std::string::npos) << missing.output;
  EXPECT_EQ(std::count(missing.output.begin(), missing.output.end(), '\n'), 1);
  EXPECT_EQ(render(std::string(kBall) + " --beta -1 --normal-map " + path("ridges.png") + " -o " +
                   path("x.png"))
                .exit_code,
            1);
  EXPECT_EQ(render("--mesh sphere:5 --pose \"0 0 0\" -o " + path("x.png")).exit_code, 2);
  EXPECT_EQ(render("--mesh sphere:5 --pose \"0 0 nan 0 0 0\" -o " + path("x.png")).exit_code, 2);
  EXPECT_EQ(render(std::string(kBall)).exit_code, 2) << "no -o";
  EXPECT_EQ(
      render(std::string(kBall) + " --background " + path("nope.png") + " -o " + path("x.png"))
          .exit_code,
      1);
  EXPECT_FALSE(fs::exists(path("x.png")));
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
