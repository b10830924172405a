// Calibration of the shading to a sensor: press detection, the ball's indentation, background
// noise measurement, a round trip through rendered presses, the real fixture presses of one
// DIGIT, and bad input.
#include <malloc.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "norm2tex/calibrate/background_noise.hpp"
#include "norm2tex/calibrate/ball_press.hpp"
#include "norm2tex/calibrate/calibration_report.hpp"
#include "norm2tex/calibrate/marker_detection.hpp"
#include "norm2tex/calibrate/press_detection.hpp"
#include "norm2tex/calibrate/press_labels.hpp"
#include "norm2tex/calibrate/press_refinement.hpp"
#include "norm2tex/calibrate/press_scale.hpp"
#include "norm2tex/calibrate/sensor_calibration.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/render/digit_shader.hpp"
#include "norm2tex/render/digit_shader_noise.hpp"
#include "norm2tex/render/gel_model.hpp"
#include "norm2tex/shear/marker_pattern.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

constexpr double kBallRadiusMm = 3.0;

// Keep freed frame-sized blocks in the heap (as norm2tex_calibrate does): the fits render
// thousands of presses, and fresh pages cost ~13 us each on these VMs.
const bool kHeapTuned = [] {
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
  return true;
}();

// A press frame rendered by `truth`: a ball of kBallRadiusMm whose contact is `circle`.
cv::Mat3b renderPress(const SensorModel& truth, const DigitShader& shader,
                      const PressCircle& circle, std::int64_t seed) {
  cv::Mat1f gel;
  GelModel(truth).apply(ballPressIndentation(truth, circle, kBallRadiusMm), gel);
  return shader.shade(gel, seed);
}

// Presses spread over the gel with contact radii 1.1-1.8 mm (as the real 6 mm ball set).
std::vector<PressCircle> spreadPresses(const SensorModel& m, int count) {
  std::vector<PressCircle> circles;
  cv::RNG rng(7);
  for (int i = 0; i < count; ++i) {
    const double radius_mm = 1.1 + 0.7 * (i % 5) / 4.0;
    const double x = rng.uniform(-4.0, 4.0), y = rng.uniform(-6.0, 6.0);
    circles.push_back(
        {{x / m.mm_per_pixel + 0.5 * m.cols - 0.5, y / m.mm_per_pixel + 0.5 * m.rows - 0.5},
         radius_mm / m.mm_per_pixel});
  }
  return circles;
}

cv::Mat3f difference(const cv::Mat3b& frame, const cv::Mat3b& background) {
  cv::Mat3f f, b;
  frame.convertTo(f, CV_32F);
  background.convertTo(b, CV_32F);
  return f - b;
}

// Detection is the first estimate (centre within 0.2 mm, radius biased outwards by the rim
// shadow and skirt); refinement against the model then recovers the true circle.
TEST(PressDetection, FindsARenderedPressAndRefinementRecoversItsCircle) {
  const SensorModel m = makeDigitSensorModel();
  const cv::Mat3b background = makeSyntheticBackground(m);
  const DigitShader shader(m, background, BackgroundSource::kSynthetic);
  for (const PressCircle& truth : spreadPresses(m, 6)) {
    PressObservation press;
    press.name = "rendered";
    press.diff = difference(renderPress(m, shader, truth, 3), background);
    press.circle = detectPress(press.diff, press.name);
    EXPECT_LT(cv::norm(press.circle.centre_px - truth.centre_px), 0.2 / m.mm_per_pixel)
        << truth.centre_px;
    EXPECT_GT(press.circle.radius_px, 0.7 * truth.radius_px);
    EXPECT_LT(press.circle.radius_px, 1.6 * truth.radius_px);
    PressCircle start = press.circle;
    start.radius_px /= 1.4;  // roughly the detector's bias (the fit finds it as a factor)
    const PressCircle refined = refinePressCircle(shader, m, press, start, kBallRadiusMm);
    EXPECT_LT(cv::norm(refined.centre_px - truth.centre_px), 0.5) << truth.centre_px;
    EXPECT_NEAR(refined.radius_px, truth.radius_px, 0.03 * truth.radius_px) << truth.centre_px;
  }
}

