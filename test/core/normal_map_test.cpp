#include <cmath>
#include <fstream>
#include <iterator>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/texture/normal_encoding.hpp"
#include "norm2tex/texture/normal_map.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

// One texel, given as R, G, B in [0, 255]; OpenCV stores B, G, R.
cv::Mat texel8(int red, int green, int blue) {
  return cv::Mat(1, 1, CV_8UC3, cv::Scalar(blue, green, red));
}

TEST(NormalMap, FlatTexelDecodesToStraightUp) {
  const NormalMap map = NormalMap::fromImage(texel8(128, 128, 255));
  const cv::Vec3f n = map.normals()(0, 0);
  EXPECT_NEAR(n[0], 0.0, 0.01);
  EXPECT_NEAR(n[1], 0.0, 0.01);
  EXPECT_NEAR(n[2], 1.0, 1e-4);
  EXPECT_EQ(map.validCount(), 1);
}

TEST(NormalMap, OpenGLGreenPointsUpTheImage) {
  // Green high = normal tilted towards +v = towards row 0 = image-frame -y.
  NormalMapOptions gl;
  const cv::Vec3f up = NormalMap::fromImage(texel8(128, 200, 230), gl).normals()(0, 0);
  EXPECT_LT(up[1], -0.2);
  NormalMapOptions dx;
  dx.convention = NormalConvention::kDirectX;
  const cv::Vec3f down = NormalMap::fromImage(texel8(128, 200, 230), dx).normals()(0, 0);
  EXPECT_GT(down[1], 0.2);
  EXPECT_NEAR(up[1], -down[1], 1e-6);
}

TEST(NormalMap, SlopesOfATiltedPlaneRecoverTheTilt) {
  // h = 0.3 column - 0.2 row: every texel has dx = 0.3, dy = -0.2.
  const cv::Mat1f dx(8, 8, 0.3f), dy(8, 8, -0.2f);
  for (const NormalConvention convention :
       {NormalConvention::kOpenGL, NormalConvention::kDirectX}) {
    const cv::Mat image = encodeNormalMap(dx, dy, convention, CV_16U);
    NormalMapOptions options;
    options.convention = convention;
    const NormalMap map = NormalMap::fromImage(image, options);
    cv::Mat1f gx, gy;
    normalsToGradients(map.normals(), map.valid(), options.min_nz, gx, gy);
    EXPECT_NEAR(gx(4, 4), 0.3, 1e-4) << toString(convention);
    EXPECT_NEAR(gy(4, 4), -0.2, 1e-4) << toString(convention);
  }
}

TEST(NormalMap, DirectXMapDecodedAsDirectXEqualsOpenGLMapDecodedAsOpenGL) {
  const cv::Size size(64, 48);
  AnalyticSurface surface = makeWaves(size, {{2.0, 17.0, 0.7, 0.2}});
  surface += makeBumps(size, {{{20, 30}, 6.0, 5.0}});
  for (const int depth : {CV_8U, CV_16U}) {
    const cv::Mat gl_image =
        encodeNormalMap(surface.dx, surface.dy, NormalConvention::kOpenGL, depth);
    const cv::Mat dx_image =
        encodeNormalMap(surface.dx, surface.dy, NormalConvention::kDirectX, depth);
    ASSERT_GT(cv::norm(gl_image, dx_image, cv::NORM_INF), 0.0) << "green must differ";
    NormalMapOptions gl, dx;
    dx.convention = NormalConvention::kDirectX;
    const NormalMap a = NormalMap::fromImage(gl_image, gl);
    const NormalMap b = NormalMap::fromImage(dx_image, dx);
    // Quantisation rounds the flipped green a half step differently at most.
    EXPECT_LT(cv::norm(a.normals(), b.normals(), cv::NORM_INF), depth == CV_8U ? 0.01 : 5e-5);
    EXPECT_EQ(cv::countNonZero(a.valid() != b.valid()), 0);
  }
}

TEST(NormalMap, SixteenBitIsFinerThanEightBit) {
  const cv::Size size(32, 32);
  const AnalyticSurface surface = makeWaves(size, {{1.5, 11.0, 0.3, 0.0}});
  const cv::Mat1b all(size, 255);
  double error8 = 0, error16 = 0;
  for (const int depth : {CV_8U, CV_16U}) {
    const NormalMap map = test::quantisedNormalMap(surface, all, depth);
    cv::Mat1f gx, gy;
    normalsToGradients(map.normals(), map.valid(), 1e-3, gx, gy);
    (depth == CV_8U ? error8 : error16) = cv::norm(gx, surface.dx, cv::NORM_INF);
  }
  EXPECT_LT(error16, error8 / 50.0);
  EXPECT_LT(error8, 0.05);
}

