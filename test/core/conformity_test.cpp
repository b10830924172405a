// GelConformity: Johnson's wavy-surface contact against its analytic truth, the renderer's
// texture against force and pressure, conformity off = the fixed-depth overlay bit for bit.
#include <cmath>
#include <fstream>
#include <optional>
#include <string>
#include <limits>
#include <memory>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/render/contact_rasterizer.hpp"
#include "norm2tex/render/gel_conformity.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "norm2tex/gel/gel_law.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

// ---------------------------------------------------------------------------------------------
// (a) A 1-D sinusoid pressed flat.

// The relief Delta cos(2 pi c / lambda) over 5 whole periods, crests on the first and last
// column: symmetric about both, so the bands' mirrored borders continue it exactly.
constexpr int kWavelengthPx = 200, kCols = 5 * kWavelengthPx + 1, kRows = 9;
constexpr double kMmPerPixel = 0.01;  // lambda = 2 mm
constexpr double kAmplitudeMm = 0.05;
constexpr double kModulusMpa = 0.1;

struct SinusoidPress {
  cv::Mat1f relief, followed;
  ConformityStats stats;
};

// p* = pi E* Delta / lambda (Johnson 1985, 13.2); the press at mean pressure ratio * p*.
double fullContactPressureMpa() {
  return CV_PI * kModulusMpa * kAmplitudeMm / (kWavelengthPx * kMmPerPixel);
}

SinusoidPress pressSinusoid(double pressure_ratio, double coating_length_mm = 0.0) {
  SinusoidPress press;
  press.relief.create(kRows, kCols);
  for (int r = 0; r < kRows; ++r) {
    for (int c = 0; c < kCols; ++c) {
      press.relief(r, c) =
          static_cast<float>(kAmplitudeMm * std::cos(2.0 * CV_PI * c / kWavelengthPx));
    }
  }
  const cv::Mat1f indentation(kRows, kCols, 0.5f);  // flat: uniform pressure
  const double area_mm2 = kRows * kCols * kMmPerPixel * kMmPerPixel;
  const double force_n = pressure_ratio * fullContactPressureMpa() * area_mm2;
  ConformityOptions options;
  options.enabled = true;
  options.contact_modulus_mpa = kModulusMpa;
  options.coating_length_mm = coating_length_mm;
  GelConformity conformity(options, kMmPerPixel);
  press.stats = conformity.apply(indentation, press.relief, 1.0, cv::Rect(0, 0, kCols, kRows),
                                 force_n, press.followed);
  return press;
}

// Half the peak-to-valley of the followed relief along the middle row.
double renderedAmplitudeMm(const SinusoidPress& press) {
  double lo = 0, hi = 0;
  cv::minMaxLoc(press.followed.row(kRows / 2), &lo, &hi);
  return 0.5 * (hi - lo);
}

// Where the gel touches the relief: there it follows the relief (up to a constant, the
// clipping's mean rise taken off); over the valleys it spans, it is flat at its lowest level.
double contactFraction(const SinusoidPress& press) {
  const int r = kRows / 2;
  double lowest = 0;
  cv::minMaxLoc(press.followed.row(r), &lowest);
  int touching = 0;
  for (int c = 0; c < kCols; ++c) {
    if (press.followed(r, c) > lowest + 1e-4 * kAmplitudeMm) ++touching;
  }
  return static_cast<double>(touching) / kCols;
}