// Two presses of the ball moved 8 mm along the gel between them (with a caliper) give the scale
// the ball presses themselves do not pin: within 1 % for presses rendered at 0.0532 and at
// 0.060 mm/px, moved along x, y or both.
TEST(PressScale, TwoPressesAKnownDistanceApartGiveTheScale) {
  for (const double truth_scale : {0.0532, 0.060}) {
    SensorModel m = makeDigitSensorModel();
    m.mm_per_pixel = truth_scale;
    const cv::Mat3b background = makeSyntheticBackground(m);
    const DigitShader shader(m, background, BackgroundSource::kSynthetic);
    const auto pressAt = [&](double x_mm, double y_mm) {
      const PressCircle circle{{x_mm / m.mm_per_pixel + 0.5 * m.cols - 0.5,
                                y_mm / m.mm_per_pixel + 0.5 * m.rows - 0.5},
                               1.5 / m.mm_per_pixel};
      return renderPress(m, shader, circle, 5);
    };
    for (const cv::Point2d move : {cv::Point2d(8, 0), cv::Point2d(0, 8), cv::Point2d(4.8, 6.4)}) {
      const cv::Point2d from(-0.5 * move.x, -0.5 * move.y);
      const PressScale scale = measureScaleFromTwoPresses(
          background, pressAt(from.x, from.y), "a.png", pressAt(from.x + move.x, from.y + move.y),
          "b.png", 8.0);
      EXPECT_NEAR(scale.mm_per_pixel / truth_scale, 1.0, 0.01) << move << " at " << truth_scale;
      EXPECT_NEAR(scale.distance_px, 8.0 / truth_scale, 0.01 * 8.0 / truth_scale);
    }
  }
  const SensorModel m = makeDigitSensorModel();
  const cv::Mat3b background = makeSyntheticBackground(m);
  const DigitShader shader(m, background, BackgroundSource::kSynthetic);
  const cv::Mat3b press = renderPress(m, shader, spreadPresses(m, 1)[0], 5);
  test::expectError(
      [&] { measureScaleFromTwoPresses(background, press, "a.png", press, "b.png", 8.0); },
      {"a.png", "b.png", "too close"});
  test::expectError(
      [&] { measureScaleFromTwoPresses(background, press, "a.png", press, "b.png", -1.0); },
      {"finite and > 0"});
  test::expectError(
      [&] {
        measureScaleFromTwoPresses(background, press, "a.png", background, "empty.png", 8.0);
      },
      {"empty.png", "no press"});
  test::expectError(
      [&] {
        measureScaleFromTwoPresses(background, press, "a.png", cv::Mat3b(10, 10), "small.png", 8.0);
      },
      {"small.png", "10 x 10"});
}

TEST(PressDetection, NoPressIsAClearError) {
  const SensorModel m = makeDigitSensorModel();
  const DigitShader shader(m, makeSyntheticBackground(m), BackgroundSource::kSynthetic);
  const cv::Mat1f flat(m.rows, m.cols, 0.0f);
  const cv::Mat3f noise_only = difference(shader.shade(flat, 1), shader.shade(flat, 2));
  test::expectError([&] { detectPress(noise_only, "empty.png"); }, {"empty.png", "no press"});
}

TEST(BallPress, IndentationIsTheSphericalCapOfTheContact) {
  SensorModel m = makeDigitSensorModel();
  const PressCircle contact{{119.5, 159.5}, 1.5 / m.mm_per_pixel};
  const cv::Mat1f h = ballPressIndentation(m, contact, kBallRadiusMm);
  const double depth = kBallRadiusMm - std::sqrt(kBallRadiusMm * kBallRadiusMm - 1.5 * 1.5);
  double peak = 0.0;
  cv::minMaxLoc(h, nullptr, &peak);
  EXPECT_NEAR(peak, depth, 1e-3);
  const double area_mm2 = cv::countNonZero(h) * m.mm_per_pixel * m.mm_per_pixel;
  EXPECT_NEAR(area_mm2, CV_PI * 1.5 * 1.5, 0.03 * CV_PI * 1.5 * 1.5);
  test::expectError([&] { ballPressIndentation(m, contact, 1.0); }, {"ball radius", "1.5"});
}

