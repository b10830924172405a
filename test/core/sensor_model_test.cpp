#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "norm2tex/common/error.hpp"
#include "norm2tex/render/digit_shader_response.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/render/synthetic_background.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

// config/digit.yaml is the calibrated s09 unit: the built-in defaults carry its shading, and
// its own scale and background.
TEST(SensorModel, ShippedConfigLoadsAndMatchesTheDefaults) {
  const SensorModel shipped = loadSensorModel(NORM2TEX_SOURCE_DIR "/config/digit.yaml");
  const SensorModel defaults = makeDigitSensorModel();
  EXPECT_EQ(shipped.rows, 320);
  EXPECT_EQ(shipped.cols, 240);
  EXPECT_DOUBLE_EQ(shipped.mm_per_pixel, 0.0532);
  EXPECT_NEAR(defaults.mm_per_pixel, 0.054, 1e-12);  // the measured 17-19.6 px/mm
  EXPECT_EQ(shipped.leds[0].name, "red");
  EXPECT_EQ(shipped.leds[0].position_mm, defaults.leds[0].position_mm);
  EXPECT_EQ(shipped.gel.pyramid_sigmas_mm, defaults.gel.pyramid_sigmas_mm);
  EXPECT_EQ(shipped.gel.final_sigma_mm, defaults.gel.final_sigma_mm);
  EXPECT_EQ(shipped.shading.kind, ShadingKind::kCalibrated);
  EXPECT_EQ(shipped.shading.shadow_sigma_mm, defaults.shading.shadow_sigma_mm);
  EXPECT_EQ(shipped.shading.slope_saturation, defaults.shading.slope_saturation);
  EXPECT_EQ(shipped.conformity.coating_length_mm, defaults.conformity.coating_length_mm);
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < kShadingFeatureCount; ++j) {
      EXPECT_NEAR(shipped.shading.response_bgr[k][j], defaults.shading.response_bgr[k][j], 1e-9)
          << "channel " << k << " feature " << j;
    }
  }
  EXPECT_EQ(shipped.noise.sigma_bgr, defaults.noise.sigma_bgr);
  EXPECT_FALSE(shipped.noise.on_real_background);
  EXPECT_EQ(shipped.background_image, NORM2TEX_SOURCE_DIR "/config/digit_s09_background.png");
}

// Real units brighten red at the upper right of a press, green at its left and blue below:
// the analytic preset's LEDs sit on those sides.
TEST(SensorModel, AnalyticLedsSitWhereRealPressesBrightenEachColour) {
  const SensorModel m = makeDigitSensorModel();
  const auto angle = [](const LedModel& led) {
    return std::atan2(led.position_mm[1], led.position_mm[0]) * 180.0 / CV_PI;
  };
  EXPECT_EQ(m.leds[0].name, "red");
  EXPECT_NEAR(angle(m.leds[0]), -40.0, 15.0);  // real: -31 to -52 degrees (0 right, 90 down)
  EXPECT_EQ(m.leds[1].name, "green");
  EXPECT_NEAR(angle(m.leds[1]), -155.0, 15.0);  // real: -146 to -163
  EXPECT_EQ(m.leds[2].name, "blue");
  EXPECT_NEAR(angle(m.leds[2]), 70.0, 25.0);  // real: 57 to 84
}

TEST(SensorModel, SavedModelLoadsBackTheSame) {
  test::ScratchDirectory dir;
  SensorModel m = makeDigitSensorModel();
  m.mm_per_pixel = 0.0517;
  m.shading.response_bgr[1][3] = -12.25;
  m.shading.shadow_sigma_mm = 0.45;
  m.noise.sigma_bgr = {3.0, 1.25, 2.0};
  m.noise.correlation_gr = -0.3;
  m.gel.pyramid_sigmas_mm = {0.6, 0.2};
  m.gel_pad_width_mm = 18.35;
  m.background_image = "bg.png";
  saveSensorModel(m, dir.path("saved.yaml"));
  const SensorModel loaded = loadSensorModel(dir.path("saved.yaml"));
  EXPECT_DOUBLE_EQ(loaded.mm_per_pixel, 0.0517);
  EXPECT_DOUBLE_EQ(loaded.shading.response_bgr[1][3], -12.25);
  EXPECT_EQ(loaded.shading.response_bgr, m.shading.response_bgr);
  EXPECT_DOUBLE_EQ(loaded.shading.shadow_sigma_mm, 0.45);
  EXPECT_EQ(loaded.noise.sigma_bgr, m.noise.sigma_bgr);
  EXPECT_DOUBLE_EQ(loaded.noise.correlation_gr, -0.3);
  EXPECT_EQ(loaded.gel.pyramid_sigmas_mm, m.gel.pyramid_sigmas_mm);
  EXPECT_DOUBLE_EQ(loaded.gel_pad_width_mm, 18.35);
  EXPECT_EQ(loaded.leds[1].position_mm, m.leds[1].position_mm);
  EXPECT_EQ(loaded.background_image, dir.path("bg.png")) << "relative to the yaml";
}