TEST(GelConformity, SinusoidIsFollowedFromItsCrestsAsJohnsonSays) {
  // The measured wavelength and p* are the sinusoid's own.
  const SinusoidPress half = pressSinusoid(0.5);
  EXPECT_NEAR(half.stats.relief_amplitude_mm, kAmplitudeMm, 1e-3 * kAmplitudeMm);
  // Bands holding only a sliver of the sinusoid are folded into the coarser ones (amplitude 0);
  // the one that holds it sees its wavelength and p*.
  int bands_holding_it = 0;
  for (const ConformityBand& band : half.stats.bands) {
    if (band.amplitude_mm == 0.0) continue;
    ++bands_holding_it;
    EXPECT_NEAR(band.wavelength_mm, kWavelengthPx * kMmPerPixel, 0.01 * kWavelengthPx * kMmPerPixel);
    EXPECT_NEAR(band.full_contact_pressure_mpa, fullContactPressureMpa(),
                0.01 * fullContactPressureMpa());
  }
  EXPECT_GE(bands_holding_it, 1);
  // The gel's mean indentation is the physics': clipping the valleys does not raise it.
  for (double ratio : {0.0, 0.3, 0.8}) {
    EXPECT_NEAR(cv::mean(pressSinusoid(ratio).followed)[0], 0.0, 1e-2 * kAmplitudeMm) << ratio;
  }
  // p << p*: the gel spans the valleys, touching only the crests: hardly any relief.
  EXPECT_LT(renderedAmplitudeMm(pressSinusoid(0.01)), 0.02 * kAmplitudeMm);
  // It grows with the pressure ...
  double previous = renderedAmplitudeMm(pressSinusoid(0.01));
  for (double ratio : {0.25, 0.5, 0.75, 0.95}) {
    const double amplitude = renderedAmplitudeMm(pressSinusoid(ratio));
    EXPECT_GT(amplitude, previous + 0.1 * kAmplitudeMm) << "p / p* = " << ratio;
    previous = amplitude;
  }
  // ... and is the full relief from p* on.
  for (double ratio : {1.0, 1.5, 4.0}) {
    const SinusoidPress press = pressSinusoid(ratio);
    EXPECT_NEAR(renderedAmplitudeMm(press), kAmplitudeMm, 0.05 * kAmplitudeMm) << ratio;
    EXPECT_LT(cv::norm(press.followed, press.relief, cv::NORM_INF), 5e-3 * kAmplitudeMm) << ratio;
  }
}

TEST(GelConformity, ACoatingRaisesTheFullContactPressureAsAPlateOnTheGel) {
  // A plate of bending length l on the half-space: p* grows by (1 + (2 pi l / lambda)^3), here
  // 1 + (2 pi 0.5 / 2)^3 = 4.9 for the 2 mm sinusoid; the same pressure follows less of it.
  const double l = 0.5, lambda = kWavelengthPx * kMmPerPixel;
  const double stiffening = 1.0 + std::pow(2.0 * CV_PI * l / lambda, 3);
  const SinusoidPress coated = pressSinusoid(0.5 * stiffening, l);
  bool checked = false;
  for (const ConformityBand& band : coated.stats.bands) {
    if (band.amplitude_mm == 0.0) continue;
    checked = true;
    EXPECT_NEAR(band.full_contact_pressure_mpa, stiffening * fullContactPressureMpa(),
                0.01 * stiffening * fullContactPressureMpa());
  }
  EXPECT_TRUE(checked);
  // At 4.9 times the pressure the bare gel needs for half the relief, the coated one follows
  // half of it too; at the bare gel's pressure, a fifth.
  EXPECT_NEAR(renderedAmplitudeMm(coated), renderedAmplitudeMm(pressSinusoid(0.5)),
              0.03 * kAmplitudeMm);
  EXPECT_NEAR(renderedAmplitudeMm(pressSinusoid(0.5, l)),
              renderedAmplitudeMm(pressSinusoid(0.5)) / stiffening, 0.01 * kAmplitudeMm);
  // Without a coating the relief is Johnson's, bit for bit.
  const SinusoidPress bare = pressSinusoid(0.5), zero = pressSinusoid(0.5, 0.0);
  EXPECT_EQ(cv::norm(bare.followed, zero.followed, cv::NORM_INF), 0.0);
}