// Noise drawn with known options over a smooth background is measured back.
TEST(BackgroundNoise, MeasuresTheNoiseItWasGiven) {
  const SensorModel m = makeDigitSensorModel();
  const cv::Mat3b smooth = makeSyntheticBackground(m);
  const DigitShader shader(m, smooth, BackgroundSource::kSynthetic);
  const cv::Mat1f flat(m.rows, m.cols, 0.0f);
  std::vector<cv::Mat3b> frames;
  for (const std::int64_t seed : {11, 12, 13}) frames.push_back(shader.shade(flat, seed));
  const NoiseOptions measured = measureBackgroundNoise(frames);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(measured.sigma_bgr[k], m.noise.sigma_bgr[k], 0.15 * m.noise.sigma_bgr[k]) << k;
  }
  EXPECT_NEAR(measured.neighbour_correlation, m.noise.neighbour_correlation, 0.1);
  EXPECT_NEAR(measured.correlation_bg, m.noise.correlation_bg, 0.08);
  EXPECT_NEAR(measured.correlation_gr, m.noise.correlation_gr, 0.08);
  EXPECT_NEAR(measured.correlation_br, m.noise.correlation_br, 0.08);
  EXPECT_FALSE(measured.on_real_background);
}

// Presses rendered with a known shading model and scale are calibrated without the scale: the
// fitted model reproduces the held-out presses and recovers the scale.
TEST(Calibration, RoundTripRecoversTheScaleAndReproducesHeldOutPresses) {
  const SensorModel truth = makeDigitSensorModel();  // 0.054 mm/px, the default response
  const cv::Mat3b smooth = makeSyntheticBackground(truth);
  const DigitShader shader(truth, smooth, BackgroundSource::kSynthetic);
  CalibrationInput input;
  const cv::Mat1f flat(truth.rows, truth.cols, 0.0f);
  input.backgrounds.push_back({"bg0", shader.shade(flat, 100)});
  input.backgrounds.push_back({"bg1", shader.shade(flat, 101)});
  int seed = 0;
  for (const PressCircle& circle : spreadPresses(truth, 14)) {
    input.presses.push_back(
        {"press" + std::to_string(seed), renderPress(truth, shader, circle, seed)});
    ++seed;
  }
  input.ball_diameter_mm = 2.0 * kBallRadiusMm;
  SensorModel base = makeDigitSensorModel();
  base.mm_per_pixel = 0.08;  // not used: the scale is fitted
  const CalibrationResult result = calibrateSensor(base, input);
  std::printf("round trip: scale %.4f mm/px (truth %.4f), held-out variance explained %.3f\n",
              result.model.mm_per_pixel, truth.mm_per_pixel, result.held_out.variance_explained);
  EXPECT_NEAR(result.model.mm_per_pixel, truth.mm_per_pixel, 0.05 * truth.mm_per_pixel);
  EXPECT_GE(result.held_out.variance_explained, 0.95);
  EXPECT_GE(result.held_out.presses, 3);
  EXPECT_EQ(result.training_presses + result.held_out.presses, 14);
  EXPECT_FALSE(result.fit.scale_at_search_bound);
  // The profile of the search brackets the truth: here the response model is the renderer's own.
  for (const std::string& line : describeScaleSearch(result.fit)) std::printf("%s\n", line.c_str());
  const ScaleSearch& search = result.fit.scale_search;
  EXPECT_GE(search.profile.size(), 8u);
  EXPECT_LE(search.range_min, truth.mm_per_pixel);
  EXPECT_GE(search.range_max, truth.mm_per_pixel);
}

