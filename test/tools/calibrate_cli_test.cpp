// Runs the real norm2tex_calibrate executable on presses rendered with a known sensor: the yaml
// it writes loads and carries the fit, the background and report are written, the --json report
// holds every press and its medians, labels are used, a fitted scale comes with its profile, and
// bad input is a one-line error (exit 1) or the usage (exit 2).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include "cli_runner.hpp"
#include "norm2tex/calibrate/ball_press.hpp"
#include "norm2tex/render/digit_shader.hpp"
#include "norm2tex/render/gel_model.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/shear/marker_pattern.hpp"

namespace {

/// The gel of press i of a 6 mm ball (3 mm radius) whose contact circle is centred centre_mm from
/// the image centre, its radius growing with i (1.1 mm + 0.12 mm per press), and that circle.
std::pair<cv::Mat1f, norm2tex::PressCircle> ballPress(const norm2tex::SensorModel& m,
                                                      cv::Point2d centre_mm, int i) {
  const norm2tex::PressCircle circle{
      {centre_mm.x / m.mm_per_pixel + (m.cols - 1) / 2.0,
       centre_mm.y / m.mm_per_pixel + (m.rows - 1) / 2.0},
      (1.1 + 0.12 * i) / m.mm_per_pixel};
  cv::Mat1f gel;
  norm2tex::GelModel(m).apply(norm2tex::ballPressIndentation(m, circle, 3.0), gel);
  return {gel, circle};
}
using norm2tex::test::CliRun;

CliRun calibrate(const std::string& arguments) {
  return norm2tex::test::runCommand(NORM2TEX_CALIBRATE_EXECUTABLE, arguments);
}

// Six presses of a 6 mm ball rendered by the default sensor, written as PNGs with one
// no-contact frame; their true circles in labels.csv.
class CalibrateCli : public norm2tex::test::CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    const norm2tex::SensorModel m = norm2tex::makeDigitSensorModel();
    const norm2tex::DigitShader shader(m, norm2tex::makeSyntheticBackground(m),
                                       norm2tex::BackgroundSource::kSynthetic);
    const cv::Mat1f flat(m.rows, m.cols, 0.0f);
    cv::imwrite(path("bg.png"), shader.shade(flat, 1));
    std::ofstream labels(path("labels.csv"));
    labels << "file,centre_x_px,centre_y_px,radius_px\n";
    const cv::Point2d centres_mm[] = {{-3, -5}, {2, -4}, {0, 0}, {-2, 3}, {3, 4}, {1, 6}};
    for (int i = 0; i < 6; ++i) {
      const auto [gel, circle] = ballPress(m, centres_mm[i], i);
      const std::string name = "press" + std::to_string(i) + ".png";
      cv::imwrite(path(name), shader.shade(gel, 10 + i));
      presses_ += " " + path(name);
      labels << name << "," << circle.centre_px.x << "," << circle.centre_px.y << ","
             << circle.radius_px << "\n";
    }
  }
  std::string presses_;
};