TEST(GelConformity, ContactPatchesHaveJohnsonsWidth) {
  for (double ratio : {0.25, 0.5, 0.75}) {
    // sin^2(pi a / lambda) = p / p*: patches of width 2a per wavelength.
    const double expected = 2.0 / CV_PI * std::asin(std::sqrt(ratio));
    const SinusoidPress press = pressSinusoid(ratio);
    EXPECT_NEAR(contactFraction(press), expected, 0.05 * expected) << "p / p* = " << ratio;
    // The depth followed is the part of the relief above the patch edge: p / p* of it.
    EXPECT_NEAR(renderedAmplitudeMm(press), ratio * kAmplitudeMm, 0.05 * ratio * kAmplitudeMm);
  }
}

TEST(GelConformity, BallFollowsMoreTextureAtItsCentreThanAtItsRim) {
  // A 10 mm ball pressed 0.5 mm (a paraboloid of indentation) with the gel law's 4.7 N on a
  // smooth random relief of +-0.1 mm: the Winkler pressure falls from the centre to 0 at the
  // rim, so the share of the relief the gel follows (its RMS over the relief's) falls too.
  const double mm_per_pixel = 0.054, radius_mm = 5.0, press_mm = 0.5;
  const int size = 121;
  cv::Mat1f relief(size, size), indentation(size, size);
  cv::RNG rng(7);
  rng.fill(relief, cv::RNG::UNIFORM, -1.0, 1.0);
  cv::GaussianBlur(relief, relief, cv::Size(), 1.5, 1.5);
  cv::normalize(relief, relief, -0.1, 0.1, cv::NORM_MINMAX);
  const double contact_radius_mm = std::sqrt(2.0 * radius_mm * press_mm);
  cv::Mat1b centre = cv::Mat1b::zeros(size, size), rim = centre.clone();
  for (int r = 0; r < size; ++r) {
    for (int c = 0; c < size; ++c) {
      const double d_mm = std::hypot(r - size / 2, c - size / 2) * mm_per_pixel;
      indentation(r, c) = static_cast<float>(std::max(0.0, press_mm - d_mm * d_mm / (2 * radius_mm)));
      const double d = d_mm / contact_radius_mm;
      if (d < 0.5) centre(r, c) = 255;
      if (d > 0.8 && d < 0.97) rim(r, c) = 255;
    }
  }
  const double force_n = GelLaw::taximDefault().force(press_mm * 1e-3);
  for (double modulus : {0.1, 1.0}) {
    ConformityOptions options;
    options.enabled = true;
    options.contact_modulus_mpa = modulus;
    GelConformity conformity(options, mm_per_pixel);
    cv::Mat1f followed;
    conformity.apply(indentation, relief, 1.0, cv::Rect(0, 0, size, size), force_n, followed);
    const double share_centre =
        test::maskedStdDev(followed, centre) / test::maskedStdDev(relief, centre);
    const double share_rim = test::maskedStdDev(followed, rim) / test::maskedStdDev(relief, rim);
    // At 0.1 MPa (the default) the ball's pressure exceeds p* over most of the rim band too;
    // a stiffer gel's p* lies between the centre's pressure and the rim's.
    EXPECT_GT(share_centre, share_rim * (modulus < 0.5 ? 1.005 : 1.2))
        << "E* " << modulus << " MPa: centre " << share_centre << ", rim " << share_rim;
    EXPECT_LE(share_centre, 1.0 + 1e-3);
  }
}

TEST(GelConformity, BadInputIsAClearError) {
  ConformityOptions options;
  const cv::Mat1f field(4, 4, 0.1f);
  cv::Mat1f out;
  GelConformity conformity(options, 0.05);
  const cv::Rect box(0, 0, 4, 4);
  test::expectError([&] { conformity.apply(field, field, 1.0, box, -1.0, out); },
                    {"normal force", "-1", ">= 0 N"});
  test::expectError(
      [&] {
        conformity.apply(field, field, 1.0, box, std::numeric_limits<double>::quiet_NaN(), out);
      },
      {"normal force", "nan"});
  test::expectError([&] { conformity.apply(field, field, -0.1, box, 1.0, out); }, {"beta"});
  test::expectError([&] { conformity.apply(field, cv::Mat1f(3, 4, 0.0f), 1.0, box, 1.0, out); },
                    {"differ in size"});
  options.contact_modulus_mpa = 0.0;
  test::expectError([&] { GelConformity bad(options, 0.05); },
                    {"conformity.contact_modulus_mpa", "(0, 100] MPa"});
  options.contact_modulus_mpa = std::numeric_limits<double>::quiet_NaN();
  test::expectError([&] { GelConformity bad(options, 0.05); }, {"conformity.contact_modulus_mpa"});
}