// A marker gel: its dots are found on the background (grid, pitch, diameter), filled in before
// the fit, and the calibration reproduces the held-out presses as well as without them.
TEST(Calibration, AMarkerGelsDotsAreMeasuredAndMaskedOutOfTheFit) {
  SensorModel truth = makeDigitSensorModel();
  truth.markers.enabled = true;
  truth.markers.rows = 9;
  truth.markers.cols = 7;
  truth.markers.pitch_mm = 1.6;
  truth.markers.dot_diameter_mm = 0.45;
  truth.markers.darkness = 0.6;
  const cv::Mat3b smooth = makeSyntheticBackground(truth);
  const DigitShader shader(truth, smooth, BackgroundSource::kSynthetic);
  const MarkerPattern pattern(truth);
  std::vector<Marker> rest;
  for (const cv::Point2f& p : pattern.restPx()) rest.push_back({p, p, {0, 0}});
  const auto marked = [&](cv::Mat3b frame) {
    pattern.draw(frame, rest);  // a pure press leaves the markers where they are
    return frame;
  };
  CalibrationInput input;
  const cv::Mat1f flat(truth.rows, truth.cols, 0.0f);
  input.backgrounds.push_back({"bg0", marked(shader.shade(flat, 100))});
  int seed = 0;
  for (const PressCircle& circle : spreadPresses(truth, 10)) {
    input.presses.push_back(
        {"press" + std::to_string(seed), marked(renderPress(truth, shader, circle, seed))});
    ++seed;
  }
  input.ball_diameter_mm = 2.0 * kBallRadiusMm;
  input.mm_per_pixel = truth.mm_per_pixel;
  const CalibrationResult result = calibrateSensor(makeDigitSensorModel(), input);
  ASSERT_TRUE(result.markers.found());
  EXPECT_EQ(result.markers.centres_px.size(), 63u);
  const MarkerOptions& m = result.model.markers;
  EXPECT_TRUE(m.enabled);
  EXPECT_EQ(m.rows, 9);
  EXPECT_EQ(m.cols, 7);
  EXPECT_NEAR(m.pitch_mm, 1.6, 0.02);
  EXPECT_NEAR(m.dot_diameter_mm, 0.45, 0.05);
  EXPECT_NEAR(m.darkness, 0.6, 0.1);
  EXPECT_NEAR(m.offset_mm[0], 0.0, 0.03);
  EXPECT_NEAR(m.offset_mm[1], 0.0, 0.03);
  std::printf("with markers: held-out variance explained %.3f\n",
              result.held_out.variance_explained);
  EXPECT_GE(result.held_out.variance_explained, 0.95);
  // The background kept is the gel's without its dots: no dot left darker than the threshold.
  EXPECT_FALSE(detectMarkers(result.background).found());
  // A DIGIT's real background has no markers.
  EXPECT_FALSE(detectMarkers(cv::imread(NORM2TEX_SOURCE_DIR "/config/digit_s09_background.png")).found());
}

NamedFrame fixtureFrame(int index) {
  const std::string path =
      NORM2TEX_SOURCE_DIR "/test/fixtures/digit_s09/frame_" + std::to_string(index) + ".jpg";
  const cv::Mat3b image = cv::imread(path, cv::IMREAD_COLOR);
  if (image.empty()) throw Error("fixture '" + path + "' is missing");
  return {path, image};
}

