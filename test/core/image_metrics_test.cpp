// The frame measures of the calibration report (SSIM, PSNR, mean |diff|, their medians) against
// closed forms and scikit-image, and the small JSON writer the report is written with.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/json_writer.hpp"
#include "norm2tex/calibrate/ball_press.hpp"
#include "norm2tex/calibrate/image_metrics.hpp"
#include "norm2tex/calibrate/press_frame_comparison.hpp"
#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

constexpr int kRows = 24, kCols = 19;  // not square: a transposed index would show

// The pair of the scikit-image reference below: a wrapped ramp pattern, and a halved, shifted,
// clipped other.
cv::Mat3b patternA() {
  cv::Mat3b a(kRows, kCols);
  for (int r = 0; r < kRows; ++r) {
    for (int c = 0; c < kCols; ++c) {
      for (int k = 0; k < 3; ++k) a(r, c)[k] = (r * 37 + c * 91 + k * 53 + r * c * 7) % 256;
    }
  }
  return a;
}

cv::Mat3b patternB() {
  const cv::Mat3b a = patternA();
  cv::Mat3b b(kRows, kCols);
  for (int r = 0; r < kRows; ++r) {
    for (int c = 0; c < kCols; ++c) {
      for (int k = 0; k < 3; ++k) {
        const int value = a(r, c)[k] / 2 + (r * 11 + c * 5 + k * 3 + (r * c) % 13 * 9) % 128 - 10;
        b(r, c)[k] = static_cast<unsigned char>(std::clamp(value, 0, 255));
      }
    }
  }
  return b;
}

cv::Mat1b greenOf(const cv::Mat3b& image) {
  cv::Mat1b green;
  cv::extractChannel(image, green, 1);
  return green;
}