// ---------------------------------------------------------------------------------------------
// The renderer.

Eigen::Isometry3d poseMm(double x_mm, double y_mm, double z_mm) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(x_mm, y_mm, z_mm) * 1e-3;
  return pose;
}

/// A smooth random texture in [-1, 1] that tiles (as render_test's).
std::shared_ptr<const HeightAtlas> randomAtlas(double blur_texels) {
  const int size = 256, pad = 24;
  cv::Mat1f noise(size, size);
  cv::RNG rng(42);
  rng.fill(noise, cv::RNG::UNIFORM, -1.0, 1.0);
  cv::Mat1f padded;
  cv::copyMakeBorder(noise, padded, pad, pad, pad, pad, cv::BORDER_WRAP);
  cv::GaussianBlur(padded, padded, cv::Size(0, 0), blur_texels, blur_texels);
  noise = padded(cv::Rect(pad, pad, size, size)).clone();
  cv::normalize(noise, noise, -1.0, 1.0, cv::NORM_MINMAX);
  return std::make_shared<const HeightAtlas>(noise, cv::Mat1b(size, size, 255));
}

SensorModel conformingSensor() {
  SensorModel model = makeDigitSensorModel();
  model.conformity.enabled = true;
  return model;
}

/// RMS of the texture in the image over `mask`: the textured frame minus the textureless one at
/// the same pose, less its own 0.5 mm blur. The texture is the fine part of the difference;
/// the smooth part (the rim moving a little with the texture's mean level) is not texture.
double textureRms(const cv::Mat3b& textured, const cv::Mat3b& plain, const cv::Mat1b& mask) {
  cv::Mat3f difference, smooth;
  cv::subtract(cv::Mat3f(textured), cv::Mat3f(plain), difference);
  const double sigma_px = 0.5 / makeDigitSensorModel().mm_per_pixel;
  cv::GaussianBlur(difference, smooth, cv::Size(), sigma_px, sigma_px, cv::BORDER_REFLECT);
  difference -= smooth;
  cv::Scalar mean, deviation;
  cv::meanStdDev(difference, mean, deviation, mask);
  return std::sqrt(deviation[0] * deviation[0] + deviation[1] * deviation[1] +
                   deviation[2] * deviation[2]);
}

TEST(ConformityRender, FlatFaceShowsMoreTextureTheHarderItIsPressed) {
  // A face larger than the gel, pressed as deep as the gel law says for each force.
  const auto box = std::make_shared<const TexturedMesh>(makeBox({0.06, 0.06, 0.01}, 0.02));
  const GelLaw law = GelLaw::taximDefault();
  TactileRenderer textured(conformingSensor()), plain(conformingSensor());
  textured.setObject(box, randomAtlas(1.0), 0.1);  // relief +-0.1 mm: p* within 2-12 N
  plain.setObject(box);
  const std::vector<double> forces = {2.0, 5.0, 12.0};
  std::vector<cv::Mat3b> textured_images, plain_images;
  cv::Mat1b in_contact_at_all(makeDigitSensorModel().imageSize(), 255);
  for (double force : forces) {
    const auto pose = poseMm(0.0, 0.0, 5.0 - law.indentation(force) * 1e3);
    const TactileFrame& frame = textured.render(pose, -1, force);
    ASSERT_TRUE(frame.conformity.has_value());
    textured_images.push_back(frame.image.clone());
    const TactileFrame& smooth = plain.render(pose, -1, force);
    plain_images.push_back(smooth.image.clone());
    cv::bitwise_and(in_contact_at_all, smooth.contact_mask, in_contact_at_all);
  }
  ASSERT_GT(cv::countNonZero(in_contact_at_all), 1000);
  std::vector<double> rms;
  for (std::size_t i = 0; i < forces.size(); ++i) {
    rms.push_back(textureRms(textured_images[i], plain_images[i], in_contact_at_all));
  }
  EXPECT_GT(rms[1], rms[0] * 1.1) << rms[0] << " at 2 N, " << rms[1] << " at 5 N";
  EXPECT_GT(rms[2], rms[1] * 1.1) << rms[1] << " at 5 N, " << rms[2] << " at 12 N";
}

