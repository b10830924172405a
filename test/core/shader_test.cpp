// DigitShader and DIGIT backgrounds: exactness where nothing touches, noise statistics and
// determinism, LED colours on the right side of a press, realistic magnitudes, synthetic
// background statistics against real DIGIT frames, and the handling of bad inputs.

#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "norm2tex/render/digit_shader.hpp"
#include "norm2tex/common/error.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

// Indentation (mm) of a sphere of `radius_mm` pressed `depth_mm` into the gel, centred at gel
// point (cx_mm, cy_mm); 0 outside the contact.
cv::Mat1f sphericalCap(const SensorModel& model, double radius_mm, double depth_mm,
                       double cx_mm = 0.0, double cy_mm = 0.0) {
  cv::Mat1f h(model.rows, model.cols, 0.0f);
  for (int r = 0; r < model.rows; ++r) {
    for (int c = 0; c < model.cols; ++c) {
      const cv::Point2d p = model.pixelToGelMm(r, c);
      const double rho2 = (p.x - cx_mm) * (p.x - cx_mm) + (p.y - cy_mm) * (p.y - cy_mm);
      if (rho2 >= radius_mm * radius_mm) continue;
      const double value = depth_mm - (radius_mm - std::sqrt(radius_mm * radius_mm - rho2));
      if (value > 0.0) h(r, c) = static_cast<float>(value);
    }
  }
  return h;
}

// A stand-in for the gel's smoothing, so these tests do not depend on GelModel: one Gaussian.
cv::Mat1f smoothed(const cv::Mat1f& h, const SensorModel& model, double sigma_mm) {
  cv::Mat1f out;
  const double sigma_px = sigma_mm / model.mm_per_pixel;
  const int radius = static_cast<int>(std::ceil(3.0 * sigma_px));
  cv::GaussianBlur(h, out, cv::Size(2 * radius + 1, 2 * radius + 1), sigma_px);
  return out;
}

// Mean BGR over the rectangle given in fractions of the image.
cv::Scalar regionMean(const cv::Mat3b& image, double left, double top, double right,
                      double bottom) {
  const cv::Rect rect(cvRound(left * image.cols), cvRound(top * image.rows),
                      cvRound((right - left) * image.cols), cvRound((bottom - top) * image.rows));
  return cv::mean(image(rect));
}

cv::Mat3f difference(const cv::Mat3b& a, const cv::Mat3b& b) {
  cv::Mat3f fa, fb;
  a.convertTo(fa, CV_32F);
  b.convertTo(fb, CV_32F);
  return fa - fb;
}

// Mean of |v| over all channels of the pixels where mask != 0.
double meanAbs(const cv::Mat3f& v, const cv::Mat1b& mask) {
  const cv::Scalar m = cv::mean(cv::abs(v), mask);
  return (m[0] + m[1] + m[2]) / 3.0;
}