template <typename F>
void expectErrorMentioning(F&& call, const std::string& fragment) {
  try {
    call();
    ADD_FAILURE() << "no Error; expected one mentioning '" << fragment << "'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(ImageMetrics, AnImageAgainstItselfIsPerfect) {
  cv::Mat3b image(40, 30);
  cv::randu(image, 0, 256);
  const ImageSimilarity s = compareImages(image, image);
  EXPECT_DOUBLE_EQ(s.ssim, 1.0);
  EXPECT_DOUBLE_EQ(s.ssim_in_mask, 1.0);
  EXPECT_EQ(s.psnr_db, std::numeric_limits<double>::infinity());
  EXPECT_EQ(s.mean_abs_diff, 0.0);
  EXPECT_DOUBLE_EQ(structuralSimilarity(greenOf(image), greenOf(image)), 1.0);
}

// Reference values from scikit-image 0.19.3 (Debian 12's python3-skimage), computed offline (it
// is not a dependency of the package) with numpy building the same pair:
//   r, c, k = np.meshgrid(np.arange(24), np.arange(19), np.arange(3), indexing="ij")
//   a = ((r * 37 + c * 91 + k * 53 + r * c * 7) % 256).astype(np.uint8)
//   b = np.clip(a.astype(int) // 2 + (r * 11 + c * 5 + k * 3 + (r * c) % 13 * 9) % 128 - 10,
//               0, 255).astype(np.uint8)
//   args = dict(gaussian_weights=True, sigma=1.5, use_sample_covariance=False, data_range=255)
//   m, S = structural_similarity(a, b, channel_axis=2, full=True, **args)       # colour
//   structural_similarity(a[..., 1], b[..., 1], **args)                          # grey
//   yy, xx = np.mgrid[0:24, 0:19]; mask = (xx - 9.0) ** 2 + (yy - 12.0) ** 2 <= 36.0
//   crop = np.zeros_like(mask); crop[5:-5, 5:-5] = True      # skimage's own border for the mean
//   S.mean(axis=2)[mask & crop].mean()                                           # masked
//   peak_signal_noise_ratio(a, b, data_range=255); np.abs(a.astype(float) - b).mean()
TEST(ImageMetrics, MatchScikitImageOnASmallPair) {
  const cv::Mat3b a = patternA(), b = patternB();
  const cv::Mat1b disc = contactDiscMask(a.size(), {9.0, 12.0}, 6.0);
  const ImageSimilarity s = compareImages(a, b, disc);
  EXPECT_NEAR(s.ssim, 0.66294386588891652, 1e-12);
  EXPECT_NEAR(s.ssim_in_mask, 0.68176642682741917, 1e-12);
  EXPECT_NEAR(s.psnr_db, 13.544500206854014, 1e-12);
  EXPECT_NEAR(s.mean_abs_diff, 43.932748538011694, 1e-12);
  EXPECT_NEAR(structuralSimilarity(greenOf(a), greenOf(b)), 0.6893010850316682, 1e-12);
  // Order does not matter for any of them.
  EXPECT_NEAR(compareImages(b, a, disc).ssim_in_mask, s.ssim_in_mask, 1e-15);
}

// Two constant images a, b: every window has zero variance, so SSIM = (2ab + C1) / (a^2 + b^2 +
// C1) exactly (the structure term is C2 / C2), everywhere, whatever the border handling.
TEST(ImageMetrics, ConstantImagesHaveTheClosedForm) {
  const double c1 = (0.01 * 255) * (0.01 * 255);
  for (const auto& [a, b] : {std::pair<int, int>{100, 150}, {0, 255}, {17, 18}, {0, 0}}) {
    const double expected = (2.0 * a * b + c1) / (a * a + b * b + c1);
    const cv::Mat3b image_a(16, 12, cv::Vec3b(a, a, a)), image_b(16, 12, cv::Vec3b(b, b, b));
    EXPECT_NEAR(structuralSimilarity(image_a, image_b), expected, 1e-12) << a << " vs " << b;
    EXPECT_NEAR(meanAbsoluteDifference(image_a, image_b), std::abs(a - b), 1e-12);
  }
}

// +-d around a grey level, alternating pixel by pixel: every squared difference is d^2, so
// MSE = d^2 and PSNR = 10 log10(255^2 / d^2); mean |diff| = d.
TEST(ImageMetrics, PsnrAndMeanDifferenceOfAlternatingNoiseAreExact) {
  for (const int d : {1, 5, 40}) {
    const cv::Mat3b clean(20, 30, cv::Vec3b(128, 128, 128));
    cv::Mat3b noisy = clean.clone();
    for (int r = 0; r < noisy.rows; ++r) {
      for (int c = 0; c < noisy.cols; ++c) {
        const int sign = (r + c) % 2 == 0 ? 1 : -1;
        for (int k = 0; k < 3; ++k) noisy(r, c)[k] = static_cast<unsigned char>(128 + sign * d);
      }
    }
    EXPECT_NEAR(peakSignalToNoiseRatio(clean, noisy), 10.0 * std::log10(255.0 * 255.0 / (d * d)),
                1e-12);
    EXPECT_NEAR(meanAbsoluteDifference(clean, noisy), d, 1e-12);
    EXPECT_LT(structuralSimilarity(clean, noisy), 1.0);
  }
}

TEST(ImageMetrics, MaskOfTheWholeFrameGivesTheFrameSsim) {
  const cv::Mat3b a = patternA(), b = patternB();
  const ImageSimilarity all = compareImages(a, b, cv::Mat1b(a.size(), 255));
  EXPECT_DOUBLE_EQ(all.ssim_in_mask, all.ssim);
  EXPECT_DOUBLE_EQ(compareImages(a, b).ssim_in_mask, all.ssim);  // no mask: everything
  // Only the border's pixels inside a mask is a mask with nothing to average.
  cv::Mat1b border(a.size(), 255);
  border(cv::Rect(5, 5, a.cols - 10, a.rows - 10)).setTo(0);
  expectErrorMentioning([&] { compareImages(a, b, border); }, "border");
}

TEST(ImageMetrics, BadInputIsAClearError) {
  const cv::Mat3b a = patternA();
  expectErrorMentioning([&] { compareImages(a, cv::Mat3b(kRows + 1, kCols)); }, "differ");
  expectErrorMentioning([&] { compareImages(a, greenOf(a)); }, "differ");
  expectErrorMentioning([&] { compareImages(a, cv::Mat3b()); }, "empty");
  expectErrorMentioning([&] { peakSignalToNoiseRatio(cv::Mat(), cv::Mat()); }, "empty");
  expectErrorMentioning([&] { meanAbsoluteDifference(a, cv::Mat3f(a.size())); }, "8-bit");
  expectErrorMentioning([&] { structuralSimilarity(cv::Mat3b(10, 40), cv::Mat3b(10, 40)); },
                        "smaller than the 11 x 11 window");
  expectErrorMentioning([&] { compareImages(a, a, cv::Mat1b(kRows, kCols + 2, 255)); }, "mask");
  expectErrorMentioning([&] { compareImages(a, a, cv::Mat1f(kRows, kCols, 1.0f)); }, "mask");
}

TEST(PressFrameComparison, MediansAndTheContactDisc) {
  std::vector<PressFrameComparison> presses(4);
  const double ssim[] = {0.9, 0.7, 0.95, 0.8}, psnr[] = {30, std::numeric_limits<double>::infinity(),
                                                         25, 28};
  for (int i = 0; i < 4; ++i) {
    presses[i].similarity = {ssim[i], 1.0 - ssim[i], psnr[i], 10.0 * i};
  }
  ImageSimilarity m = medianSimilarity(presses);  // even count: the middle two's mean
  EXPECT_DOUBLE_EQ(m.ssim, 0.85);
  EXPECT_DOUBLE_EQ(m.ssim_in_mask, 0.15);
  EXPECT_DOUBLE_EQ(m.psnr_db, 29.0);
  EXPECT_DOUBLE_EQ(m.mean_abs_diff, 15.0);
  presses.pop_back();
  m = medianSimilarity(presses);
  EXPECT_DOUBLE_EQ(m.ssim, 0.9);
  EXPECT_EQ(m.psnr_db, 30.0);
  EXPECT_THROW(medianSimilarity({}), Error);
  // A disc of radius 2 about a pixel centre: 13 pixels (1 + 4 + 4 + 4 at distance 2).
  EXPECT_EQ(cv::countNonZero(contactDiscMask({9, 7}, {4.0, 3.0}, 2.0)), 13);
  // The ball's depth: R - sqrt(R^2 - a^2) = 3 - 2.4 for a 3 mm ball and a 1.8 mm contact.
  EXPECT_NEAR(ballPressDepthMm(1.8, 3.0), 0.6, 1e-12);
  EXPECT_THROW(ballPressDepthMm(3.0, 3.0), Error);
}

TEST(JsonWriter, WritesNestedValuesAndRefusesMisuse) {
  JsonWriter json;
  json.beginObject();
  json.key("name \"q\"\n").value("a\\b");
  json.key("list").beginArray().value(1).value(0.1).value(true).endArray();
  json.key("inf").value(std::numeric_limits<double>::infinity());
  json.key("empty").beginObject().endObject();
  json.endObject();
  EXPECT_EQ(json.text(),
            "{\n  \"name \\\"q\\\"\\u000a\": \"a\\\\b\",\n  \"list\": [\n    1,\n    0.1,\n"
            "    true\n  ],\n  \"inf\": null,\n  \"empty\": {}\n}\n");
  // Numbers read back exactly.
  for (const double x : {0.1, 1.0 / 3.0, 33.781191841016664, 1e-300, -2.5}) {
    EXPECT_EQ(std::stod(jsonNumber(x)), x) << jsonNumber(x);
  }
  EXPECT_EQ(jsonNumber(0.1), "0.1");
  JsonWriter bad;
  bad.beginObject();
  EXPECT_THROW(bad.value(1), Error);    // a value without its key
  EXPECT_THROW(bad.endArray(), Error);  // closes what is not open
  EXPECT_THROW(bad.text(), Error);      // not complete
  JsonWriter array;
  array.beginArray();
  EXPECT_THROW(array.key("x"), Error);
}

}  // namespace
}  // namespace norm2tex