TEST(ConformityRender, BallShowsMoreTextureAtItsCentreThanNearItsRim) {
  // A 10 mm ball pressed 0.5 mm, its force from the gel law (4.7 N): the Winkler pressure is
  // highest at the centre and falls to 0 at the rim, so the centre shows more of the texture,
  // the more so the stiffer the gel.
  const double radius_mm = 5.0, press_mm = 0.5;
  const auto ball =
      std::make_shared<const TexturedMesh>(makeUvSphere(radius_mm * 1e-3, 96, 192));
  const auto atlas = randomAtlas(1.0);
  const auto pose = poseMm(0.0, 0.0, radius_mm - press_mm);
  const auto centreToRimRatio = [&](const SensorModel& model) {
    TactileRenderer textured(model), plain(model);
    textured.setObject(ball, atlas, 0.1);
    plain.setObject(ball);
    const cv::Mat3b image = textured.render(pose, -1).image.clone();
    const TactileFrame& smooth = plain.render(pose, -1);
    const double contact_px = std::sqrt(cv::countNonZero(smooth.contact_mask) / CV_PI);
    const cv::Point2d centre(model.cols / 2.0 - 0.5, model.rows / 2.0 - 0.5);
    cv::Mat1b inner = cv::Mat1b::zeros(model.imageSize()), rim = inner.clone();
    for (int r = 0; r < model.rows; ++r) {
      for (int c = 0; c < model.cols; ++c) {
        const double d = std::hypot(c - centre.x, r - centre.y) / contact_px;
        if (d < 0.5) inner(r, c) = 255;
        if (d > 0.8 && d < 0.97) rim(r, c) = 255;
      }
    }
    return textureRms(image, smooth.image, inner) / textureRms(image, smooth.image, rim);
  };
  // The shipped gel (E* 0.1 MPa, its coating): the ball's pressure (0.32 MPa mean) is highest at
  // the centre, where the gel follows the most of the relief.
  const double ratio_default = centreToRimRatio(conformingSensor());
  EXPECT_GT(ratio_default, 1.5) << "centre / rim texture RMS with conformity";
  // A stiffer gel (E* 1 MPa), whose p* the ball's pressure spans from centre to rim: the
  // conformity itself adds to the centre's lead. (The fixed-depth overlay is no control here:
  // in the image the rim band also holds the gel model's core edge, at 0.77 of the radius for a
  // ball, which flips with any texture at all, so its ratio says little; the model-level test
  // above shows the effect without it.)
  SensorModel stiff = conformingSensor();
  stiff.conformity.contact_modulus_mpa = 1.0;
  const double ratio_stiff = centreToRimRatio(stiff);
  EXPECT_GT(ratio_stiff, 1.2 * ratio_default) << "E* 1 MPa " << ratio_stiff << ", 0.1 MPa "
                                              << ratio_default;
}