/// encodeNormalMapFromHeight's definition written out texel by texel, as it was first
/// implemented: central differences inside the mask, one-sided at its edges, std::round.
cv::Mat referenceFromHeight(const cv::Mat1f& h, const cv::Mat1b& mask, int depth, float y_sign) {
  const double full = depth == CV_8U ? 255.0 : 65535.0;
  const auto inside = [&](int r, int c) {
    return r >= 0 && c >= 0 && r < h.rows && c < h.cols && mask(r, c) != 0;
  };
  const auto slope = [&](int r, int c, int dr, int dc) {
    const bool f = inside(r + dr, c + dc), b = inside(r - dr, c - dc);
    if (f && b) return 0.5f * (h(r + dr, c + dc) - h(r - dr, c - dc));
    if (f) return h(r + dr, c + dc) - h(r, c);
    if (b) return h(r, c) - h(r - dr, c - dc);
    return 0.0f;
  };
  cv::Mat out(h.size(), CV_MAKETYPE(depth, 3));
  for (int r = 0; r < h.rows; ++r) {
    for (int c = 0; c < h.cols; ++c) {
      float x = 0.0f, y = 0.0f, z = 1.0f;
      if (inside(r, c)) {
        const float gx = slope(r, c, 0, 1), gy = slope(r, c, 1, 0);
        const float length = std::sqrt(gx * gx + gy * gy + 1.0f);
        x = -gx / length;
        y = -gy / length;
        z = 1.0f / length;
      }
      const float components[3] = {z, y_sign * y, x};
      for (int k = 0; k < 3; ++k) {
        const double v = std::round((components[k] + 1.0) * 0.5 * full);
        if (depth == CV_8U) {
          out.at<cv::Vec3b>(r, c)[k] = cv::saturate_cast<uchar>(v);
        } else {
          out.at<cv::Vec3w>(r, c)[k] = cv::saturate_cast<ushort>(v);
        }
      }
    }
  }
  return out;
}

TEST(NormalEncoding, FromHeightEqualsTheTexelByTexelDefinitionBitForBit) {
  cv::Mat1f height(37, 53);
  cv::randu(height, -4.0f, 4.0f);
  height(5, 7) = 0.0f;  // a few exact values: flat neighbourhoods quantise to exact halves
  cv::Mat1b mask(height.size(), uchar(255));
  cv::Mat1b holes(height.size());
  cv::randu(holes, 0, 4);
  mask.setTo(0, holes == 0);  // ~25 % masked: many one-sided and isolated texels
  mask.row(0).setTo(0);
  for (const int depth : {CV_8U, CV_16U}) {
    for (const NormalConvention convention :
         {NormalConvention::kOpenGL, NormalConvention::kDirectX}) {
      const float y_sign = convention == NormalConvention::kOpenGL ? -1.0f : 1.0f;
      const cv::Mat expected = referenceFromHeight(height, mask, depth, y_sign);
      const cv::Mat encoded = encodeNormalMapFromHeight(height, convention, depth, mask);
      ASSERT_EQ(encoded.type(), expected.type());
      EXPECT_EQ(cv::norm(encoded, expected, cv::NORM_INF), 0.0) << "depth " << depth;
      const cv::Mat1b everywhere(height.size(), uchar(255));
      EXPECT_EQ(cv::norm(encodeNormalMapFromHeight(height, convention, depth),
                         referenceFromHeight(height, everywhere, depth, y_sign), cv::NORM_INF),
                0.0)
          << "no mask = every texel valid";

      // With alpha: the same colours, alpha full scale on the mask and 0 off it.
      const cv::Mat bgra = encodeNormalMapFromHeight(height, convention, depth, mask, true);
      ASSERT_EQ(bgra.channels(), 4);
      std::vector<cv::Mat> channels;
      cv::split(bgra, channels);
      cv::Mat bgr;
      cv::merge(std::vector<cv::Mat>{channels[0], channels[1], channels[2]}, bgr);
      EXPECT_EQ(cv::norm(bgr, expected, cv::NORM_INF), 0.0);
      cv::Mat expected_alpha;
      mask.convertTo(expected_alpha, depth, depth == CV_8U ? 1.0 : 257.0);
      EXPECT_EQ(cv::norm(channels[3], expected_alpha, cv::NORM_INF), 0.0);
    }
  }
  test::expectError(
      [&] {
        encodeNormalMapFromHeight(height, NormalConvention::kOpenGL, CV_16U, cv::Mat1b(3, 3));
      },
      {"mask", "size"});
}