// Real presses of one DIGIT (6 mm ball, 0.0532 mm/px; another recording of the unit the default
// was fitted on): calibrate on half, render the other half at the fitted geometry, compare.
TEST(Calibration, RealPressesAreReproducedOnTheHeldOutHalf) {
  CalibrationInput input;
  input.backgrounds.push_back(fixtureFrame(30));
  for (int i = 0; i <= 28; i += 2) input.presses.push_back(fixtureFrame(i));
  input.ball_diameter_mm = 6.0;
  input.mm_per_pixel = 0.0532;
  CalibrationOptions options;
  options.holdout_fraction = 0.5;
  const CalibrationResult result = calibrateSensor(makeDigitSensorModel(), input, options);
  const FitQuality& q = result.held_out;
  for (const std::string& line : describeFitQuality(result)) std::printf("%s\n", line.c_str());
  EXPECT_GE(q.presses, 7);
  EXPECT_GE(q.variance_explained, 0.5);
  for (int k = 0; k < 3; ++k) EXPECT_LE(q.side_error_deg[k], 30.0) << "channel " << k;
  ASSERT_LT(q.real_rim_darkest, -3.0) << "the real presses show a rim shadow";
  EXPECT_LE(q.sim_rim_darkest, 0.5 * q.real_rim_darkest);
  EXPECT_NEAR(q.sim_contact_mean, q.real_contact_mean, 0.3 * q.real_contact_mean);
  EXPECT_NEAR(q.sim_contact_p95, q.real_contact_p95, 0.3 * q.real_contact_p95);
  // The real measures themselves are those of a DIGIT (digit_facts.md), not of noise.
  EXPECT_GT(q.real_contact_mean, 15.0);
  EXPECT_NEAR(q.real_side_deg[0], 70.0, 30.0);   // blue below
  EXPECT_NEAR(q.real_side_deg[2], -41.0, 30.0);  // red upper right
  // The rendered frames against the real ones, as the field reports them (SSIM >= 0.93 in
  // Taccel and TaCauchy; this package's goal 0.90 on held-out presses; measured 0.944, contact
  // 0.914, PSNR 33.8 dB, mean |diff| 4.0 on this split).
  ASSERT_EQ(static_cast<int>(result.held_out_frames.size()), q.presses);
  ASSERT_EQ(static_cast<int>(result.training_frames.size()), result.training_presses);
  const ImageSimilarity held_out = medianSimilarity(result.held_out_frames);
  EXPECT_GE(held_out.ssim, 0.90);
  EXPECT_GE(held_out.ssim_in_mask, 0.85);
  EXPECT_GE(held_out.psnr_db, 30.0);
  EXPECT_LE(held_out.mean_abs_diff, 6.0);
  // Most of a frame is untouched gel, so the bare background already scores a high frame SSIM;
  // inside the contact the rendered press must do clearly better than no press at all.
  const ImageSimilarity bare =
      medianSimilarity(result.held_out_frames, &PressFrameComparison::bare_background);
  EXPECT_GE(held_out.ssim, bare.ssim);
  EXPECT_GE(held_out.ssim_in_mask, bare.ssim_in_mask + 0.04);
  for (const PressFrameComparison& press : result.held_out_frames) {
    EXPECT_TRUE(press.held_out);
    EXPECT_FALSE(press.labelled);
    EXPECT_EQ(press.name, input.presses[press.index].name);
    EXPECT_GT(press.depth_mm, 0.2) << press.name;  // contacts of 1.1-1.9 mm: 0.2-0.7 mm deep
    EXPECT_LT(press.depth_mm, 0.8) << press.name;
    // The contact is where the render differs most: its SSIM is below the frame's.
    EXPECT_LT(press.similarity.ssim_in_mask, press.similarity.ssim + 0.02) << press.name;
  }
}

