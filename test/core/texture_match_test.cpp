// Fitting a material's texture depth to frames of a DIGIT pressing a flat sample: round trips
// through frames rendered with a known beta and known forces (with noise, conformity on and
// off, forces given and area-matched), the texture band's measurement, and bad input.
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "norm2tex/calibrate/texture_band.hpp"
#include "norm2tex/calibrate/texture_match.hpp"
#include "norm2tex/calibrate/texture_match_report.hpp"
#include "norm2tex/calibrate/texture_sample.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/image_io.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "norm2tex/gel/gel_law.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

const std::vector<double> kForcesN = {2.0, 5.0, 12.0};  // light, medium, firm

// The shipped DIGIT (its captured background), its noise added on that background too: the
// "real" frames carry sensor noise the fit has to see through.
SensorModel sensor(bool conformity) {
  SensorModel model = loadSensorModel(std::string(NORM2TEX_SOURCE_DIR) + "/config/digit.yaml");
  model.conformity.enabled = conformity;
  model.conformity.contact_modulus_mpa = 0.1;
  model.noise.on_real_background = true;
  return model;
}

const cv::Mat3b& background() {
  static const cv::Mat3b image = [] {
    const SensorModel model = sensor(false);
    cv::Mat3b read = readImage(model.background_image, cv::IMREAD_COLOR, "background");
    cv::Mat3b resized;
    cv::resize(read, resized, model.imageSize(), 0, 0, cv::INTER_AREA);
    return resized;
  }();
  return image;
}

// Fabric at half its shipped texture size (a 25.6 mm period, wider than the imaged gel): the
// bake takes a quarter of the time and the face shows the same relief.
const TextureSample& fabric() {
  static const TextureSample sample = [] {
    MaterialConfig config = loadMaterialConfig(std::string(NORM2TEX_SOURCE_DIR) +
                                               "/config/materials/fabric.yaml");
    config.size = 512;
    return makeMaterialSample(config, 0);
  }();
  return sample;
}

// A coarse weave (threads 2 mm apart, 0.1 mm high): relief long enough for the shipped gel's
// coating to let through, so its depth shows at every force. The shipped weave's 0.5 mm threads
// are held back by the coating to a texture below the sensor's noise on a flat face.
const TextureSample& coarseFabric() {
  static const TextureSample sample = [] {
    MaterialConfig config = loadMaterialConfig(std::string(NORM2TEX_SOURCE_DIR) +
                                               "/config/materials/fabric.yaml");
    config.size = 512;
    config.mm_per_texel = 0.1;
    config.parameters["thread_spacing_mm"] = 2.0;
    config.parameters["thread_height_mm"] = 0.1;
    config.beta_mm = 0.1;
    return makeMaterialSample(config, 0);
  }();
  return sample;
}

// Frames of the sample pressed with each force at the matcher's default tilt, as deep as the gel
// law says, rendered with `beta_mm` and noise seeds the fit does not use.
std::vector<TextureFrame> truthFrames(const SensorModel& model, double beta_mm,
                                      const std::vector<double>& forces, bool give_forces,
                                      const TextureSample& sample = fabric()) {
  TactileRenderer renderer(model, background(), BackgroundSource::kCaptured);
  renderer.setObject(TextureMatcher::sampleFace(sample.period_mm), sample.atlas, beta_mm);
  const double tilt = TextureMatchOptions().tilt_deg;
  std::vector<TextureFrame> frames;
  for (size_t i = 0; i < forces.size(); ++i) {
    const double press_mm = GelLaw::taximDefault().indentation(forces[i]) * 1e3;
    const TactileFrame& frame =
        renderer.render(TextureMatcher::samplePose(model, tilt, press_mm), 17 + i, forces[i]);
    TextureFrame out;
    out.name = "press_" + std::to_string(i) + ".png";
    out.image = frame.image.clone();
    if (give_forces) out.normal_force_n = forces[i];
    frames.push_back(out);
  }
  return frames;
}

struct RoundTrip {
  bool conformity;
  double beta_factor;
  bool give_forces;
  /// The shipped gel (its coating) with the coarse weave, or a gel without a coating
  /// (Johnson's half-space) with the shipped fabric.
  bool bare_gel = false;
};

class TextureMatchRoundTrip : public testing::TestWithParam<RoundTrip> {};