TEST(ConformityRender, OffIsTheFixedDepthOverlayBitForBit) {
  // Conformity off: the renderer is exactly today's stages in a row, whatever force it gets.
  SensorModel model = makeDigitSensorModel();
  ASSERT_TRUE(model.conformity.enabled) << "the default is on";
  model.conformity.enabled = false;
  const auto ball = std::make_shared<const TexturedMesh>(makeUvSphere(5e-3, 96, 192));
  const auto atlas = randomAtlas(2.0);
  const double beta = 0.2;
  TactileRenderer renderer(model);
  renderer.setObject(ball, atlas, beta);
  const ContactRasterizer rasterizer(model);
  const TextureOverlay overlay(atlas, beta);
  const GelModel gel(model);
  const DigitShader shader(model, makeSyntheticBackground(model),
                           BackgroundSource::kSynthetic);
  for (double press_mm : {0.3, 1.0}) {
    const auto pose = poseMm(0.7, -1.1, 5.0 - press_mm);
    ContactRaster raster;
    rasterizer.rasterize(*ball, pose, overlay.reachMm(), true, raster);
    cv::Mat1f h_final, gel_mm;
    overlay.apply(raster, model.gel_thickness_mm, h_final);
    gel.apply(h_final, gel_mm);
    const cv::Mat3b expected = shader.shade(gel_mm, 7);
    for (std::optional<double> force : {std::optional<double>(), std::optional<double>(0.5),
                                        std::optional<double>(30.0)}) {
      const TactileFrame& frame = renderer.render(pose, 7, force);
      EXPECT_FALSE(frame.conformity.has_value());
      EXPECT_EQ(cv::norm(frame.image, expected, cv::NORM_INF), 0.0) << "press " << press_mm;
      EXPECT_EQ(cv::norm(frame.gel_mm, gel_mm, cv::NORM_INF), 0.0) << "press " << press_mm;
    }
  }
}

TEST(ConformityRender, TheCoatingLeavesAnUntexturedPressAsItWas) {
  // The coating only changes how much texture the gel follows: a ball without texture (what
  // the calibration fits) renders bit for bit as without a coating, at any force.
  SensorModel coated = makeDigitSensorModel();
  ASSERT_DOUBLE_EQ(coated.conformity.coating_length_mm, 0.23) << "the shipped coating";
  SensorModel bare = coated;
  bare.conformity.coating_length_mm = 0.0;
  const auto ball = std::make_shared<const TexturedMesh>(makeUvSphere(3e-3, 96, 192));
  TactileRenderer with(coated), without(bare);
  with.setObject(ball);
  without.setObject(ball);
  for (double press_mm : {0.3, 1.2}) {
    const auto pose = poseMm(0.4, -0.9, 3.0 - press_mm);
    const double force = GelLaw::taximDefault().force(press_mm * 1e-3);
    const cv::Mat3b image = with.render(pose, 3, force).image.clone();
    EXPECT_EQ(cv::norm(image, without.render(pose, 3, force).image, cv::NORM_INF), 0.0)
        << "press " << press_mm;
  }
  // ... while the same ball with a texture shows less of it through the coating.
  const auto atlas = randomAtlas(1.0);
  with.setObject(ball, atlas, 0.05);
  without.setObject(ball, atlas, 0.05);
  const auto pose = poseMm(0.0, 0.0, 3.0 - 0.5);
  const double force = GelLaw::taximDefault().force(0.5e-3);
  EXPECT_GT(cv::norm(with.render(pose, 3, force).image, without.render(pose, 3, force).image,
                     cv::NORM_INF),
            0.0);
}

