#include <fstream>

#include <gtest/gtest.h>

#include "norm2tex/common/error.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

TEST(SensorModel, ShippedConfigLoadsAndMatchesTheDefaults) {
  const SensorModel shipped = loadSensorModel(NORM2TEX_SOURCE_DIR "/config/digit.yaml");
  const SensorModel defaults = makeDigitSensorModel();
  EXPECT_EQ(shipped.rows, 320);
  EXPECT_EQ(shipped.cols, 240);
  EXPECT_DOUBLE_EQ(shipped.mm_per_pixel, defaults.mm_per_pixel);
  EXPECT_EQ(shipped.leds[0].name, "red");
  EXPECT_EQ(shipped.leds[0].position_mm, defaults.leds[0].position_mm);
  EXPECT_EQ(shipped.gel.pyramid_sigmas_mm, defaults.gel.pyramid_sigmas_mm);
  EXPECT_TRUE(shipped.background_image.empty());
}

TEST(SensorModel, PixelCentresMapToTheGelFrame) {
  const SensorModel m = makeDigitSensorModel();
  const cv::Point2d top_left = m.pixelToGelMm(0, 0);
  EXPECT_DOUBLE_EQ(top_left.x, -0.5 * m.gelWidthMm() + 0.5 * m.mm_per_pixel);
  EXPECT_DOUBLE_EQ(top_left.y, -0.5 * m.gelHeightMm() + 0.5 * m.mm_per_pixel);
  const cv::Point2d centre = m.pixelToGelMm(159.5, 119.5);
  EXPECT_NEAR(centre.x, 0.0, 1e-12);
  EXPECT_NEAR(centre.y, 0.0, 1e-12);
}

TEST(SensorModel, VgaPresetKeepsTheGelAndHalvesThePixels) {
  test::ScratchDirectory dir;
  std::ofstream(dir.path("vga.yaml")) << "preset: vga\nbackground_image: my_bg.png\n";
  const SensorModel vga = loadSensorModel(dir.path("vga.yaml"));
  EXPECT_EQ(vga.rows, 640);
  EXPECT_EQ(vga.cols, 480);
  EXPECT_NEAR(vga.gelWidthMm(), makeDigitSensorModel().gelWidthMm(), 1e-9);
  EXPECT_EQ(vga.background_image, dir.path("my_bg.png")) << "relative to the yaml";
}

TEST(SensorModel, BadValuesNameTheFileAndKey) {
  test::ScratchDirectory dir;
  const auto expectError = [&](const std::string& yaml, const std::string& fragment) {
    std::ofstream(dir.path("bad.yaml")) << yaml;
    try {
      loadSensorModel(dir.path("bad.yaml"));
      ADD_FAILURE() << "accepted: " << yaml;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos) << e.what();
    }
  };
  expectError("image: {rows: 0}\n", "image.rows");
  expectError("image: {mm_per_pixel: -1}\n", "image.mm_per_pixel");
  expectError("noise_sigma: -2\n", "noise_sigma");
  expectError("preset: hd\n", "preset");
  expectError("leds: [{name: red}]\n", "3 LEDs");
  expectError("image: {rows: [1, 2]}\n", "bad.yaml");
  expectError("image: {rows: 320\n", "bad.yaml");  // broken yaml
  EXPECT_THROW(loadSensorModel(dir.path("missing.yaml")), Error);
}

}  // namespace
}  // namespace norm2tex