TEST_P(TextureMatchRoundTrip, RecoversBetaWithinTenPercent) {
  const RoundTrip c = GetParam();
  SensorModel model = sensor(c.conformity);
  if (c.bare_gel) model.conformity.coating_length_mm = 0.0;
  const TextureSample& sample = c.conformity && !c.bare_gel ? coarseFabric() : fabric();
  const double truth = c.beta_factor * sample.beta_mm;
  const std::vector<TextureFrame> frames =
      truthFrames(model, truth, kForcesN, c.give_forces, sample);
  const TextureMatchResult result = TextureMatcher(model, background(), sample).fit(frames);
  std::printf("conformity %s (coating %.2f mm), forces %s: true beta %.4f, fitted %.4f (%+.1f %%), "
              "misfit %.3f\n",
              c.conformity ? "on" : "off", model.conformity.coating_length_mm,
              c.give_forces ? "given" : "area-matched", truth, result.beta_mm,
              100.0 * (result.beta_mm / truth - 1.0), result.misfit);
  for (const FrameMatch& f : result.frames) {
    std::printf("  %s: %.2f N press %.3f mm real %.2f sim %.2f (contact %d / %d px)\n",
                f.name.c_str(), f.force_n, f.press_mm, f.real.rms, f.sim.rms,
                f.real.contact_pixels, f.sim.contact_pixels);
  }
  EXPECT_NEAR(result.beta_mm / truth, 1.0, 0.10);
  EXPECT_FALSE(result.beta_at_bound);
  EXPECT_EQ(result.frames.size(), kForcesN.size());
  // The fit started at the material's own beta, 0.6x or 1.5x off: it must have improved.
  EXPECT_LT(result.misfit, result.start_misfit);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, TextureMatchRoundTrip,
    testing::Values(RoundTrip{true, 0.6, true}, RoundTrip{true, 1.5, true},
                    RoundTrip{true, 0.6, false}, RoundTrip{true, 1.5, false},
                    RoundTrip{true, 0.6, true, true}, RoundTrip{true, 1.5, false, true},
                    RoundTrip{false, 0.6, true}, RoundTrip{false, 1.5, false}),
    [](const testing::TestParamInfo<RoundTrip>& info) {
      return std::string(info.param.conformity ? "ConformityOn" : "ConformityOff") +
             (info.param.bare_gel ? "BareGel" : "") +
             (info.param.beta_factor < 1.0 ? "Shallow" : "Deep") +
             (info.param.give_forces ? "ForcesGiven" : "AreaMatched");
    });

TEST(TextureMatch, ReportsWhyTheModulusIsKeptAndDrawsItsReport) {
  const SensorModel model = sensor(true);
  const std::vector<TextureFrame> frames = truthFrames(model, coarseFabric().beta_mm, {2.0, 5.0},
                                                       /*give_forces=*/false, coarseFabric());
  const TextureMatchResult result =
      TextureMatcher(model, background(), coarseFabric()).fit(frames);
  EXPECT_FALSE(result.contact_modulus_fitted);
  EXPECT_DOUBLE_EQ(result.contact_modulus_mpa, 0.1);
  EXPECT_NE(result.contact_modulus_note.find("without the frames' forces"), std::string::npos)
      << result.contact_modulus_note;
  const cv::Mat3b report = makeTextureMatchReport(result, background());
  // Text, two rows of crops and the plots; the crops are not blank.
  EXPECT_GE(report.rows, 2 * 160 + 220);
  cv::Scalar mean, deviation;
  cv::meanStdDev(report(cv::Rect(0, report.rows - 220 - 160, 160, 160)), mean, deviation);
  EXPECT_GT(deviation[0] + deviation[1] + deviation[2], 3.0);
  const std::vector<std::string> lines = describeTextureMatch(result);
  EXPECT_NE(lines.front().find("beta"), std::string::npos);
  EXPECT_EQ(lines.size(), 2u + frames.size() + result.warnings.size());
}

TEST(TextureMatch, NeverEndsWorseThanItStartedWhenTheFramesCannotPinBeta) {
  // The shipped weave's 0.5 mm threads through the shipped gel: its coating holds them back to
  // a texture band under the sensor's noise, at every depth. The fit must not end worse than
  // where it started (it keeps the material's beta, and says why, if nothing is better).
  const SensorModel model = sensor(true);
  const std::vector<TextureFrame> frames =
      truthFrames(model, 1.5 * fabric().beta_mm, kForcesN, /*give_forces=*/true);
  const TextureMatchResult result = TextureMatcher(model, background(), fabric()).fit(frames);
  for (const FrameMatch& f : result.frames) EXPECT_LT(f.real.rms, f.real.noise_rms) << f.name;
  // The deeper relief shows less here (the gel touches fewer, narrower crests), so a search
  // that assumed the opposite ran to the range's end (33x, misfit 0.91 against 0.24 at the start).
  EXPECT_LE(result.misfit, result.start_misfit * 1.001);
  EXPECT_FALSE(result.beta_at_bound);
  if (result.beta_kept) EXPECT_EQ(result.beta_mm, fabric().beta_mm);
}