TEST(NormalMap, AlphaIsTheValidityMask) {
  cv::Mat image(2, 2, CV_8UC4, cv::Scalar(255, 128, 128, 255));
  image.at<cv::Vec4b>(0, 1)[3] = 0;
  image.at<cv::Vec4b>(1, 0)[3] = 100;  // below the default threshold 0.5
  const NormalMap map = NormalMap::fromImage(image);
  EXPECT_EQ(map.valid()(0, 0), 255);
  EXPECT_EQ(map.valid()(0, 1), 0);
  EXPECT_EQ(map.valid()(1, 0), 0);
  EXPECT_EQ(map.valid()(1, 1), 255);
  EXPECT_EQ(map.normals()(0, 1), cv::Vec3f(0, 0, 0));
}

TEST(NormalMap, ExplicitMaskOverridesAlpha) {
  const cv::Mat image(2, 2, CV_16UC4, cv::Scalar(65535, 32768, 32768, 0));  // alpha says: invalid
  cv::Mat1b mask(2, 2, uchar(0));
  mask(1, 1) = 1;
  const NormalMap map = NormalMap::fromImage(image, {}, mask);
  EXPECT_EQ(map.validCount(), 1);
  EXPECT_EQ(map.valid()(1, 1), 255);
}

TEST(NormalMap, GrazingAndDegenerateTexelsAreMaskedNotDividedByZero) {
  cv::Mat image(1, 3, CV_8UC3);
  image.at<cv::Vec3b>(0, 0) = cv::Vec3b(128, 128, 255);  // straight up
  image.at<cv::Vec3b>(0, 1) = cv::Vec3b(127, 128, 255);  // nz = 0 after decoding (B = 127)
  image.at<cv::Vec3b>(0, 2) = cv::Vec3b(0, 128, 128);    // points into the surface
  const NormalMap map = NormalMap::fromImage(image);
  EXPECT_EQ(map.valid()(0, 0), 255);
  EXPECT_EQ(map.valid()(0, 1), 0);
  EXPECT_EQ(map.valid()(0, 2), 0);
  cv::Mat1f gx, gy;
  normalsToGradients(map.normals(), map.valid(), 1e-3, gx, gy);
  EXPECT_TRUE(cv::checkRange(gx) && cv::checkRange(gy));
}

TEST(NormalMap, NaNTexelsOfAFloatImageAreMasked) {
  cv::Mat image(1, 2, CV_32FC3, cv::Scalar(1.0, 0.5, 0.5));
  image.at<cv::Vec3f>(0, 1)[1] = std::nanf("");
  const NormalMap map = NormalMap::fromImage(image);
  EXPECT_EQ(map.valid()(0, 0), 255);
  EXPECT_EQ(map.valid()(0, 1), 0);
  EXPECT_TRUE(cv::checkRange(map.normals()));
}

TEST(NormalMap, NonSquareImagesKeepTheirShape) {
  const NormalMap map = NormalMap::fromImage(cv::Mat(3, 7, CV_8UC3, cv::Scalar(255, 128, 128)));
  EXPECT_EQ(map.rows(), 3);
  EXPECT_EQ(map.cols(), 7);
}

TEST(NormalMapErrors, RejectsGrayscaleTwoChannelAndEmptyImages) {
  EXPECT_THROW(NormalMap::fromImage(cv::Mat(4, 4, CV_8UC1, cv::Scalar(128))), Error);
  EXPECT_THROW(NormalMap::fromImage(cv::Mat(4, 4, CV_8UC2, cv::Scalar(128))), Error);
  EXPECT_THROW(NormalMap::fromImage(cv::Mat()), Error);
  EXPECT_THROW(NormalMap::fromImage(cv::Mat(4, 4, CV_64FC3, cv::Scalar(1))), Error);
  try {
    NormalMap::fromImage(cv::Mat(4, 4, CV_8UC1, cv::Scalar(128)));
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("grayscale"), std::string::npos) << e.what();
  }
}

TEST(NormalMapErrors, RejectsAMaskOfAnotherSize) {
  EXPECT_THROW(NormalMap::fromImage(cv::Mat(4, 4, CV_8UC3, cv::Scalar(255, 128, 128)), {},
                                    cv::Mat1b(3, 4, uchar(255))),
               Error);
}

TEST(NormalMapErrors, FileProblemsNameTheFile) {
  test::ScratchDirectory dir;
  const auto expectError = [](const std::string& path, const std::string& fragment) {
    try {
      NormalMap::load(path);
      ADD_FAILURE() << "no error for " << path;
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path), std::string::npos) << message;
      EXPECT_NE(message.find(fragment), std::string::npos) << message;
    }
  };
  expectError(dir.path("missing.png"), "does not exist");
  std::ofstream(dir.path("empty.png")).close();
  expectError(dir.path("empty.png"), "empty file");
  std::ofstream(dir.path("corrupt.png")) << "\x89PNG\r\n\x1a\nthis is not really a png";
  expectError(dir.path("corrupt.png"), "corrupt");
  expectError(dir.root(), "directory");
  cv::imwrite(dir.path("gray.png"), cv::Mat(4, 4, CV_8UC1, cv::Scalar(7)));
  expectError(dir.path("gray.png"), "grayscale");
}