// A response belongs with the slope saturation it was fitted with: a yaml that gives one without
// the other (every calibrated yaml written before the option) was fitted on the slopes
// themselves; one that gives neither keeps the built-in pair; a saved model keeps its own.
TEST(SensorModel, AResponseWithoutItsSlopeSaturationWasFittedWithoutOne) {
  test::ScratchDirectory dir;
  std::ofstream(dir.path("old.yaml")) << "shading:\n  response:\n    blue: [" << [] {
    std::string values;
    for (int j = 0; j < kShadingFeatureCount; ++j) values += (j ? ", " : "") + std::to_string(j);
    return values;
  }() << "]\n";
  EXPECT_EQ(loadSensorModel(dir.path("old.yaml")).shading.slope_saturation, 0.0);
  std::ofstream(dir.path("neither.yaml")) << "shading:\n  gain: 1.0\n";
  EXPECT_EQ(loadSensorModel(dir.path("neither.yaml")).shading.slope_saturation,
            kDefaultSlopeSaturation);
  SensorModel m = makeDigitSensorModel();
  m.shading.slope_saturation = 0.7;
  saveSensorModel(m, dir.path("saved.yaml"));
  EXPECT_EQ(loadSensorModel(dir.path("saved.yaml")).shading.slope_saturation, 0.7);
  std::ofstream(dir.path("bad.yaml")) << "shading:\n  slope_saturation: 0.01\n";
  test::expectError([&] { loadSensorModel(dir.path("bad.yaml")); },
                    {"shading.slope_saturation", "0 (none) or [0.05, 20]"});
}

TEST(SensorModel, UnknownKeysAreErrorsNamingTheKey) {
  test::ScratchDirectory dir;
  const auto expectUnknown = [&](const std::string& yaml, const std::string& key) {
    std::ofstream(dir.path("typo.yaml")) << yaml;
    test::expectError([&] { loadSensorModel(dir.path("typo.yaml")); },
                      {"typo.yaml", "unknown key '" + key + "'"});
  };
  expectUnknown("mm_per_pixel: 0.05\n", "mm_per_pixel");  // belongs under image:
  expectUnknown("image: {mm_per_pixle: 0.05}\n", "image.mm_per_pixle");
  expectUnknown("noise_sigma: 2\n", "noise_sigma");  // replaced by noise.sigma_bgr
  expectUnknown("noise: {sigma: 2}\n", "noise.sigma");
  expectUnknown("shading: {gain: 1, modle: calibrated}\n", "shading.modle");
  expectUnknown("shading: {response: {alpha: [1]}}\n", "shading.response.alpha");
  expectUnknown("gel_model: {core: 0.4}\n", "gel_model.core");
  expectUnknown("leds: [{name: a, colour: [1, 0, 0]}, {name: b}, {name: c}]\n", "leds[].colour");
}

