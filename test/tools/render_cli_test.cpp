// Runs the real norm2tex_render executable: outputs, the sheet, exit codes and messages.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <limits>
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
  EXPECT_NEAR(max_depth, 1.0e-3, 0.2e-3) << "metres: the 1 mm press, its ridges' crests deeper";
  const cv::Mat mask = cv::imread(path("mask.png"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(mask.type(), CV_8UC1);
  const cv::Moments m = cv::moments(mask, true);
  ASSERT_GT(m.m00, 1000);
  const double mm_per_pixel = norm2tex::makeDigitSensorModel().mm_per_pixel;  // no --sensor
  EXPECT_NEAR(m.m10 / m.m00, 119.5 + 2.0 / mm_per_pixel, 1.5) << "x = +2 mm is right of centre";
}

TEST_F(RenderCli, ContactStatsMeasureThePressAgainstTheBackground) {
  // The figure real presses are compared with: |frame - background| over the contact. The
  // synthetic background without noise: a press away from the frame's contact changes nothing.
  const CliRun run = render(std::string(kBall) + " --no-noise --contact-stats -o " +
                            path("frame.png") + " --mask-out " + path("mask.png"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string key = "contact |frame - background|: mean ";
  const size_t at = run.output.find(key);
  ASSERT_NE(at, std::string::npos) << run.output;
  const double mean = std::stod(run.output.substr(at + key.size()));
  EXPECT_GT(mean, 5.0) << run.output;
  EXPECT_LT(mean, 60.0) << run.output;
  EXPECT_NE(run.output.find("95th percentile"), std::string::npos) << run.output;
  const CliRun sheet = render(std::string(kBall) + " --sheet --contact-stats -o " +
                              path("sheet.png"));
  EXPECT_EQ(sheet.exit_code, 2) << sheet.output;
  EXPECT_NE(sheet.output.find("--contact-stats"), std::string::npos) << sheet.output;
}

TEST_F(RenderCli, SheetHasOneRowPerTextureAndOneColumnPerPress) {
  const CliRun run =
      render(std::string("--sheet ") + kBall + " --presses 0.5,1 --normal-map " +
             path("ridges.png") + "," + path("ridges.png") + " -o " + path("sheet.png"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("3 x 2"), std::string::npos) << run.output;
  const cv::Mat3b sheet = cv::imread(path("sheet.png"));
  // Layout of contact_sheet.cpp: 28 px of column labels, 150 px of row labels, 4 px gaps.
  ASSERT_EQ(sheet.rows, 28 + 3 * (320 + 4));
  ASSERT_EQ(sheet.cols, 150 + 2 * (240 + 4));
  const auto tile = [&](int row, int column) {
    return cv::Mat3b(sheet(cv::Rect(150 + column * 244, 28 + row * 324, 240, 320)));
  };
  const auto difference = [](const cv::Mat3b& a, const cv::Mat3b& b) {
    return cv::norm(a, b, cv::NORM_L1) / (a.total() * 3.0);
  };
  for (int column = 0; column < 2; ++column) {
    // Row 0 textureless, rows 1 and 2 the same normal map: the texture shows and is the same.
    EXPECT_GT(difference(tile(0, column), tile(1, column)), 0.05) << "press " << column;
    EXPECT_EQ(difference(tile(1, column), tile(2, column)), 0.0) << "press " << column;
  }
  EXPECT_GT(difference(tile(0, 0), tile(0, 1)), 0.1) << "a deeper press is another image";
}

TEST_F(RenderCli, FloatDepthToAnEightBitFormatIsRefusedBeforeAnyOutput) {
  const CliRun run =
      render(std::string(kBall) + " -o " + path("frame.png") + " --depth-out " + path("depth.png"));
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("depth.png"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(".tiff"), std::string::npos) << "names the format to use";
  EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
  EXPECT_FALSE(fs::exists(path("frame.png")));
  EXPECT_FALSE(fs::exists(path("depth.png")));
}

TEST_F(RenderCli, AtlasNaNTexelsAreInvalidAndInfiniteOnesAnError) {
  // Left half NaN (invalid, as norm2tex_bake writes), right half a height of 1.
  cv::Mat1f atlas(64, 64, 1.0f);
  atlas(cv::Rect(0, 0, 32, 64)).setTo(std::numeric_limits<float>::quiet_NaN());
  cv::imwrite(path("nan.tiff"), atlas);
  const CliRun run =
      render(std::string(kBall) + " --atlas " + path("nan.tiff") + " --beta 0.2 -o " +
             path("frame.png") + " --depth-out " + path("depth.tiff"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const cv::Mat depth = cv::imread(path("depth.tiff"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(depth.type(), CV_32FC1);
  EXPECT_TRUE(cv::checkRange(depth)) << "no NaN depth";
  double max_depth = 0;
  cv::minMaxLoc(depth, nullptr, &max_depth);
  EXPECT_LT(max_depth, 1.0e-3 + 0.2e-3 + 0.15e-3) << "press + beta at most, never a slab";

  atlas(cv::Rect(40, 10, 3, 3)).setTo(std::numeric_limits<float>::infinity());
  cv::imwrite(path("inf.tiff"), atlas);
  const CliRun bad =
      render(std::string(kBall) + " --atlas " + path("inf.tiff") + " -o " + path("bad.png"));
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_NE(bad.output.find("infinite"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(path("bad.png")));
}

TEST_F(RenderCli, BetaZeroBakesNothing) {
  // A texture at beta 0 is the textureless render: nothing is baked (no cache entry), the image
  // is the one without a texture bit for bit, and the normal map is not even read.
  const CliRun zero = render(std::string(kBall) + " --normal-map " + path("ridges.png") +
                             " --beta 0 --no-noise -o " + path("zero.png"));
  ASSERT_EQ(zero.exit_code, 0) << zero.output;
  EXPECT_NE(zero.output.find("textureless"), std::string::npos) << zero.output;
  EXPECT_EQ(zero.output.find("texture:"), std::string::npos) << "nothing loaded: " << zero.output;
  EXPECT_TRUE(!fs::exists(path("cache")) || fs::is_empty(path("cache"))) << "nothing baked";
  const CliRun plain = render(std::string(kBall) + " --no-noise -o " + path("plain.png"));
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  const cv::Mat zero_image = cv::imread(path("zero.png")),
                plain_image = cv::imread(path("plain.png"));
  ASSERT_FALSE(zero_image.empty());
  EXPECT_EQ(cv::norm(zero_image, plain_image, cv::NORM_INF), 0.0);
  std::ofstream(path("broken.png")) << "not a png";
  EXPECT_EQ(render(std::string(kBall) + " --normal-map " + path("broken.png") + " --beta 0 -o " +
                   path("broken_zero.png"))
                .exit_code,
            0);
  // The same texture at beta 0.2 is baked (one cache entry) and shows.
  const CliRun textured = render(std::string(kBall) + " --normal-map " + path("ridges.png") +
                                 " --beta 0.2 --no-noise -o " + path("textured.png"));
  ASSERT_EQ(textured.exit_code, 0) << textured.output;
  EXPECT_FALSE(fs::is_empty(path("cache")));
  EXPECT_GT(cv::norm(cv::imread(path("textured.png")), plain_image, cv::NORM_L1), 0.0);
}

TEST_F(RenderCli, ForceSetsTheTextureOnlyWithConformityOn) {
  const std::string textured =
      std::string(kBall) + " --normal-map " + path("ridges.png") + " --beta 0.1 --no-noise";
  const auto image = [&](const std::string& options, const std::string& name) {
    const CliRun run = render(textured + " " + options + " -o " + path(name));
    EXPECT_EQ(run.exit_code, 0) << run.output;
    return cv::imread(path(name));
  };
  // Off: the force changes nothing, bit for bit.
  const cv::Mat off = image("--conformity off", "off.png");
  EXPECT_EQ(cv::norm(off, image("--conformity off --force-n 0.2", "off_light.png"), cv::NORM_INF),
            0.0);
  // On (the default sensor's): a light and a firm force give different frames, and the tool
  // reports the model.
  const CliRun on = render(textured + " --force-n 0.2 -o " + path("light.png"));
  ASSERT_EQ(on.exit_code, 0) << on.output;
  EXPECT_NE(on.output.find("conformity: 0.2 N"), std::string::npos) << on.output;
  EXPECT_GT(cv::norm(cv::imread(path("light.png")), image("--force-n 50", "firm.png"),
                     cv::NORM_L1),
            0.0);
  EXPECT_EQ(cv::norm(cv::imread(path("light.png")),
                     image("--conformity on --force-n 0.2", "light_on.png"), cv::NORM_INF),
            0.0);
  // Bad force or switch: a one-line error, a usage error.
  const CliRun negative = render(textured + " --conformity on --force-n -1 -o " + path("x.png"));
  EXPECT_EQ(negative.exit_code, 1) << negative.output;
  EXPECT_NE(negative.output.find("normal force"), std::string::npos) << negative.output;
  EXPECT_EQ(render(textured + " --conformity maybe -o " + path("x.png")).exit_code, 2);
  EXPECT_FALSE(fs::exists(path("x.png")));
}

// --shear pushes the markers along the push (the CSV they are written to, and the image: a dot
// where the shear carried it), prints the slip; the shear sheet has one column per load; bad
// loads and options that do not go together are usage errors.
TEST_F(RenderCli, ShearMovesTheMarkersAndBadLoadsAreUsageErrors) {
  const std::string ball = "--mesh sphere:5 --pose \"0 0 0.005 0 0 0\" --press-mm 1 --force-n 3";
  const CliRun run = render(ball + " --no-noise --markers on --shear 1,0 -o " + path("f.png") +
                            " --markers-out " + path("m.csv"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("of the contact slips"), std::string::npos) << run.output;
  std::ifstream csv(path("m.csv"));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "rest_x_px,rest_y_px,current_x_px,current_y_px,displacement_x_mm,"
                  "displacement_y_mm");
  int rows = 0;
  double largest_x = 0.0, largest_y = 0.0;
  while (std::getline(csv, line)) {
    double v[6];
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf", v, v + 1, v + 2, v + 3, v + 4,
                          v + 5),
              6)
        << line;
    EXPECT_GE(v[4], 0.0) << "every marker moves along +x, or not at all: " << line;
    largest_x = std::max(largest_x, v[4]);
    largest_y = std::max(largest_y, std::abs(v[5]));
    ++rows;
  }
  EXPECT_EQ(rows, 63) << "the built-in 9 x 7 grid";
  EXPECT_GT(largest_x, 0.05);
  EXPECT_LT(largest_y, 0.2 * largest_x);
  const CliRun sheet = render(ball + " --shear-sheet --loads \"0,0;1,0;0,0,0.002\" -o " +
                              path("sheet.png"));
  ASSERT_EQ(sheet.exit_code, 0) << sheet.output;
  const cv::Mat tiles = cv::imread(path("sheet.png"));
  EXPECT_GT(tiles.cols, 3 * 240) << "three columns";
  EXPECT_LT(tiles.cols, 4 * 240);
  for (const std::string& bad :
       {std::string(" --shear 1"), std::string(" --shear 1,x"), std::string(" --shear 1,nan"),
        std::string(" --markers maybe"), std::string(" --markers-out ") + path("m2.csv"),
        std::string(" --loads \"1,0\""), std::string(" --shear-sheet"),
        std::string(" --shear-sheet --shear 1,0 --loads \"1,0\"")}) {
    const CliRun r = render(ball + bad + " -o " + path("bad.png"));
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.output;
  }
  EXPECT_FALSE(fs::exists(path("bad.png")));
  const CliRun friction = render(ball + " --shear 1,0 --friction 0 -o " + path("bad.png"));
  EXPECT_EQ(friction.exit_code, 1) << friction.output;
  EXPECT_NE(friction.output.find("friction"), std::string::npos) << friction.output;
}

// The second sensor: --sensor config/gelsight_mini.yaml renders its landscape 320 x 240 frame,
// the contact under the ball at its own scale, the press visible against its no-contact frame,
// and its own 7 x 9 marker grid.
TEST_F(RenderCli, AGelSightMiniPressIsLandscapeWithTheContactUnderTheBall) {
  const std::string mini = " --sensor " NORM2TEX_SOURCE_DIR "/config/gelsight_mini.yaml --no-noise";
  const CliRun run = render("--mesh sphere:4 --pose \"0.003 -0.002 0.004 0 0 0\" --press-mm 1" +
                            mini + " -o " + path("mini.png") + " --mask-out " + path("mask.png") +
                            " --markers-out " + path("markers.csv"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const CliRun rest =
      render("--mesh sphere:4 --pose \"0 0 0.01 0 0 0\"" + mini + " -o " + path("rest.png"));
  ASSERT_EQ(rest.exit_code, 0) << rest.output;
  const cv::Mat3b frame = cv::imread(path("mini.png")), background = cv::imread(path("rest.png"));
  const cv::Mat1b mask = cv::imread(path("mask.png"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(frame.size(), cv::Size(320, 240));
  ASSERT_EQ(background.size(), cv::Size(320, 240));
  ASSERT_EQ(mask.size(), cv::Size(320, 240));
  const norm2tex::SensorModel mini_model =
      norm2tex::loadSensorModel(NORM2TEX_SOURCE_DIR "/config/gelsight_mini.yaml");
  const cv::Moments m = cv::moments(mask, true);
  ASSERT_GT(m.m00, 500.0);
  EXPECT_NEAR(m.m10 / m.m00, 159.5 + 3.0 / mini_model.mm_per_pixel, 1.5) << "x = +3 mm: right";
  EXPECT_NEAR(m.m01 / m.m00, 119.5 - 2.0 / mini_model.mm_per_pixel, 1.5) << "y = -2 mm: up";
  // The press shows inside the contact, and nowhere far from it.
  cv::Mat diff;
  cv::absdiff(frame, background, diff);
  cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
  EXPECT_GT(cv::mean(diff, mask)[0], 5.0);
  cv::Mat1b far;
  cv::dilate(mask, far, cv::Mat(), {-1, -1}, 25);
  cv::bitwise_not(far, far);
  EXPECT_EQ(cv::countNonZero(diff & far), 0);
  std::ifstream csv(path("markers.csv"));
  std::string line;
  int markers = -1;  // the header
  while (std::getline(csv, line)) ++markers;
  EXPECT_EQ(markers, 7 * 9) << "the Mini's grid, not the built-in 9 x 7";
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