// The shipped sensor, fitted on one recording of the unit (vocdex/Taxim sphere2), judged on the
// other (the fixture: sphere, another day, another background): every press held out, nothing
// fitted. Goal of the realism work: at least 0.85 of the variance, the rim shadow within 20 %.
TEST(Calibration, TheShippedSensorIsJudgedOnTheUnitsOtherRecording) {
  CalibrationInput input;
  input.backgrounds.push_back(fixtureFrame(30));
  for (int i = 0; i <= 28; i += 2) input.presses.push_back(fixtureFrame(i));
  input.ball_diameter_mm = 6.0;
  const SensorModel shipped = loadSensorModel(NORM2TEX_SOURCE_DIR "/config/digit.yaml");
  const CalibrationResult result = judgeSensor(shipped, input);
  const FitQuality& q = result.held_out;
  for (const std::string& line : describeFitQuality(result)) std::printf("%s\n", line.c_str());
  EXPECT_EQ(result.training_presses, 0);
  EXPECT_TRUE(result.training_frames.empty());
  EXPECT_EQ(q.presses, 15);
  EXPECT_EQ(result.model.shading.response_bgr, shipped.shading.response_bgr);  // nothing fitted
  EXPECT_GE(q.variance_explained, 0.85);
  ASSERT_LT(q.real_rim_darkest, -3.0);
  EXPECT_NEAR(q.sim_rim_darkest / q.real_rim_darkest, 1.0, 0.2);
  for (int k = 0; k < 3; ++k) EXPECT_LE(q.side_error_deg[k], 15.0) << "channel " << k;
  EXPECT_EQ(result.held_out_frames.size(), 15u);
  // The judged sensor's scale is the scale: another one given is refused, not used.
  input.mm_per_pixel = 0.05;
  test::expectError([&] { judgeSensor(shipped, input); }, {"0.0532", "leave the scale out"});
  input.mm_per_pixel.reset();
  input.presses.clear();
  test::expectError([&] { judgeSensor(shipped, input); }, {"at least 1 ball press"});
}

// Without the scale, the real presses do not pin it (ScaleSearch: a response fitted per unit
// absorbs most of a change of scale, and real presses fit best near the smallest scale
// searched, as presses rendered with the analytic LEDs do). The calibration must say so: the fit
// is flagged at the bound or the scales that fit within kScaleIndifference span more than 10 %
// (what the tool warns about), and the profile shows the source's own scale fitting nearly as
// well.
TEST(Calibration, RealPressesWithoutTheScaleAreFlaggedAsNotPinningIt) {
  CalibrationInput input;
  input.backgrounds.push_back(fixtureFrame(30));
  for (int i = 0; i <= 28; i += 2) input.presses.push_back(fixtureFrame(i));
  input.ball_diameter_mm = 6.0;
  const CalibrationResult result = calibrateSensor(makeDigitSensorModel(), input);
  for (const std::string& line : describeScaleSearch(result.fit)) std::printf("%s\n", line.c_str());
  const ScaleSearch& search = result.fit.scale_search;
  EXPECT_TRUE(result.fit.scale_at_search_bound || search.range_max > 1.1 * search.range_min)
      << result.model.mm_per_pixel << " mm/px; fits as well over " << search.range_min << "-"
      << search.range_max;
  ASSERT_GE(search.profile.size(), 6u);
  EXPECT_NEAR(search.range_min, kMinSearchedScale, 1e-9);
  double best = 0.0, at_source_scale = 0.0, nearest = 1e9;
  for (const ScaleProfilePoint& point : search.profile) {
    best = std::max(best, point.variance_explained);
    if (std::abs(point.mm_per_pixel - 0.0532) < nearest) {
      nearest = std::abs(point.mm_per_pixel - 0.0532);
      at_source_scale = point.variance_explained;
    }
  }
  EXPECT_LT(nearest, 0.004);
  EXPECT_GT(at_source_scale, best - 0.03) << "flat: the source's 0.0532 mm/px fits nearly as well";
  EXPECT_GE(result.held_out.variance_explained, 0.5);
}