// The marker grid and the gel's shear section: off by default (a DIGIT has no markers), read,
// saved and loaded back, and every bad value named.
TEST(SensorModel, MarkersAndShearLoadSaveAndRejectBadValues) {
  test::ScratchDirectory dir;
  EXPECT_FALSE(makeDigitSensorModel().markers.enabled);
  EXPECT_FALSE(loadSensorModel(NORM2TEX_SOURCE_DIR "/config/digit.yaml").markers.enabled);
  std::ofstream(dir.path("markers.yaml"))
      << "markers: {enabled: true, rows: 5, cols: 6, pitch_mm: 1.2, dot_diameter_mm: 0.4,\n"
         "  darkness: 0.5, blur_mm: 0.03, jitter_mm: 0.05, seed: 7, offset_mm: [0.1, -0.2]}\n"
         "shear: {shear_modulus_mpa: 0.3, friction: 0.8}\n";
  const SensorModel m = loadSensorModel(dir.path("markers.yaml"));
  EXPECT_TRUE(m.markers.enabled);
  EXPECT_EQ(m.markers.rows, 5);
  EXPECT_EQ(m.markers.cols, 6);
  EXPECT_DOUBLE_EQ(m.markers.pitch_mm, 1.2);
  EXPECT_DOUBLE_EQ(m.markers.dot_diameter_mm, 0.4);
  EXPECT_DOUBLE_EQ(m.markers.darkness, 0.5);
  EXPECT_DOUBLE_EQ(m.markers.jitter_mm, 0.05);
  EXPECT_EQ(m.markers.seed, 7);
  EXPECT_DOUBLE_EQ(m.markers.offset_mm[1], -0.2);
  EXPECT_DOUBLE_EQ(m.shear.shear_modulus_mpa, 0.3);
  EXPECT_DOUBLE_EQ(m.shear.friction, 0.8);
  saveSensorModel(m, dir.path("saved.yaml"));
  const SensorModel loaded = loadSensorModel(dir.path("saved.yaml"));
  EXPECT_TRUE(loaded.markers.enabled);
  EXPECT_EQ(loaded.markers.cols, 6);
  EXPECT_DOUBLE_EQ(loaded.markers.blur_mm, 0.03);
  EXPECT_DOUBLE_EQ(loaded.markers.offset_mm[0], 0.1);
  EXPECT_DOUBLE_EQ(loaded.shear.friction, 0.8);
  const auto expectBad = [&](const std::string& yaml, std::vector<std::string> words) {
    std::ofstream(dir.path("bad.yaml")) << yaml;
    test::expectError([&] { loadSensorModel(dir.path("bad.yaml")); }, words);
  };
  expectBad("markers: {rows: 0}\n", {"markers.rows", "[1, 200]"});
  expectBad("markers: {pitch_mm: 1.0, dot_diameter_mm: 1.2}\n",
            {"markers.dot_diameter_mm", "pitch_mm"});
  expectBad("markers: {darkness: 1.5}\n", {"markers.darkness", "[0, 1]"});
  expectBad("markers: {offset_mm: [1]}\n", {"markers.offset_mm", "2 numbers"});
  expectBad("markers: {pitch: 1}\n", {"unknown key 'markers.pitch'"});
  expectBad("shear: {shear_modulus_mpa: -1}\n", {"shear.shear_modulus_mpa", "(0, 100] MPa"});
  expectBad("shear: {friction: .nan}\n", {"shear.friction"});
}