TEST(NormalMapErrors, TruncatedFilesAreRefusedNotDecodedAsGrey) {
  // libjpeg decodes a truncated JPEG with grey rows (a constant tilt); every cut must fail,
  // whatever the format, and the intact file must load.
  test::ScratchDirectory dir;
  const cv::Size size(64, 48);
  const AnalyticSurface s = makeWaves(size, {{2.0, 20.0, 0.4, 0.0}});
  const cv::Mat image = encodeNormalMap(s.dx, s.dy, NormalConvention::kOpenGL, CV_8U);
  for (const std::string name : {"map.png", "map.jpg", "map.tif"}) {
    ASSERT_TRUE(cv::imwrite(dir.path(name), image));
    std::ifstream file(dir.path(name), std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(file)),
                            std::istreambuf_iterator<char>());
    EXPECT_NO_THROW(NormalMap::load(dir.path(name))) << name;
    for (const size_t cut : {size_t(200), bytes.size() / 2, bytes.size() - 40}) {
      const std::string truncated = dir.path("cut_" + std::to_string(cut) + "_" + name);
      std::ofstream(truncated, std::ios::binary) << bytes.substr(0, cut);
      test::expectError([&] { NormalMap::load(truncated); }, {truncated, "corrupt"});
    }
  }
}

TEST(NormalMapErrors, OptionsOutOfRangeAreRejected) {
  NormalMapOptions options;
  options.min_nz = 1.0;
  EXPECT_THROW(validate(options), Error);
  options.min_nz = 1e-3;
  options.alpha_threshold = -0.1;
  EXPECT_THROW(validate(options), Error);
  EXPECT_THROW(parseNormalConvention("vulkan"), Error);
  EXPECT_EQ(parseNormalConvention("DirectX"), NormalConvention::kDirectX);
}

TEST(NormalMap, LoadsSixteenBitRgbaFromDisk) {
  test::ScratchDirectory dir;
  cv::Mat image(5, 6, CV_16UC4, cv::Scalar(65535, 32768, 32768, 65535));
  image.at<cv::Vec4w>(2, 3)[3] = 0;
  ASSERT_TRUE(cv::imwrite(dir.path("n.png"), image));
  const NormalMap map = NormalMap::load(dir.path("n.png"));
  EXPECT_EQ(map.validCount(), 29);
  EXPECT_EQ(map.valid()(2, 3), 0);
}

TEST(NormalMap, LoadsTiffAndJpegLikePng) {
  // The same relief through 16-bit TIFF, 8-bit PNG and JPEG (lossy, so only close).
  test::ScratchDirectory dir;
  const cv::Size size(64, 40);
  const AnalyticSurface s = makeWaves(size, {{1.5, 20.0, 0.5, 0.0}});
  ASSERT_TRUE(cv::imwrite(dir.path("n.tiff"),
                          encodeNormalMap(s.dx, s.dy, NormalConvention::kOpenGL, CV_16U)));
  const cv::Mat image8 = encodeNormalMap(s.dx, s.dy, NormalConvention::kOpenGL, CV_8U);
  ASSERT_TRUE(cv::imwrite(dir.path("n.png"), image8));
  ASSERT_TRUE(cv::imwrite(dir.path("n.jpg"), image8, {cv::IMWRITE_JPEG_QUALITY, 98}));
  const NormalMap tiff = NormalMap::load(dir.path("n.tiff"));
  const NormalMap png = NormalMap::load(dir.path("n.png"));
  const NormalMap jpeg = NormalMap::load(dir.path("n.jpg"));
  EXPECT_EQ(tiff.rows(), 40);
  EXPECT_EQ(tiff.cols(), 64);
  EXPECT_LT(cv::norm(tiff.normals(), png.normals(), cv::NORM_INF), 0.01);
  // JPEG subsamples chroma: single texels stray, the average stays close.
  const double jpeg_mean_error =
      cv::norm(tiff.normals(), jpeg.normals(), cv::NORM_L1) / (3.0 * 64 * 40);
  EXPECT_LT(jpeg_mean_error, 0.01);
  EXPECT_LT(cv::norm(tiff.normals(), jpeg.normals(), cv::NORM_INF), 0.15);
  EXPECT_EQ(jpeg.validCount(), 64 * 40);
}

}  // namespace
}  // namespace norm2tex