TEST(Calibration, BadInputIsAClearError) {
  const SensorModel m = makeDigitSensorModel();
  const cv::Mat3b smooth = makeSyntheticBackground(m);
  const DigitShader shader(m, smooth, BackgroundSource::kSynthetic);
  CalibrationInput good;
  good.backgrounds.push_back({"bg.png", smooth});
  int seed = 0;
  for (const PressCircle& circle : spreadPresses(m, 5)) {
    good.presses.push_back(
        {"p" + std::to_string(seed) + ".png", renderPress(m, shader, circle, seed)});
    ++seed;
  }
  good.ball_diameter_mm = 6.0;
  good.mm_per_pixel = m.mm_per_pixel;

  CalibrationInput landscape = good;
  cv::transpose(landscape.presses[2].image, landscape.presses[2].image);
  test::expectError([&] { calibrateSensor(m, landscape); }, {"p2.png", "landscape", "rotate"});

  CalibrationInput no_press = good;
  no_press.presses[1].image = smooth.clone();
  test::expectError([&] { calibrateSensor(m, no_press); }, {"p1.png", "no press"});

  CalibrationInput tiny_ball = good;
  tiny_ball.ball_diameter_mm = 1.0;
  test::expectError([&] { calibrateSensor(m, tiny_ball); }, {"ball", "--ball-diameter-mm"});

  CalibrationInput one_press = good;
  one_press.presses.resize(1);
  test::expectError([&] { calibrateSensor(m, one_press); }, {"at least 4", "got 1"});

  CalibrationInput no_background = good;
  no_background.backgrounds.clear();
  test::expectError([&] { calibrateSensor(m, no_background); }, {"background"});
}

// A scale the user gives is the scale calibrated, exactly. Presses (contact radii up to 1.8 mm,
// detected a little wider) of a ball said to have a 1.6 mm radius fit it at 0.054 mm/px only with
// the detected radii taken as at most ~0.8 of themselves: the radius factor gives way, not the
// scale (which the fit used to lower silently to where the ball allowed a factor near 1). A ball
// that cannot make a press at that scale at all refuses the scale, naming the press, its radius
// in pixels and the ball's radius.
TEST(Calibration, AGivenScaleIsUsedAsGivenOrRefusedNamingThePress) {
  const SensorModel m = makeDigitSensorModel();
  const cv::Mat3b smooth = makeSyntheticBackground(m);
  const DigitShader shader(m, smooth, BackgroundSource::kSynthetic);
  CalibrationInput input;
  input.backgrounds.push_back({"bg.png", smooth});
  int seed = 0;
  for (const PressCircle& circle : spreadPresses(m, 6)) {
    input.presses.push_back(
        {"p" + std::to_string(seed) + ".png", renderPress(m, shader, circle, seed)});
    ++seed;
  }
  input.mm_per_pixel = 0.054;
  input.ball_diameter_mm = 3.2;
  const CalibrationResult result = calibrateSensor(m, input);
  EXPECT_EQ(result.model.mm_per_pixel, 0.054);
  EXPECT_EQ(result.fit.geometry.mm_per_pixel, 0.054);

  // p4 holds the largest contact (1.8 mm, ~33 px detected a little wider): at 0.6 of it, still
  // wider than a ball of radius 0.8 mm makes.
  input.ball_diameter_mm = 1.6;
  test::expectError([&] { calibrateSensor(m, input); },
                    {"0.054", "refused", "'p4.png'", " px", "radius 0.8 mm"});
}

// A labels file made on another machine (test/fixtures/digit_s09/labels_other_machine.csv):
// header line, CRLF, that machine's absolute paths. It labels the presses given here by their
// own paths, matched on base names.
TEST(PressLabels, LabelsFromAnotherMachineMatchByBaseName) {
  const std::string fixtures = NORM2TEX_SOURCE_DIR "/test/fixtures/digit_s09/";
  const std::vector<PressLabel> labels = readPressLabels(fixtures + "labels_other_machine.csv");
  ASSERT_EQ(labels.size(), 6u);
  EXPECT_EQ(labels[0].name, "/home/someone/data/images/frame_0.jpg");  // no '\r' kept
  EXPECT_EQ(labels[0].line, 2);
  EXPECT_DOUBLE_EQ(labels[5].circle.centre_px.x, 185.7);
  EXPECT_DOUBLE_EQ(labels[5].circle.centre_px.y, 103.1);
  EXPECT_DOUBLE_EQ(labels[5].circle.radius_px, 46.2);  // "46.2\r" read as a number
  // Presses 0..12 here: the labelled ones (0..10) get their circles, frame_12 none.
  std::vector<std::string> presses;
  for (int i = 0; i <= 12; i += 2)
    presses.push_back(fixtures + "frame_" + std::to_string(i) + ".jpg");
  const std::vector<std::optional<PressCircle>> circles =
      matchPressLabels(labels, presses, "labels");
  ASSERT_EQ(circles.size(), presses.size());
  for (size_t i = 0; i < 6; ++i) {
    ASSERT_TRUE(circles[i].has_value()) << presses[i];
    EXPECT_EQ(circles[i]->centre_px, labels[i].circle.centre_px) << presses[i];
    EXPECT_EQ(circles[i]->radius_px, labels[i].circle.radius_px) << presses[i];
  }
  EXPECT_FALSE(circles[6].has_value());
  // The circles are where the presses are: the detector agrees within a few pixels.
  const NamedFrame background = fixtureFrame(30);
  const NamedFrame press = fixtureFrame(4);
  cv::Mat3f diff;
  cv::subtract(press.image, background.image, diff, cv::noArray(), CV_32F);
  const PressCircle detected = detectPress(diff, press.name);
  EXPECT_LT(cv::norm(detected.centre_px - circles[2]->centre_px), 3.0);
}