// The synthetic frame's look: the DIGIT's by default (a yaml without the section keeps it), a
// yaml's own replaces it (its glows the whole list), saved and loaded back, bad values named.
TEST(SensorModel, SyntheticBackgroundLoadsSavesAndRejectsBadValues) {
  test::ScratchDirectory dir;
  const SyntheticBackgroundOptions digit;
  ASSERT_EQ(digit.glows.size(), 4u);
  std::ofstream(dir.path("none.yaml")) << "image: {mm_per_pixel: 0.05}\n";
  const SensorModel without = loadSensorModel(dir.path("none.yaml"));
  EXPECT_EQ(without.synthetic_background.base_bgr, digit.base_bgr);
  ASSERT_EQ(without.synthetic_background.glows.size(), 4u);
  EXPECT_EQ(without.synthetic_background.glows[2].centre_uv, digit.glows[2].centre_uv);
  // digit.yaml spells the defaults out.
  const SyntheticBackgroundOptions shipped =
      loadSensorModel(NORM2TEX_SOURCE_DIR "/config/digit.yaml").synthetic_background;
  EXPECT_EQ(shipped.base_bgr, digit.base_bgr);
  EXPECT_EQ(shipped.vignette_strength, digit.vignette_strength);
  EXPECT_EQ(shipped.vignette_power, digit.vignette_power);
  ASSERT_EQ(shipped.glows.size(), digit.glows.size());
  for (std::size_t j = 0; j < digit.glows.size(); ++j) {
    EXPECT_EQ(shipped.glows[j].centre_uv, digit.glows[j].centre_uv) << j;
    EXPECT_EQ(shipped.glows[j].sigma_uv, digit.glows[j].sigma_uv) << j;
    EXPECT_EQ(shipped.glows[j].angle_rad, digit.glows[j].angle_rad) << j;
    EXPECT_EQ(shipped.glows[j].color_bgr, digit.glows[j].color_bgr) << j;
  }

  std::ofstream(dir.path("own.yaml"))
      << "synthetic_background:\n  base_bgr: [10, 20, 30]\n  vignette_strength: 0.5\n"
         "  glows:\n    - {centre_uv: [0.25, 1.5], sigma_uv: [0.5, 0.125], angle_rad: -0.75,\n"
         "       color_bgr: [40, 0, 60]}\n";
  SensorModel m = loadSensorModel(dir.path("own.yaml"));
  EXPECT_EQ(m.synthetic_background.base_bgr, cv::Vec3d(10, 20, 30));
  EXPECT_DOUBLE_EQ(m.synthetic_background.vignette_strength, 0.5);
  EXPECT_DOUBLE_EQ(m.synthetic_background.vignette_power, digit.vignette_power);  // not given
  ASSERT_EQ(m.synthetic_background.glows.size(), 1u);
  EXPECT_EQ(m.synthetic_background.glows[0].centre_uv, (std::array<double, 2>{0.25, 1.5}));
  EXPECT_DOUBLE_EQ(m.synthetic_background.glows[0].angle_rad, -0.75);
  saveSensorModel(m, dir.path("saved.yaml"));
  const SyntheticBackgroundOptions loaded =
      loadSensorModel(dir.path("saved.yaml")).synthetic_background;
  EXPECT_EQ(loaded.base_bgr, m.synthetic_background.base_bgr);
  ASSERT_EQ(loaded.glows.size(), 1u);
  EXPECT_EQ(loaded.glows[0].sigma_uv, m.synthetic_background.glows[0].sigma_uv);
  EXPECT_EQ(loaded.glows[0].color_bgr, m.synthetic_background.glows[0].color_bgr);
  // No glows at all: a plain vignetted base, saved as an empty list.
  m.synthetic_background.glows.clear();
  saveSensorModel(m, dir.path("plain.yaml"));
  EXPECT_TRUE(loadSensorModel(dir.path("plain.yaml")).synthetic_background.glows.empty());

  const auto expectBad = [&](const std::string& yaml, std::vector<std::string> words) {
    std::ofstream(dir.path("bad.yaml")) << yaml;
    test::expectError([&] { loadSensorModel(dir.path("bad.yaml")); }, words);
  };
  const std::string glow = "centre_uv: [0.5, 0.5], sigma_uv: [0.2, 0.2], angle_rad: 0, ";
  expectBad("synthetic_background: {base_bgr: [0, 300, 0]}\n",
            {"bad.yaml", "synthetic_background.base_bgr", "[0, 255]"});
  expectBad("synthetic_background: {vignette_strength: 1}\n",
            {"synthetic_background.vignette_strength", "[0, 1)"});
  expectBad("synthetic_background: {vignette_power: 0}\n", {"synthetic_background.vignette_power"});
  expectBad("synthetic_background: {glows: {centre_uv: [0, 0]}}\n", {"a list of glows"});
  expectBad("synthetic_background: {glows: [{centre_uv: [0.5, 0.5]}]}\n",
            {"synthetic_background.glows[0] needs sigma_uv"});
  expectBad("synthetic_background: {glows: [{" + glow + "color_bgr: [0, 0, 9]}, {" + glow +
                "color_bgr: [0, -1, 0]}]}\n",
            {"synthetic_background.glows[1].color_bgr", "[0, 255]"});
  expectBad("synthetic_background: {glows: [{" + glow + "color_bgr: [0, 0]}]}\n",
            {"synthetic_background.glows[0].color_bgr", "3 numbers"});
  expectBad("synthetic_background: {glows: [{centre_uv: [0.5, 0.5], sigma_uv: [0, 0.2], "
            "angle_rad: 0, color_bgr: [1, 1, 1]}]}\n",
            {"synthetic_background.glows[0].sigma_uv", "(0, 10]"});
  expectBad("synthetic_background: {glows: [{" + glow + "color_bgr: [1, 1, 1], colour: 1}]}\n",
            {"unknown key 'synthetic_background.glows[].colour'"});
  expectBad("synthetic_background: {base: [1, 1, 1]}\n",
            {"unknown key 'synthetic_background.base'"});
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
  expectError("noise: {sigma_bgr: [2, -1, 2]}\n", "noise.sigma_bgr");
  expectError("noise: {neighbour_correlation: 0.9}\n", "noise.neighbour_correlation");
  expectError("noise: {correlation_bg: 0.9, correlation_gr: 0.9, correlation_br: -0.9}\n",
              "positive definite");
  expectError("shading: {model: phong}\n", "analytic_leds");
  expectError("shading: {response: {blue: [1, 2, 3]}}\n", "shading.response.blue");
  expectError("shading: {shadow_sigma_mm: 0}\n", "shading.shadow_sigma_mm");
  expectError("preset: hd\n", "preset");
  expectError("leds: [{name: red}]\n", "3 LEDs");
  expectError("image: {rows: [1, 2]}\n", "bad.yaml");
  expectError("image: {rows: 320\n", "bad.yaml");  // broken yaml
  EXPECT_THROW(loadSensorModel(dir.path("missing.yaml")), Error);
}

}  // namespace
}  // namespace norm2tex