TEST(ConformityRender, OnIsTheStagesInARowWithTheFollowedRelief) {
  // The renderer's one-pass path (GelConformity::applyToFinal) gives what the overlay, then
  // apply()'s followed relief in place of beta H_local, then the gel and the shading give.
  const SensorModel model = makeDigitSensorModel();
  const auto ball = std::make_shared<const TexturedMesh>(makeUvSphere(5e-3, 96, 192));
  const auto atlas = randomAtlas(2.0);
  const double beta = 0.2;
  TactileRenderer renderer(model);
  renderer.setObject(ball, atlas, beta);
  const ContactRasterizer rasterizer(model);
  const TextureOverlay overlay(atlas, beta);
  GelConformity conformity(model.conformity, model.mm_per_pixel);
  const GelModel gel(model);
  const DigitShader shader(model, makeSyntheticBackground(model),
                           BackgroundSource::kSynthetic);
  for (double press_mm : {0.3, 1.0}) {
    const auto pose = poseMm(0.7, -1.1, 5.0 - press_mm);
    for (double force : {0.5, 4.0, 30.0}) {
      ContactRaster raster;
      rasterizer.rasterize(*ball, pose, overlay.reachMm(), true, raster);
      cv::Mat1f h_final, h_local, followed, gel_mm;
      overlay.apply(raster, model.gel_thickness_mm, h_final, &h_local);
      conformity.apply(raster.h_sensor_mm, h_local, beta, raster.covered_box, force, followed);
      const cv::Rect box = raster.covered_box;
      cv::Mat1f rewritten = followed(box) - raster.gap_mm(box);
      rewritten = cv::max(cv::min(rewritten, model.gel_thickness_mm), 0.0);
      rewritten.copyTo(h_final(box));
      gel.apply(h_final, gel_mm);
      const cv::Mat3b expected = shader.shade(gel_mm, 7);
      const TactileFrame& frame = renderer.render(pose, 7, force);
      ASSERT_TRUE(frame.conformity.has_value());
      EXPECT_EQ(cv::norm(frame.gel_mm, gel_mm, cv::NORM_INF), 0.0)
          << "press " << press_mm << " mm, " << force << " N";
      EXPECT_EQ(cv::norm(frame.image, expected, cv::NORM_INF), 0.0)
          << "press " << press_mm << " mm, " << force << " N";
    }
  }
}

TEST(ConformityRender, BadForceIsAClearError) {
  TactileRenderer renderer(conformingSensor());
  renderer.setObject(std::make_shared<const TexturedMesh>(makeUvSphere(5e-3, 48, 96)),
                     randomAtlas(2.0), 0.1);
  const auto pose = poseMm(0, 0, 4.0);
  test::expectError([&] { renderer.render(pose, -1, -2.0); }, {"normal force", "-2", ">= 0 N"});
  test::expectError(
      [&] { renderer.render(pose, -1, std::numeric_limits<double>::quiet_NaN()); },
      {"normal force", "nan"});
  test::expectError(
      [&] { renderer.render(pose, -1, std::numeric_limits<double>::infinity()); },
      {"normal force", "inf"});
  // Conformity off: the same force is refused too (one contract for the argument).
  TactileRenderer off(makeDigitSensorModel());
  off.setObject(std::make_shared<const TexturedMesh>(makeUvSphere(5e-3, 48, 96)));
  test::expectError([&] { off.render(pose, -1, -0.1); }, {"normal force"});
}

TEST(ConformityConfig, TheSensorYamlSwitchIsReadAndChecked) {
  test::ScratchDirectory scratch;
  const std::string path = scratch.path("digit.yaml");
  {
    std::ofstream yaml(path);
    yaml << "conformity:\n  enabled: true\n  contact_modulus_mpa: 0.25\n";
  }
  const SensorModel model = loadSensorModel(path);
  EXPECT_TRUE(model.conformity.enabled);
  EXPECT_DOUBLE_EQ(model.conformity.contact_modulus_mpa, 0.25);
  const std::string copy = scratch.path("copy.yaml");
  saveSensorModel(model, copy);
  EXPECT_TRUE(loadSensorModel(copy).conformity.enabled);
  EXPECT_DOUBLE_EQ(loadSensorModel(copy).conformity.contact_modulus_mpa, 0.25);
  {
    std::ofstream yaml(path);
    yaml << "conformity:\n  contact_modulus_mpa: -1\n";
  }
  test::expectError([&] { loadSensorModel(path); },
                    {"digit.yaml", "conformity.contact_modulus_mpa", "(0, 100] MPa"});
  {
    std::ofstream yaml(path);
    yaml << "conformity:\n  enable: true\n";
  }
  test::expectError([&] { loadSensorModel(path); }, {"digit.yaml", "enable"});
}

}  // namespace
}  // namespace norm2tex