TEST(TextureMatch, TheModulusNeedsPressuresThatSpanEnough) {
  const SensorModel model = sensor(true);
  // Three presses of nearly one force: p* cannot show.
  const std::vector<TextureFrame> frames = truthFrames(
      model, coarseFabric().beta_mm, {4.0, 4.5, 5.0}, /*give_forces=*/true, coarseFabric());
  const TextureMatchResult result =
      TextureMatcher(model, background(), coarseFabric()).fit(frames);
  EXPECT_FALSE(result.contact_modulus_fitted);
  EXPECT_NE(result.contact_modulus_note.find("not identifiable"), std::string::npos)
      << result.contact_modulus_note;
}

TEST(TextureBandMeasure, FindsTheTexturedContactAndItsNoiseFloor) {
  const SensorModel model = sensor(false);
  const std::vector<TextureFrame> frames = truthFrames(model, 0.09, {5.0}, false);
  cv::Mat3f a, b;
  frames[0].image.convertTo(a, CV_32F);
  background().convertTo(b, CV_32F);
  const TextureBand band = measureTextureBand(a - b, NoContactLevel(), "press");
  // The tilted face touches from the bottom edge: the contact is the image's lower part.
  EXPECT_GT(band.contact_centre.y, 0.5 * model.rows);
  EXPECT_NEAR(band.contact_fraction, 0.45, 0.15);
  EXPECT_TRUE(band.noise_from_frame);
  EXPECT_GT(band.noise_rms, 1.0);
  EXPECT_GT(band.rms, band.noise_rms);  // fabric at 0.09 mm stands out of the noise
  ASSERT_EQ(band.spectrum.size(), 12u);
  // The weave's 0.5 mm threads (about 9 px): more power in the band's middle than at its ends.
  EXPECT_GT(band.spectrum[2], band.spectrum[11]);
}

class TextureMatchErrors : public testing::Test {
 protected:
  std::vector<TextureFrame> frames(bool forces) const {
    return truthFrames(sensor(false), fabric().beta_mm, {2.0, 5.0}, forces);
  }
  TextureMatchResult fit(const std::vector<TextureFrame>& frames) const {
    return TextureMatcher(sensor(false), background(), fabric()).fit(frames);
  }
};

TEST_F(TextureMatchErrors, FrameOfAnotherSizeIsNamed) {
  std::vector<TextureFrame> f = frames(false);
  cv::resize(f[1].image, f[1].image, cv::Size(480, 640));
  test::expectError([&] { fit(f); }, {"press_1.png", "480 x 640", "240 x 320"});
}

TEST_F(TextureMatchErrors, FrameWithoutContactIsNamed) {
  std::vector<TextureFrame> f = frames(false);
  f[0].image = background().clone();
  test::expectError([&] { fit(f); }, {"press_0.png", "no contact"});
}

TEST_F(TextureMatchErrors, TooFewFramesSaysHowManyAreNeeded) {
  std::vector<TextureFrame> f = frames(false);
  f.resize(1);
  test::expectError([&] { fit(f); }, {"at least 2 frames", "got 1"});
}

TEST_F(TextureMatchErrors, ForcesForSomeFramesOnly) {
  std::vector<TextureFrame> f = frames(true);
  f[1].normal_force_n.reset();
  test::expectError([&] { fit(f); }, {"1 of 2 frames", "every frame or none"});
}

TEST_F(TextureMatchErrors, NegativeOrNonFiniteForceIsNamed) {
  std::vector<TextureFrame> f = frames(true);
  f[1].normal_force_n = -3.0;
  test::expectError([&] { fit(f); }, {"press_1.png", "-3", "> 0 N"});
  f[1].normal_force_n = std::numeric_limits<double>::quiet_NaN();
  test::expectError([&] { fit(f); }, {"press_1.png", "finite"});
}

TEST_F(TextureMatchErrors, ContactOverTheWholeImageNeedsForces) {
  // A face pressed parallel to the gel: no area to match the press by.
  const SensorModel model = sensor(false);
  TactileRenderer renderer(model, background(), BackgroundSource::kCaptured);
  renderer.setObject(TextureMatcher::sampleFace(fabric().period_mm), fabric().atlas, 0.06);
  std::vector<TextureFrame> f = frames(false);
  f[1].image = renderer.render(TextureMatcher::samplePose(model, 0.0, 0.5), 3).image.clone();
  test::expectError([&] { fit(f); }, {"press_1.png", "covers", "forces"});
}

TEST_F(TextureMatchErrors, SensorAndBackgroundOfDifferentSizes) {
  cv::Mat3b small;
  cv::resize(background(), small, cv::Size(120, 160));
  test::expectError([&] { TextureMatcher(sensor(false), small, fabric()); },
                    {"background is 120 x 160", "240 x 320"});
}

}  // namespace
}  // namespace norm2tex