TEST_F(CalibrateCli, WritesASensorYamlThatLoadsWithItsBackgroundAndAReport) {
  const CliRun run = calibrate("--background " + path("bg.png") + " --presses" + presses_ +
                               " --ball-diameter-mm 6 --mm-per-pixel 0.054 -o " +
                               path("mine.yaml") + " --report " + path("report.png"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("variance explained"), std::string::npos) << run.output;
  const norm2tex::SensorModel model = norm2tex::loadSensorModel(path("mine.yaml"));
  EXPECT_DOUBLE_EQ(model.mm_per_pixel, 0.054);
  EXPECT_EQ(model.shading.kind, norm2tex::ShadingKind::kCalibrated);
  EXPECT_EQ(model.background_image, path("mine_background.png"));
  const cv::Mat background = cv::imread(model.background_image);
  ASSERT_EQ(background.size(), cv::Size(240, 320));
  EXPECT_LT(cv::norm(background, cv::imread(path("bg.png")), cv::NORM_INF), 1.0);
  // The fitted response reproduces the renderer's own: same sign and similar size on the
  // strongest coefficient of each channel.
  const norm2tex::SensorModel truth = norm2tex::makeDigitSensorModel();
  for (int k = 0; k < 3; ++k) {
    int strongest = 0;
    for (int j = 0; j < norm2tex::kShadingFeatureCount; ++j) {
      if (std::abs(truth.shading.response_bgr[k][j]) >
          std::abs(truth.shading.response_bgr[k][strongest])) {
        strongest = j;
      }
    }
    EXPECT_GT(model.shading.response_bgr[k][strongest] / truth.shading.response_bgr[k][strongest],
              0.5)
        << "channel " << k;
  }
  const cv::Mat report = cv::imread(path("report.png"));
  EXPECT_EQ(report.cols, 3 * 160);
  EXPECT_GT(report.rows, 160);
}

// --judge fits nothing: the sensor that rendered the presses, judged on them, reproduces them
// (up to the noise drawn into each); a sensor whose shading is half as strong does not; the
// sensor yaml is not rewritten.
TEST_F(CalibrateCli, JudgeRendersAGivenSensorOnThePressesWithoutFitting) {
  norm2tex::SensorModel truth = norm2tex::makeDigitSensorModel();
  norm2tex::saveSensorModel(truth, path("truth.yaml"));
  truth.shading.gain = 0.5;
  norm2tex::saveSensorModel(truth, path("weak.yaml"));
  const std::string common =
      " --background " + path("bg.png") + " --presses" + presses_ + " --ball-diameter-mm 6";
  const CliRun run = calibrate("--judge " + path("truth.yaml") + common + " --json " +
                               path("judged.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("judged on 6 presses"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("nothing fitted (judged); 6 presses held out"), std::string::npos)
      << run.output;
  const auto explained = [](const std::string& output) {
    const std::string key = "variance explained ";
    const size_t at = output.find(key);
    return at == std::string::npos ? -1.0 : std::stod(output.substr(at + key.size()));
  };
  EXPECT_GT(explained(run.output), 0.95) << run.output;
  const YAML::Node report = YAML::LoadFile(path("judged.json"));  // JSON is YAML
  EXPECT_TRUE(report["judged"].as<bool>());
  EXPECT_TRUE(report["fitted"].IsNull());
  EXPECT_EQ(report["held_out"]["presses"].as<int>(), 6);
  EXPECT_EQ(report["presses"].size(), 6u);
  const CliRun weak = calibrate("--judge " + path("weak.yaml") + common);
  ASSERT_EQ(weak.exit_code, 0) << weak.output;
  EXPECT_LT(explained(weak.output), explained(run.output) - 0.1) << weak.output;
  EXPECT_FALSE(std::filesystem::exists(path("truth_background.png")));
  // Fitting options have no place in a judgement: usage errors.
  EXPECT_EQ(calibrate("--judge " + path("truth.yaml") + common + " -o " + path("x.yaml"))
                .exit_code,
            2);
  EXPECT_EQ(calibrate("--judge " + path("truth.yaml") + common + " --holdout 0.5").exit_code, 2);
  const CliRun missing = calibrate("--judge " + path("none.yaml") + common);
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_NE(missing.output.find("none.yaml"), std::string::npos) << missing.output;
}

// A landscape sensor: presses rendered by the GelSight Mini profile (320 x 240) calibrate with
// --sensor config/gelsight_mini.yaml into a yaml of the same size, gel and grid: its dots, drawn
// into every frame as the renderer draws them, are found, filled in before the fit and measured
// back (grid, pitch, diameter); without its yaml the frames are refused as not a DIGIT's, naming
// the way out.
TEST_F(CalibrateCli, AGelSightMiniCalibratesFromLandscapeFramesWithItsYaml) {
  const std::string mini_yaml = NORM2TEX_SOURCE_DIR "/config/gelsight_mini.yaml";
  const norm2tex::SensorModel m = norm2tex::loadSensorModel(mini_yaml);
  ASSERT_EQ(m.imageSize(), cv::Size(320, 240));
  const norm2tex::DigitShader shader(m, norm2tex::makeSyntheticBackground(m),
                                     norm2tex::BackgroundSource::kSynthetic);
  const norm2tex::MarkerPattern pattern(m);
  std::vector<norm2tex::Marker> rest;
  for (const cv::Point2f& p : pattern.restPx()) rest.push_back({p, p, {0, 0}});
  const auto marked = [&](const cv::Mat3b& frame) {
    cv::Mat3b copy = frame.clone();
    pattern.draw(copy, rest);  // a pure press leaves the dots where they are
    return copy;
  };
  const cv::Mat3b bg = shader.shade(cv::Mat1f(m.rows, m.cols, 0.0f), 1);
  cv::imwrite(path("mini_bg.png"), marked(bg));
  cv::imwrite(path("plain_bg.png"), bg);
  std::string plain_presses;
  std::string presses;
  const cv::Point2d centres_mm[] = {{-5, -3}, {4, -3}, {0, 0}, {-3, 3}, {5, 3}, {1, -4}};
  for (int i = 0; i < 6; ++i) {
    const cv::Mat1f gel = ballPress(m, centres_mm[i], i).first;
    const std::string name = path("mini_press" + std::to_string(i) + ".png");
    const cv::Mat3b press = shader.shade(gel, 20 + i);
    cv::imwrite(name, marked(press));
    presses += " " + name;
    const std::string plain = path("plain_press" + std::to_string(i) + ".png");
    cv::imwrite(plain, press);
    plain_presses += " " + plain;
  }
  const std::string frames = "--background " + path("mini_bg.png") + " --presses" + presses +
                             " --ball-diameter-mm 6 --mm-per-pixel 0.0634";
  const CliRun run = calibrate(frames + " --sensor " + mini_yaml + " -o " + path("my_mini.yaml"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const norm2tex::SensorModel fitted = norm2tex::loadSensorModel(path("my_mini.yaml"));
  EXPECT_EQ(fitted.imageSize(), cv::Size(320, 240));
  EXPECT_EQ(fitted.shading.kind, norm2tex::ShadingKind::kCalibrated);
  EXPECT_DOUBLE_EQ(fitted.gel_pad_width_mm, m.gel_pad_width_mm);
  EXPECT_NE(run.output.find("markers: 63 found, a 7 x 9 grid"), std::string::npos) << run.output;
  EXPECT_TRUE(fitted.markers.enabled);
  EXPECT_EQ(fitted.markers.rows, 7);
  EXPECT_EQ(fitted.markers.cols, 9);
  EXPECT_NEAR(fitted.markers.pitch_mm, m.markers.pitch_mm, 0.03 * m.markers.pitch_mm);
  EXPECT_NEAR(fitted.markers.dot_diameter_mm, m.markers.dot_diameter_mm,
              0.1 * m.markers.dot_diameter_mm);
  // The held-out presses are explained as well as the same presses without dots.
  const auto heldOutVariance = [](const std::string& output) {
    const size_t at = output.find("    variance explained ");
    return at == std::string::npos ? -1.0 : std::stod(output.substr(at + 23));
  };
  const CliRun plain = calibrate("--background " + path("plain_bg.png") + " --presses" +
                                 plain_presses + " --ball-diameter-mm 6 --mm-per-pixel 0.0634" +
                                 " --sensor " + mini_yaml + " -o " + path("plain_mini.yaml"));
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  EXPECT_EQ(plain.output.find("markers:"), std::string::npos) << plain.output;
  EXPECT_GT(heldOutVariance(plain.output), 0.5) << plain.output;
  EXPECT_NEAR(heldOutVariance(run.output), heldOutVariance(plain.output), 0.03)
      << run.output << plain.output;
  EXPECT_EQ(cv::imread(fitted.background_image).size(), cv::Size(320, 240));
  const CliRun digit = calibrate(frames + " -o " + path("x.yaml"));
  EXPECT_EQ(digit.exit_code, 1) << digit.output;
  EXPECT_NE(digit.output.find("landscape"), std::string::npos) << digit.output;
  EXPECT_NE(digit.output.find("--sensor"), std::string::npos) << digit.output;
}

// Two frames of the ball moved 8 mm between them measure the scale, which the fit then uses as
// given; the scale is given once.
TEST_F(CalibrateCli, TwoPressesAKnownDistanceApartGiveTheScale) {
  const norm2tex::SensorModel m = norm2tex::makeDigitSensorModel();
  const norm2tex::DigitShader shader(m, norm2tex::makeSyntheticBackground(m),
                                     norm2tex::BackgroundSource::kSynthetic);
  for (const double x_mm : {-4.0, 4.0}) {
    const norm2tex::PressCircle circle{{x_mm / m.mm_per_pixel + 119.5, 159.5},
                                       1.5 / m.mm_per_pixel};
    cv::Mat1f gel;
    norm2tex::GelModel(m).apply(norm2tex::ballPressIndentation(m, circle, 3.0), gel);
    cv::imwrite(path(x_mm < 0 ? "left.png" : "right.png"), shader.shade(gel, 30));
  }
  const std::string common = "--background " + path("bg.png") + " --presses" + presses_ +
                             " --ball-diameter-mm 6 -o " + path("scaled.yaml") +
                             " --scale-presses " + path("left.png") + " " + path("right.png");
  const CliRun run = calibrate(common + " --scale-distance-mm 8");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("scale from the two presses"), std::string::npos) << run.output;
  const double scale = norm2tex::loadSensorModel(path("scaled.yaml")).mm_per_pixel;
  EXPECT_NEAR(scale / m.mm_per_pixel, 1.0, 0.01) << run.output;
  EXPECT_EQ(calibrate(common).exit_code, 2);  // without its distance
  EXPECT_EQ(calibrate(common + " --scale-distance-mm 8 --mm-per-pixel 0.05").exit_code, 2);
  const CliRun same = calibrate("--background " + path("bg.png") + " --presses" + presses_ +
                                " --ball-diameter-mm 6 -o " + path("x.yaml") + " --scale-presses " +
                                path("left.png") + " " + path("left.png") +
                                " --scale-distance-mm 8");
  EXPECT_EQ(same.exit_code, 1) << same.output;
  EXPECT_NE(same.output.find("too close"), std::string::npos) << same.output;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// The --json report, read back with yaml-cpp (a reader independent of the package's writer;
// tests/python's calibration test reads the real presses' report with Python's strict json).
TEST_F(CalibrateCli, JsonReportHoldsEveryPressAndTheirMedians) {
  const CliRun run = calibrate("--background " + path("bg.png") + " --presses" + presses_ +
                               " --ball-diameter-mm 6 --mm-per-pixel 0.054 --labels " +
                               path("labels.csv") + " --holdout 0.5 -o " + path("mine.yaml") +
                               " --json " + path("report.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("frames, median SSIM"), std::string::npos) << run.output;
  const YAML::Node report = YAML::LoadFile(path("report.json"));
  EXPECT_DOUBLE_EQ(report["ball_diameter_mm"].as<double>(), 6.0);
  EXPECT_DOUBLE_EQ(report["mm_per_pixel"].as<double>(), 0.054);
  const YAML::Node presses = report["presses"];
  ASSERT_TRUE(presses.IsSequence());
  ASSERT_EQ(presses.size(), 6u);
  const char* measures[] = {"ssim", "contact_ssim", "psnr_db", "mean_abs_diff"};
  std::vector<double> held_out_values[4], fitted_values[4];
  for (size_t i = 0; i < presses.size(); ++i) {
    const YAML::Node press = presses[i];
    // In input order, each labelled: its circle is the label's.
    EXPECT_EQ(press["image"].as<std::string>(), path("press" + std::to_string(i) + ".png"));
    EXPECT_TRUE(press["labelled"].as<bool>());
    const double radius_px = press["radius_px"].as<double>();
    EXPECT_NEAR(radius_px * 0.054, 1.1 + 0.12 * static_cast<double>(i), 1e-4);
    for (const char* key : {"centre_x_px", "centre_y_px", "contact_radius_px", "depth_mm"}) {
      EXPECT_TRUE(press[key].IsScalar()) << key;
    }
    const double a = press["contact_radius_px"].as<double>() * 0.054;
    EXPECT_NEAR(press["depth_mm"].as<double>(), 3.0 - std::sqrt(9.0 - a * a), 1e-9);
    for (int m = 0; m < 4; ++m) {
      const double value = press[measures[m]].as<double>();
      (press["held_out"].as<bool>() ? held_out_values : fitted_values)[m].push_back(value);
      EXPECT_TRUE(press["bare_background"][measures[m]].IsScalar()) << measures[m];
    }
    // Rendered by the very model that made them (noise apart): close to the real frames.
    EXPECT_GT(press["ssim"].as<double>(), 0.8);
    EXPECT_GT(press["contact_ssim"].as<double>(), press["bare_background"]["contact_ssim"].as<double>());
  }
  ASSERT_EQ(held_out_values[0].size(), 3u);  // --holdout 0.5 of 6
  EXPECT_EQ(report["held_out"]["presses"].as<int>(), 3);
  EXPECT_EQ(report["fitted"]["presses"].as<int>(), 3);
  EXPECT_GT(report["held_out"]["variance_explained"].as<double>(), 0.8);
  for (int m = 0; m < 4; ++m) {
    EXPECT_DOUBLE_EQ(report["held_out"]["median"][measures[m]].as<double>(),
                     median(held_out_values[m]))
        << measures[m];
    EXPECT_DOUBLE_EQ(report["fitted"]["median"][measures[m]].as<double>(),
                     median(fitted_values[m]))
        << measures[m];
    EXPECT_TRUE(report["held_out"]["median_bare_background"][measures[m]].IsScalar());
  }
}

// A --json that cannot be written is refused before the fit, as a one-line error, and leaves
// no yaml behind.
TEST_F(CalibrateCli, AnUnwritableJsonPathIsAOneLineError) {
  const std::string arguments = "--background " + path("bg.png") + " --presses" + presses_ +
                                " --ball-diameter-mm 6 --mm-per-pixel 0.054 -o " +
                                path("unused.yaml") + " --json ";
  for (const std::string& bad :
       {path("bg.png") + "/report.json", path("no_such_dir") + "/report.json", dir_.string()}) {
    const CliRun run = calibrate(arguments + bad);
    EXPECT_EQ(run.exit_code, 1) << bad << "\n" << run.output;
    EXPECT_NE(run.output.find("JSON report '" + bad + "' cannot be written"), std::string::npos)
        << run.output;
    EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
  }
  EXPECT_FALSE(std::filesystem::exists(path("unused.yaml")));
}

// Without --mm-per-pixel the scale is fitted, and since ball presses pin it only weakly the
// tool prints how well each searched scale fits and the range that fits about as well.
TEST_F(CalibrateCli, WithoutTheScaleItPrintsHowWellEachScaleFits) {
  const CliRun run = calibrate("--background " + path("bg.png") + " --presses" + presses_ +
                               " --ball-diameter-mm 6 --labels " + path("labels.csv") + " -o " +
                               path("fitted.yaml"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("scale searched (mm/px: variance explained"), std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("scales within 0.01 of the best"), std::string::npos) << run.output;
  const norm2tex::SensorModel model = norm2tex::loadSensorModel(path("fitted.yaml"));
  EXPECT_GE(model.mm_per_pixel, 0.03);
  EXPECT_LE(model.mm_per_pixel, 0.1);
}

TEST_F(CalibrateCli, LabelsReplaceDetection) {
  const CliRun run = calibrate("--background " + path("bg.png") + " --presses" + presses_ +
                               " --ball-diameter-mm 6 --mm-per-pixel 0.054 --labels " +
                               path("labels.csv") + " -o " + path("labelled.yaml"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NO_THROW(norm2tex::loadSensorModel(path("labelled.yaml")));
  std::ofstream(path("bad_labels.csv")) << "press0.png,10,20\n";
  const CliRun bad = calibrate("--background " + path("bg.png") + " --presses" + presses_ +
                               " --ball-diameter-mm 6 --labels " + path("bad_labels.csv") + " -o " +
                               path("x.yaml"));
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_NE(bad.output.find("bad_labels.csv"), std::string::npos) << bad.output;
}

// Labels written on another machine: its absolute paths, CRLF line ends, a header line. They
// label the presses by base name; two presses of one base name make such a label ambiguous.
TEST_F(CalibrateCli, LabelsFromAnotherMachineMatchByBaseName) {
  {
    std::ifstream ours(path("labels.csv"));
    std::ofstream theirs(path("their_labels.csv"), std::ios::binary);
    std::string line;
    std::getline(ours, line);
    theirs << "image,center_x,center_y,radius\r\n";
    while (std::getline(ours, line)) theirs << "/home/someone/data/images/" << line << "\r\n";
  }
  const CliRun run = calibrate("--background " + path("bg.png") + " --presses" + presses_ +
                               " --ball-diameter-mm 6 --mm-per-pixel 0.054 --labels " +
                               path("their_labels.csv") + " -o " + path("theirs.yaml"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NO_THROW(norm2tex::loadSensorModel(path("theirs.yaml")));

  std::filesystem::create_directories(path("other"));
  std::filesystem::copy_file(path("press1.png"), path("other/press1.png"));
  const CliRun ambiguous =
      calibrate("--background " + path("bg.png") + " --presses" + presses_ + " " +
                path("other/press1.png") + " --ball-diameter-mm 6 --mm-per-pixel 0.054 --labels " +
                path("their_labels.csv") + " -o " + path("x.yaml"));
  EXPECT_EQ(ambiguous.exit_code, 1) << ambiguous.output;
  EXPECT_NE(ambiguous.output.find("by base name"), std::string::npos) << ambiguous.output;
  EXPECT_NE(ambiguous.output.find(path("other/press1.png")), std::string::npos) << ambiguous.output;
  EXPECT_EQ(std::count(ambiguous.output.begin(), ambiguous.output.end(), '\n'), 1)
      << ambiguous.output;
}

TEST_F(CalibrateCli, HelpPrintsTheUsageAndSucceeds) {
  for (const std::string flag : {"--help", "-h"}) {
    const CliRun run = calibrate(flag);
    EXPECT_EQ(run.exit_code, 0) << run.output;
    EXPECT_EQ(run.output.rfind("usage: norm2tex_calibrate", 0), 0u) << run.output;
  }
}

TEST_F(CalibrateCli, BadInputIsAOneLineErrorOrUsage) {
  const auto expectError = [&](const std::string& arguments, const std::string& fragment) {
    const CliRun run = calibrate(arguments);
    EXPECT_EQ(run.exit_code, 1) << arguments << "\n" << run.output;
    EXPECT_NE(run.output.find(fragment), std::string::npos) << run.output;
    EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
  };
  const std::string bg = " --background " + path("bg.png");
  // Landscape frames for a portrait sensor.
  cv::Mat landscape;
  cv::transpose(cv::imread(path("press0.png")), landscape);
  cv::imwrite(path("landscape.png"), landscape);
  expectError(bg + " --presses" + presses_ + " " + path("landscape.png") +
                  " --ball-diameter-mm 6 -o " + path("x.yaml"),
              "landscape");
  // A frame with no press.
  expectError(bg + " --presses" + presses_ + " " + path("bg.png") + " --ball-diameter-mm 6 -o " +
                  path("x.yaml"),
              "no press");
  // A ball too small for the contacts.
  expectError(bg + " --presses" + presses_ + " --ball-diameter-mm 1 --mm-per-pixel 0.054 -o " +
                  path("x.yaml"),
              "ball");
  // One press only.
  expectError(
      bg + " --presses " + path("press0.png") + " --ball-diameter-mm 6 -o " + path("x.yaml"),
      "at least 4");
  // A missing file is named.
  expectError(bg + " --presses" + presses_ + " " + path("missing.png") +
                  " --ball-diameter-mm 6 -o " + path("x.yaml"),
              "missing.png");
  const CliRun usage = calibrate(bg + " --presses" + presses_ + " -o " + path("x.yaml"));
  EXPECT_EQ(usage.exit_code, 2) << usage.output;
  EXPECT_NE(usage.output.find("--ball-diameter-mm"), std::string::npos) << usage.output;
  EXPECT_FALSE(std::filesystem::exists(path("x.yaml")));
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