TEST(PressLabels, ExactPathsWinAndAmbiguityIsAnError) {
  std::istringstream text(
      "\xEF\xBB\xBF# made by hand\r\n"
      "\r\n"
      "a/frame_1.png,1,2,3\r\n"
      "\"C:\\data\\frame, two.png\",4,5,6\n");
  const std::vector<PressLabel> labels = parsePressLabels(text, "labels");
  ASSERT_EQ(labels.size(), 2u);
  EXPECT_EQ(labels[1].name, "C:\\data\\frame, two.png");
  // Two presses named frame_1.png: the label's exact path picks one.
  const auto circles =
      matchPressLabels(labels, {"b/frame_1.png", "a/frame_1.png", "x/frame, two.png"}, "labels");
  EXPECT_FALSE(circles[0].has_value());
  ASSERT_TRUE(circles[1].has_value());
  EXPECT_EQ(circles[1]->radius_px, 3.0);
  ASSERT_TRUE(circles[2].has_value());  // a Windows path's base name
  EXPECT_EQ(circles[2]->radius_px, 6.0);
  // A foreign path whose base name two presses share cannot be placed.
  std::istringstream foreign("/home/someone/frame_1.png,1,2,3\n");
  test::expectError(
      [&] {
        matchPressLabels(parsePressLabels(foreign, "labels 'l.csv'"),
                         {"b/frame_1.png", "a/frame_1.png"}, "labels 'l.csv'");
      },
      {"labels 'l.csv' line 1", "b/frame_1.png", "a/frame_1.png"});
  // Two labels for one press.
  std::istringstream twice("/x/f.png,1,2,3\n/y/f.png,1,2,4\n");
  test::expectError(
      [&] { matchPressLabels(parsePressLabels(twice, "labels"), {"f.png"}, "labels"); },
      {"lines 1 and 2", "f.png"});
  // None of the presses.
  std::istringstream other("/x/g.png,1,2,3\n");
  test::expectError(
      [&] { matchPressLabels(parsePressLabels(other, "labels"), {"d/f.png"}, "labels"); },
      {"name none", "f.png"});
}

TEST(PressLabels, MalformedLinesNameTheLine) {
  const auto expectLineError = [](const std::string& text, const std::string& fragment) {
    std::istringstream in(text);
    test::expectError([&] { parsePressLabels(in, "labels 'l.csv'"); },
                      {"labels 'l.csv'", fragment});
  };
  expectLineError("file,x,y,r\nf.png,1,2\n", "line 2");       // a field short
  expectLineError("f.png,1,2\n", "line 1");                   // too few numbers is no header
  expectLineError("f.png,1,2,3\ng.png,1,two,3\n", "line 2");  // a second header is a mistake
  expectLineError("f.png,1,2,0\n", "radius_px must be > 0");
  expectLineError(",1,2,3\n", "file name is empty");
  test::expectError([] { readPressLabels("/no/such/labels.csv"); }, {"/no/such/labels.csv"});
}

}  // namespace
}  // namespace norm2tex