bool identical(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

bool messageContains(const std::function<void()>& call, const std::string& text) {
  try {
    call();
  } catch (const Error& e) {
    return std::string(e.what()).find(text) != std::string::npos;
  }
  return false;
}

class ShaderTest : public ::testing::Test {
 protected:
  SensorModel model = makeDigitSensorModel();
  cv::Mat3b background = makeSyntheticBackground(model.imageSize());
  DigitShader shader{model, background};
  cv::Mat1f flat = cv::Mat1f(model.rows, model.cols, 0.0f);
};

// --- no contact, noise, determinism --------------------------------------------------------

TEST_F(ShaderTest, NoContactWithoutNoiseIsTheBackgroundBitForBit) {
  EXPECT_TRUE(identical(shader.shade(flat, -1), background));
  EXPECT_EQ(cv::countNonZero(shader.shadingDifference(flat).reshape(1)), 0);
}

TEST_F(ShaderTest, NoiseHasTheModelSigmaAndZeroMean) {
  for (const double sigma : {2.0, 6.0}) {
    SensorModel noisy_model = model;
    noisy_model.noise_sigma = sigma;
    const DigitShader noisy(noisy_model, background);
    const cv::Mat3f noise = difference(noisy.shade(flat, 7), background);
    cv::Scalar mean, stddev;
    cv::meanStdDev(noise.reshape(1), mean, stddev);
    EXPECT_NEAR(stddev[0], sigma, 0.15 * sigma) << "sigma " << sigma;
    EXPECT_NEAR(mean[0], 0.0, 0.05) << "sigma " << sigma;
    // White: neighbouring pixels and channels are uncorrelated.
    const cv::Mat1f flat_noise = noise.reshape(1, 1);
    const cv::Mat1f a = flat_noise.colRange(0, flat_noise.cols - 3);
    const cv::Mat1f next_pixel = flat_noise.colRange(3, flat_noise.cols);
    const cv::Mat1f next_channel = flat_noise.colRange(1, flat_noise.cols - 2);
    const cv::Mat1b all(a.size(), 255);
    EXPECT_LT(std::abs(test::correlation(a, next_pixel, all)), 0.02);
    EXPECT_LT(std::abs(test::correlation(a, next_channel, all)), 0.02);
  }
}

TEST_F(ShaderTest, SameSeedSameImageDifferentSeedsIndependentNoise) {
  const cv::Mat1f h = smoothed(sphericalCap(model, 4.4, 1.0), model, 0.3);
  EXPECT_TRUE(identical(shader.shade(h, 42), shader.shade(h, 42)));
  EXPECT_TRUE(identical(shader.shade(flat, 0), shader.shade(flat, 0)));
  const cv::Mat3f n1 = difference(shader.shade(flat, 1), background);
  const cv::Mat3f n2 = difference(shader.shade(flat, 2), background);
  EXPECT_GT(cv::countNonZero(n1.reshape(1) != n2.reshape(1)), 0.5 * n1.total() * 3);
  const cv::Mat1f f1 = n1.reshape(1, 1), f2 = n2.reshape(1, 1);
  EXPECT_LT(std::abs(test::correlation(f1, f2, cv::Mat1b(f1.size(), 255))), 0.02);
}

TEST_F(ShaderTest, ZeroNoiseSigmaOrNegativeSeedAddsNoNoise) {
  SensorModel quiet_model = model;
  quiet_model.noise_sigma = 0.0;
  const DigitShader quiet(quiet_model, background);
  EXPECT_TRUE(identical(quiet.shade(flat, 3), background));
  const cv::Mat1f h = sphericalCap(model, 3.0, 0.5);
  EXPECT_TRUE(identical(quiet.shade(h, 3), shader.shade(h, -1)));
}

// Outside the grown bounding box of the contact, the frame is exactly the no-contact frame,
// with and without noise; the noise of a pixel does not depend on where the contact is.
TEST_F(ShaderTest, OutsideTheContactBoxTheFrameIsExactlyTheNoContactFrame) {
  const cv::Mat1f h = sphericalCap(model, 3.0, 0.5, 2.0, -3.0);
  const cv::Rect contact = cv::boundingRect(h > 0.0f);
  cv::Mat1b outside(h.size(), 255);
  outside(cv::Rect(contact.x - 2, contact.y - 2, contact.width + 4, contact.height + 4)) = 0;
  for (const std::int64_t seed : {-1, 5}) {
    const cv::Mat3b pressed = shader.shade(h, seed), untouched = shader.shade(flat, seed);
    cv::Mat1b same;
    cv::Mat3b delta;
    cv::absdiff(pressed, untouched, delta);
    cv::cvtColor(delta, same, cv::COLOR_BGR2GRAY);
    EXPECT_EQ(cv::countNonZero(same & outside), 0) << "seed " << seed;
    EXPECT_GT(cv::countNonZero(same), 100) << "seed " << seed;  // the contact shows
  }
  // Where the gel is locally flat (no indentation in the 3 x 3 neighbourhood) the shading
  // difference is exactly 0, also inside the box.
  cv::Mat1b touched;
  cv::dilate(h > 0.0f, touched, cv::Mat());
  cv::Mat1b changed;
  cv::cvtColor(shader.shadingDifference(h) != 0.0f, changed, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(cv::countNonZero(changed & ~touched), 0);
  EXPECT_GT(cv::countNonZero(changed), 100);
}

// --- shading ---------------------------------------------------------------------------------

// Each LED's channel is stronger on the half of a symmetric press that faces that LED.
void expectLedSides(const SensorModel& model, const DigitShader& shader, const cv::Mat1f& h) {
  const cv::Mat3f diff = shader.shadingDifference(h);
  const cv::Mat1b contact = h > 0.0f;
  ASSERT_GT(cv::countNonZero(contact), 100);
  for (int i = 0; i < 3; ++i) {
    const LedModel& led = model.leds[i];
    const int channel = i == 0 ? 2 : (i == 1 ? 1 : 0);  // red, green, blue in BGR
    ASSERT_EQ(led.color_bgr[channel], 1.0) << led.name;
    const cv::Vec2d towards = cv::normalize(cv::Vec2d(led.position_mm[0], led.position_mm[1]));
    double near_sum = 0, far_sum = 0;
    int near_count = 0, far_count = 0;
    for (int r = 0; r < h.rows; ++r) {
      for (int c = 0; c < h.cols; ++c) {
        if (!contact(r, c)) continue;
        const cv::Point2d p = model.pixelToGelMm(r, c);
        const double side = p.x * towards[0] + p.y * towards[1];
        if (std::abs(side) < 2.0 * model.mm_per_pixel) continue;
        (side > 0 ? near_sum : far_sum) += diff(r, c)[channel];
        ++(side > 0 ? near_count : far_count);
      }
    }
    const double near_mean = near_sum / near_count, far_mean = far_sum / far_count;
    EXPECT_GT(near_mean, 0.0) << led.name;
    EXPECT_GT(near_mean, far_mean + 5.0) << led.name;
  }
  // And in the final frame: the top-left of the press is redder than its top-right.
  const cv::Mat3f frame_diff = difference(shader.shade(h, -1), shader.background());
  const cv::Rect box = cv::boundingRect(contact);
  const cv::Rect top_left(box.x, box.y, box.width / 2, box.height / 2);
  const cv::Rect top_right(box.x + box.width / 2, box.y, box.width / 2, box.height / 2);
  EXPECT_GT(cv::mean(frame_diff(top_left))[2], cv::mean(frame_diff(top_right))[2] + 5.0);
  EXPECT_GT(cv::mean(frame_diff(top_right))[1], cv::mean(frame_diff(top_left))[1] + 5.0);
}

TEST_F(ShaderTest, EachLedLightsTheSideOfAPressFacingIt) {
  expectLedSides(model, shader, sphericalCap(model, 3.0, 0.5));
}

TEST(ShaderLedTest, EachLedLightsTheSideFacingItAtVgaAndOnADome) {
  const SensorModel vga = makeDigitSensorModel(true);
  expectLedSides(vga, DigitShader(vga, makeSyntheticBackground(vga.imageSize())),
                 sphericalCap(vga, 3.0, 0.5));
  SensorModel dome = makeDigitSensorModel();
  dome.gel_curvature_radius_mm = 100.0;
  const DigitShader dome_shader(dome, makeSyntheticBackground(dome.imageSize()));
  EXPECT_TRUE(identical(dome_shader.shade(cv::Mat1f(dome.rows, dome.cols, 0.0f), -1),
                        dome_shader.background()));
  expectLedSides(dome, dome_shader, sphericalCap(dome, 3.0, 0.5));
}

// A ball of 8.8 mm pressed 1.5 mm: real DIGIT presses of such a ball differ from the
// background by ~29 grey levels on average inside the contact (95th percentile ~48) and by
// little away from it.
TEST_F(ShaderTest, BallPressHasRealisticMagnitudes) {
  const cv::Mat1f raw = sphericalCap(model, 4.4, 1.5);
  const cv::Mat1f h = smoothed(raw, model, 0.3);
  const cv::Mat3f diff = difference(shader.shade(h, -1), background);
  const cv::Mat1b contact = raw > 0.0f;
  const double inside = meanAbs(diff, contact);
  EXPECT_GT(inside, 10.0);
  EXPECT_LT(inside, 60.0);
  const double contact_radius_px = std::sqrt(2 * 4.4 * 1.5 - 1.5 * 1.5) / model.mm_per_pixel;
  cv::Mat1b far(h.size(), 255);
  cv::circle(far, cv::Point(model.cols / 2, model.rows / 2), cvRound(1.5 * contact_radius_px), 0,
             cv::FILLED);
  EXPECT_LT(meanAbs(diff, far), 0.5);
  // Bounded: the response saturates instead of burning out at the rim (the brightest
  // background channel, ~135, plus 100 stays below 255).
  EXPECT_LT(cv::norm(shader.shadingDifference(h), cv::NORM_INF), 100.0);
}

TEST_F(ShaderTest, SlopesAreScaleInvariantAcrossResolutions) {
  // The same press at VGA (half the mm per pixel) looks the same: slopes use mm over mm.
  const SensorModel vga = makeDigitSensorModel(true);
  const DigitShader vga_shader(vga, makeSyntheticBackground(vga.imageSize()));
  const cv::Mat1f qvga_raw = sphericalCap(model, 4.4, 1.0), vga_raw = sphericalCap(vga, 4.4, 1.0);
  const double qvga_mean =
      meanAbs(shader.shadingDifference(smoothed(qvga_raw, model, 0.3)), qvga_raw > 0.0f);
  const double vga_mean =
      meanAbs(vga_shader.shadingDifference(smoothed(vga_raw, vga, 0.3)), vga_raw > 0.0f);
  EXPECT_NEAR(vga_mean, qvga_mean, 0.1 * qvga_mean);
}

TEST_F(ShaderTest, ShadingGainScalesTheDifference) {
  const cv::Mat1f h = smoothed(sphericalCap(model, 3.0, 0.5), model, 0.2);
  SensorModel doubled = model, off = model;
  doubled.shading_gain = 2.0;
  off.shading_gain = 0.0;
  const cv::Mat3f base = shader.shadingDifference(h);
  const cv::Mat3f twice = DigitShader(doubled, background).shadingDifference(h);
  EXPECT_LT(cv::norm(twice, 2.0 * base, cv::NORM_INF), 1e-3);
  EXPECT_GT(cv::norm(base, cv::NORM_INF), 10.0);
  EXPECT_TRUE(identical(DigitShader(off, background).shade(h, -1), background));
}

TEST_F(ShaderTest, ContactAtTheImageBorderIsHandled) {
  // A press cut by the image corner: one-sided differences, no out-of-range access.
  const cv::Mat1f h = sphericalCap(model, 4.0, 1.0, -9.6, -12.8);
  const cv::Mat3f diff = shader.shadingDifference(h);
  EXPECT_TRUE(cv::checkRange(diff));
  EXPECT_GT(cv::norm(diff(cv::Rect(0, 0, 10, 10)), cv::NORM_INF), 1.0);
  const cv::Mat3b image = shader.shade(h, 9);
  EXPECT_EQ(image.size(), model.imageSize());
}

// --- synthetic background ------------------------------------------------------------------

void expectRealisticBackground(const cv::Mat3b& bg) {
  // Global mean of real frames: (99, 105, 99); sensors range (87, 92, 90) to (104, 112, 105).
  const cv::Scalar global = cv::mean(bg);
  EXPECT_NEAR(global[0], 99.0, 12.0);
  EXPECT_NEAR(global[1], 105.0, 12.0);
  EXPECT_NEAR(global[2], 99.0, 12.0);
  const double third = 1.0 / 3.0;
  // Real (BGR): top-left (117, 106, 133), top-right (105, 117, 73), bottom-centre (98, 92, 70),
  // centre (102, 123, 134).
  const cv::Scalar top_left = regionMean(bg, 0, 0, third, third);
  const cv::Scalar top_right = regionMean(bg, 2 * third, 0, 1, third);
  const cv::Scalar bottom_centre = regionMean(bg, third, 2 * third, 2 * third, 1);
  const cv::Scalar centre = regionMean(bg, third, third, 2 * third, 2 * third);
  const cv::Scalar bottom_left = regionMean(bg, 0, 2 * third, third, 1);
  const cv::Scalar bottom_right = regionMean(bg, 2 * third, 2 * third, 1, 1);
  const cv::Scalar targets[] = {{117, 106, 133}, {105, 117, 73}, {98, 92, 70}, {102, 123, 134}};
  const cv::Scalar reached[] = {top_left, top_right, bottom_centre, centre};
  for (int region = 0; region < 4; ++region) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(reached[region][k], targets[region][k], 12.0);
  }
  // Reddish glow top-left, green on the right, blue-violet lower-left.
  EXPECT_GT(top_left[2], top_left[0] + 5);
  EXPECT_GT(top_left[2], top_right[2] + 30);
  EXPECT_GT(top_right[1], top_right[2] + 20);
  EXPECT_GT(top_right[1], top_left[1] + 5);
  EXPECT_GT(bottom_centre[0], bottom_centre[2] + 10);
  EXPECT_GT(bottom_left[0], bottom_right[0] + 10);
  EXPECT_GT(bottom_left[0], bottom_left[1]);
  // Vignetting: the corners are darker than the centre.
  const auto brightness = [](const cv::Scalar& s) { return s[0] + s[1] + s[2]; };
  const double corners =
      brightness(regionMean(bg, 0, 0, 0.1, 0.1)) + brightness(regionMean(bg, 0.9, 0, 1, 0.1)) +
      brightness(regionMean(bg, 0, 0.9, 0.1, 1)) + brightness(regionMean(bg, 0.9, 0.9, 1, 1));
  EXPECT_LT(corners / 4.0, 0.85 * brightness(centre));
  // Smooth: neighbours differ by at most a few levels and the Laplacian is quantisation-small
  // (a real frame, with its sensor noise, gives ~2.3).
  cv::Mat3f f;
  bg.convertTo(f, CV_32F);
  const cv::Mat3f dx = f.colRange(1, f.cols) - f.colRange(0, f.cols - 1);
  const cv::Mat3f dy = f.rowRange(1, f.rows) - f.rowRange(0, f.rows - 1);
  EXPECT_LE(cv::norm(dx, cv::NORM_INF), 3.0);
  EXPECT_LE(cv::norm(dy, cv::NORM_INF), 3.0);
  cv::Mat3f laplacian;
  cv::Laplacian(f, laplacian, CV_32F);
  const cv::Scalar lap = cv::mean(cv::abs(laplacian));
  EXPECT_LT((lap[0] + lap[1] + lap[2]) / 3.0, 1.5);
}

TEST(BackgroundTest, SyntheticBackgroundLooksLikeARealDigitFrame) {
  const cv::Mat3b qvga = makeSyntheticBackground({240, 320});
  ASSERT_EQ(qvga.size(), cv::Size(240, 320));
  expectRealisticBackground(qvga);
  EXPECT_TRUE(identical(qvga, makeSyntheticBackground({240, 320})));  // deterministic
}

TEST(BackgroundTest, SyntheticBackgroundWorksAtVgaAndMatchesQvga) {
  const cv::Mat3b vga = makeSyntheticBackground({480, 640});
  ASSERT_EQ(vga.size(), cv::Size(480, 640));
  expectRealisticBackground(vga);
  cv::Mat3b down;
  cv::resize(vga, down, {240, 320}, 0, 0, cv::INTER_AREA);
  EXPECT_LT(meanAbs(difference(down, makeSyntheticBackground({240, 320})), cv::Mat1b()), 1.0);
  EXPECT_THROW(makeSyntheticBackground({0, 10}), Error);
}

// --- bad input and loading -----------------------------------------------------------------

TEST_F(ShaderTest, RejectsBackgroundAndHeightOfTheWrongSize) {
  EXPECT_THROW(DigitShader(model, cv::Mat3b()), Error);
  EXPECT_THROW(DigitShader(model, makeSyntheticBackground({320, 240})), Error);  // landscape
  EXPECT_THROW(DigitShader(model, makeSyntheticBackground({480, 640})), Error);
  SensorModel broken = model;
  broken.noise_sigma = -1.0;
  EXPECT_TRUE(messageContains([&] { const DigitShader bad(broken, background); }, "noise_sigma"));
  EXPECT_THROW(shader.shade(cv::Mat1f(10, 10, 0.0f), -1), Error);
  EXPECT_THROW(shader.shade(cv::Mat1f(), -1), Error);
  EXPECT_THROW(shader.shadingDifference(cv::Mat1f(240, 320, 0.0f)), Error);
  for (const float bad : {std::nanf(""), std::numeric_limits<float>::infinity()}) {
    for (const cv::Point where : {cv::Point(0, 0), cv::Point(120, 160), cv::Point(239, 319)}) {
      cv::Mat1f h = sphericalCap(model, 3.0, 0.5);
      h(where) = bad;
      EXPECT_TRUE(messageContains([&] { shader.shade(h, 1); }, "h_final_mm")) << where;
      EXPECT_THROW(shader.shadingDifference(h), Error) << where;
    }
  }
}

TEST_F(ShaderTest, KeepsItsOwnCopyOfTheBackground) {
  cv::Mat3b mine = background.clone();
  const DigitShader own(model, mine);
  mine.setTo(cv::Scalar(0, 0, 0));
  EXPECT_TRUE(identical(own.shade(flat, -1), background));
}

TEST(BackgroundTest, LoadsGray16BitBgraAndResizes) {
  test::ScratchDirectory dir;
  const cv::Size size(240, 320);

  const cv::Mat3b bgr(size, cv::Vec3b(10, 120, 250));
  ASSERT_TRUE(cv::imwrite(dir.path("bgr.png"), bgr));
  EXPECT_TRUE(identical(loadBackground(dir.path("bgr.png"), size), bgr));

  const cv::Mat1b gray(size, 77);
  ASSERT_TRUE(cv::imwrite(dir.path("gray.png"), gray));
  EXPECT_TRUE(identical(loadBackground(dir.path("gray.png"), size),
                        cv::Mat3b(size, cv::Vec3b(77, 77, 77))));

  const cv::Mat_<cv::Vec3w> deep(size, cv::Vec3w(0, 257 * 100, 65535));
  ASSERT_TRUE(cv::imwrite(dir.path("deep.png"), deep));
  EXPECT_TRUE(identical(loadBackground(dir.path("deep.png"), size),
                        cv::Mat3b(size, cv::Vec3b(0, 100, 255))));

  const cv::Mat4b bgra(size, cv::Vec4b(30, 60, 90, 0));  // fully transparent: alpha ignored
  ASSERT_TRUE(cv::imwrite(dir.path("bgra.png"), bgra));
  EXPECT_TRUE(identical(loadBackground(dir.path("bgra.png"), size),
                        cv::Mat3b(size, cv::Vec3b(30, 60, 90))));

  // A VGA frame for a QVGA model is resized; a smooth one stays the same at half size.
  const cv::Mat3b vga = makeSyntheticBackground({480, 640});
  ASSERT_TRUE(cv::imwrite(dir.path("vga.png"), vga));
  const cv::Mat3b loaded = loadBackground(dir.path("vga.png"), size);
  ASSERT_EQ(loaded.size(), size);
  EXPECT_LT(meanAbs(difference(loaded, makeSyntheticBackground(size)), cv::Mat1b()), 1.0);

  // A loaded background drives the shader.
  const SensorModel model = makeDigitSensorModel();
  const DigitShader shader(model, loadBackground(dir.path("vga.png"), model.imageSize()));
  EXPECT_TRUE(identical(shader.shade(cv::Mat1f(model.rows, model.cols, 0.0f), -1), loaded));
}

TEST(BackgroundTest, BadFilesThrowErrorsNamingTheFile) {
  test::ScratchDirectory dir;
  const cv::Size size(240, 320);
  const std::string missing = dir.path("missing.png");
  EXPECT_TRUE(messageContains([&] { loadBackground(missing, size); }, missing));

  const std::string text = dir.path("notes.png");
  std::ofstream(text) << "this is not an image\n";
  EXPECT_TRUE(messageContains([&] { loadBackground(text, size); }, text));

  const std::string floating = dir.path("float.tiff");
  ASSERT_TRUE(cv::imwrite(floating, cv::Mat3f(size, cv::Vec3f(0.5f, 0.5f, 0.5f))));
  EXPECT_TRUE(messageContains([&] { loadBackground(floating, size); }, floating));

  EXPECT_TRUE(messageContains([&] { loadBackground(dir.root(), size); }, dir.root()));
  EXPECT_THROW(loadBackground(text, cv::Size(0, 0)), Error);

  // A frame the driver did not rotate (landscape for a portrait sensor) is refused, not
  // silently stretched.
  const std::string landscape = dir.path("landscape.png");
  ASSERT_TRUE(cv::imwrite(landscape, makeSyntheticBackground({320, 240})));
  test::expectError([&] { loadBackground(landscape, size); }, {landscape, "landscape", "rotate"});
}

}  // namespace
}  // namespace norm2tex
