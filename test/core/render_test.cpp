// Renderer core: geometry against analytic truth, texture anchoring, determinism, bad input.
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/render/gel_model.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

constexpr double kRadiusMm = 5.0;  // the "10 mm sphere"

Eigen::Isometry3d poseMm(double x_mm, double y_mm, double z_mm) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(x_mm, y_mm, z_mm) * 1e-3;
  return pose;
}

/// Sphere centre placed so its lowest point is `press_mm` into the gel at (x, y).
Eigen::Isometry3d pressedSphere(double x_mm, double y_mm, double press_mm) {
  return poseMm(x_mm, y_mm, kRadiusMm - press_mm);
}

std::shared_ptr<const TexturedMesh> sphere() {
  static const auto mesh =
      std::make_shared<const TexturedMesh>(makeUvSphere(kRadiusMm * 1e-3, 96, 192));
  return mesh;
}

/// A smooth random texture that tiles, so phase correlation has one clear peak.
std::shared_ptr<const HeightAtlas> randomAtlas(int size = 256) {
  cv::Mat1f noise(size, size);
  cv::RNG rng(42);
  rng.fill(noise, cv::RNG::UNIFORM, -1.0, 1.0);
  // GaussianBlur has no wrap border: pad periodically, blur, crop, so the texture tiles.
  const int pad = 12;
  cv::Mat1f padded;
  cv::copyMakeBorder(noise, padded, pad, pad, pad, pad, cv::BORDER_WRAP);
  cv::GaussianBlur(padded, padded, cv::Size(0, 0), 2.0, 2.0);
  noise = padded(cv::Rect(pad, pad, size, size)).clone();
  cv::normalize(noise, noise, -1.0, 1.0, cv::NORM_MINMAX);
  return std::make_shared<const HeightAtlas>(noise, cv::Mat1b(size, size, 255));
}

double contactRadiusMm(const TactileFrame& frame, double mm_per_pixel) {
  return std::sqrt(cv::countNonZero(frame.contact_mask) / CV_PI) * mm_per_pixel;
}

cv::Point2d contactCentroid(const TactileFrame& frame) {
  const cv::Moments m = cv::moments(frame.contact_mask, true);
  return {m.m10 / m.m00, m.m01 / m.m00};
}

class RenderTest : public testing::Test {
 protected:
  RenderTest() : model_(makeDigitSensorModel()), renderer_(model_) {}
  SensorModel model_;
  TactileRenderer renderer_;
};

TEST_F(RenderTest, SpherePressGivesTheHertzianContactDisc) {
  renderer_.setObject(sphere());
  for (const double press : {0.25, 0.5, 1.0, 1.5}) {
    const TactileFrame& frame = renderer_.render(pressedSphere(0, 0, press), -1);
    const double expected = std::sqrt(2 * kRadiusMm * press - press * press);
    EXPECT_NEAR(contactRadiusMm(frame, model_.mm_per_pixel), expected, 1.5 * model_.mm_per_pixel)
        << "press " << press << " mm";
    double max_h = 0;
    cv::minMaxLoc(frame.raster.h_sensor_mm, nullptr, &max_h);
    EXPECT_NEAR(max_h, press, 0.01) << "deepest indentation = press";
  }
}

TEST_F(RenderTest, ContactIsCentredWhereTheSphereTouches) {
  renderer_.setObject(sphere());
  const TactileFrame& frame = renderer_.render(pressedSphere(3.0, -4.0, 0.8), -1);
  const cv::Point2d centroid = contactCentroid(frame);
  // x = 3 mm right of centre, y = 4 mm up: column 120 + 37.5, row 160 - 50 (pixel centres).
  EXPECT_NEAR(centroid.x, 0.5 * model_.cols - 0.5 + 3.0 / model_.mm_per_pixel, 1.0);
  EXPECT_NEAR(centroid.y, 0.5 * model_.rows - 0.5 - 4.0 / model_.mm_per_pixel, 1.0);
}

TEST_F(RenderTest, TopLeftOfTheGelShowsTopLeftInTheImage) {
  renderer_.setObject(sphere());
  const double x = -0.5 * model_.gelWidthMm() + 2.0, y = -0.5 * model_.gelHeightMm() + 2.0;
  const TactileFrame& frame = renderer_.render(pressedSphere(x, y, 1.0), -1);
  const cv::Point2d centroid = contactCentroid(frame);
  EXPECT_LT(centroid.x, model_.cols / 4.0);
  EXPECT_LT(centroid.y, model_.rows / 4.0);
  // And the image changed there, not elsewhere.
  cv::Mat diff;
  cv::absdiff(frame.image, renderer_.shader().background(), diff);
  cv::Mat1b changed;
  cv::cvtColor(diff, changed, cv::COLOR_BGR2GRAY);
  const cv::Moments m = cv::moments(changed > 5, true);
  ASSERT_GT(m.m00, 0);
  EXPECT_LT(m.m10 / m.m00, model_.cols / 3.0);
  EXPECT_LT(m.m01 / m.m00, model_.rows / 3.0);
}

TEST_F(RenderTest, HarderPressNeverShrinksTheContact) {
  renderer_.setObject(sphere());
  int previous = 0;
  for (double press = 0.0; press <= 2.0; press += 0.1) {
    const int area =
        cv::countNonZero(renderer_.render(pressedSphere(0.7, 0.3, press), -1).contact_mask);
    EXPECT_GE(area, previous) << "press " << press;
    previous = area;
  }
  EXPECT_GT(previous, 1000);
}

TEST_F(RenderTest, NoContactIsTheBackgroundExactly) {
  renderer_.setObject(sphere(), randomAtlas(), 0.3);
  const TactileFrame& frame = renderer_.render(poseMm(0, 0, kRadiusMm + 1.0), -1);  // 1 mm above
  EXPECT_EQ(cv::countNonZero(frame.contact_mask), 0);
  cv::Mat diff;
  cv::absdiff(frame.image, renderer_.shader().background(), diff);
  EXPECT_EQ(cv::countNonZero(diff.reshape(1)), 0);
}

TEST_F(RenderTest, BetaZeroIsTheTexturelessRenderBitForBit) {
  renderer_.setObject(sphere());
  const cv::Mat3b plain = renderer_.render(pressedSphere(1, 2, 1.0), -1).image.clone();
  renderer_.setObject(sphere(), randomAtlas(), 0.0);
  const cv::Mat3b beta_zero = renderer_.render(pressedSphere(1, 2, 1.0), -1).image.clone();
  EXPECT_EQ(cv::norm(plain, beta_zero, cv::NORM_INF), 0.0);
  // An atlas of zeros runs the whole overlay path and must still change nothing.
  auto flat = std::make_shared<const HeightAtlas>(cv::Mat1f(64, 64, 0.0f), cv::Mat1b(64, 64, 255));
  renderer_.setObject(sphere(), flat, 0.5);
  const TactileFrame& frame = renderer_.render(pressedSphere(1, 2, 1.0), -1);
  EXPECT_TRUE(frame.textured);
  EXPECT_EQ(cv::norm(plain, frame.image, cv::NORM_INF), 0.0);
}

TEST_F(RenderTest, TextureChangesTheImageOnlyAroundTheContact) {
  renderer_.setObject(sphere());
  const TactileFrame& plain_frame = renderer_.render(pressedSphere(0, 0, 1.0), -1);
  const cv::Mat3b plain = plain_frame.image.clone();
  const cv::Mat1b plain_contact = plain_frame.contact_mask.clone();
  // 0.3 mm: the calibrated shading answers slopes as a real DIGIT does (tens of grey levels
  // per unit slope), far less than the old analytic LED model, so shallow texture shows less.
  renderer_.setObject(sphere(), randomAtlas(), 0.3);
  const cv::Mat3b textured = renderer_.render(pressedSphere(0, 0, 1.0), -1).image.clone();
  cv::Mat diff;
  cv::absdiff(plain, textured, diff);
  cv::Mat1b changed;
  cv::cvtColor(diff, changed, cv::COLOR_BGR2GRAY);
  changed = changed > 2;  // visible change; the far skirt's rounding may flip one level
  EXPECT_GT(cv::countNonZero(changed & plain_contact), cv::countNonZero(plain_contact) / 4)
      << "texture visible in the contact";
  // Outside the contact grown by the gel's skirt (3 sigma of the whole pyramid) and the
  // shading's reach (its rim-shadow blur) nothing moves.
  double variance_mm2 = 0.0;
  for (const double sigma : model_.gel.pyramid_sigmas_mm) variance_mm2 += sigma * sigma;
  cv::Mat1b near;
  const int grow =
      static_cast<int>(std::ceil(3.0 * std::sqrt(variance_mm2) / model_.mm_per_pixel)) +
      renderer_.shader().reachPixels();
  cv::dilate(plain_contact, near,
             cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * grow + 1, 2 * grow + 1}));
  EXPECT_EQ(cv::countNonZero(changed & ~near), 0);
}

TEST_F(RenderTest, TextureMovesWithTheObject) {
  // A large box pressed flat covers the whole gel; sliding it along x or y must shift the
  // texture by d / mm_per_pixel pixels and change nothing else.
  auto box = std::make_shared<const TexturedMesh>(makeBox({0.06, 0.06, 0.01}, 0.02));
  renderer_.setObject(box, randomAtlas(), 0.05);
  const auto boxPose = [](double x_mm, double y_mm) { return poseMm(x_mm, y_mm, 5.0 - 0.3); };
  const cv::Rect centre(40, 60, 160, 200);
  cv::Mat1f window;
  cv::createHanningWindow(window, centre.size(), CV_32F);
  const cv::Mat1f rest = renderer_.render(boxPose(0, 0), -1).h_local(centre).clone();
  const auto measuredShift = [&](double x_mm, double y_mm) {
    const cv::Mat1f moved = renderer_.render(boxPose(x_mm, y_mm), -1).h_local(centre).clone();
    // phaseCorrelate applies the window in place when no padding is needed: give it copies.
    return cv::phaseCorrelate(rest.clone(), moved, window);
  };
  // Shifts of exactly 10 pixels and of 12.25 pixels (phase correlation's sub-pixel estimate is
  // biased towards whole pixels, most at half a pixel), in mm at the sensor's scale.
  const double ten_mm = 10.0 * model_.mm_per_pixel, half_mm = 12.25 * model_.mm_per_pixel;
  const cv::Point2d ten = measuredShift(ten_mm, 0.0);
  EXPECT_NEAR(ten.x, 10.0, 0.15);
  EXPECT_NEAR(ten.y, 0.0, 0.15);
  const cv::Point2d half = measuredShift(half_mm, 0.0);
  EXPECT_NEAR(half.x, 12.25, 0.5);
  const cv::Point2d up = measuredShift(0.0, -ten_mm);
  EXPECT_NEAR(up.x, 0.0, 0.15);
  EXPECT_NEAR(up.y, -10.0, 0.15);

  // Nothing else: shifting the moved H_local back by 10 columns reproduces the original.
  const cv::Mat1f moved = renderer_.render(boxPose(ten_mm, 0.0), -1).h_local.clone();
  const cv::Mat1f back = moved(centre + cv::Point(10, 0));
  cv::Mat1f residual;
  cv::absdiff(back, rest, residual);
  double worst = 0;
  cv::Point where;
  cv::minMaxLoc(residual, nullptr, &worst, nullptr, &where);
  EXPECT_LT(worst, 1e-3) << "at " << where << " of the centre window";
}

TEST_F(RenderTest, SamePoseSameImage) {
  renderer_.setObject(sphere(), randomAtlas(), 0.2);
  const cv::Mat3b a = renderer_.render(pressedSphere(-1, 1, 0.7), 7).image.clone();
  const cv::Mat3b b = renderer_.render(pressedSphere(-1, 1, 0.7), 7).image.clone();
  const cv::Mat3b c = renderer_.render(pressedSphere(-1, 1, 0.7), -1).image.clone();
  const cv::Mat3b d = renderer_.render(pressedSphere(-1, 1, 0.7), -1).image.clone();
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(c, d, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a, c, cv::NORM_INF), 0.0) << "noise on vs off differ";
}

// A frame's render owes nothing to the renders before it: tactile_renderer's ~rehearse_ms
// renders the last frame again between frames and relies on it. Textured, with the gel's
// conformity (the default sensor) and noise; the frame rendered after a wider press (whose
// overlay box and conformity buffers are larger) equals the frame rendered first.
TEST_F(RenderTest, ARenderDoesNotDependOnThePreviousOnes) {
  ASSERT_TRUE(model_.conformity.enabled) << "the default sensor conforms to the texture";
  renderer_.setObject(sphere(), randomAtlas(), 0.2);
  TactileRenderer fresh(model_);
  fresh.setObject(sphere(), randomAtlas(), 0.2);
  const Eigen::Isometry3d pose = pressedSphere(-1, 1, 0.7);
  renderer_.render(pressedSphere(2, -1, 1.5), 5, 4.0);
  renderer_.render(pressedSphere(2, -1, 1.5), 5, 4.0);  // a rehearsal of the same frame
  const TactileFrame& after = renderer_.render(pose, 7, 2.0);
  const TactileFrame& first = fresh.render(pose, 7, 2.0);
  EXPECT_EQ(cv::norm(after.image, first.image, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(after.gel_mm, first.gel_mm, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(after.contact_mask, first.contact_mask, cv::NORM_INF), 0.0);
}

TEST_F(RenderTest, DepthIsTheGelDeformationInMetres) {
  renderer_.setObject(sphere());
  const TactileFrame& frame = renderer_.render(pressedSphere(0, 0, 1.2), -1);
  double max_depth = 0;
  cv::minMaxLoc(frame.depthMetres(), nullptr, &max_depth);
  EXPECT_NEAR(max_depth, 1.2e-3, 0.05e-3);
  EXPECT_EQ(frame.depthMetres().type(), CV_32FC1);
}

TEST_F(RenderTest, IndentationIsClampedToTheGelThickness) {
  renderer_.setObject(sphere());
  const TactileFrame& frame = renderer_.render(pressedSphere(0, 0, 8.0), -1);
  double max_h = 0;
  cv::minMaxLoc(frame.raster.h_sensor_mm, nullptr, &max_h);
  EXPECT_FLOAT_EQ(max_h, model_.gel_thickness_mm);
}

TEST_F(RenderTest, MeshWithoutUvsRendersWithAWarning) {
  TexturedMesh with_uvs = makeUvSphere(kRadiusMm * 1e-3, 32, 64);
  auto no_uvs = std::make_shared<const TexturedMesh>(with_uvs.vertices(), with_uvs.triangles());
  const std::string warning = renderer_.setObject(no_uvs, randomAtlas(), 0.2);
  EXPECT_NE(warning.find("UV"), std::string::npos) << warning;
  const TactileFrame& frame = renderer_.render(pressedSphere(0, 0, 1.0), -1);
  EXPECT_FALSE(frame.textured);
  EXPECT_GT(cv::countNonZero(frame.contact_mask), 100);
}

TEST_F(RenderTest, LargeMeshesAreCulledToTheContact) {
  // ~200k triangles; only the cap near the gel may reach the rasterizer.
  auto dense = std::make_shared<const TexturedMesh>(makeUvSphere(kRadiusMm * 1e-3, 317, 317));
  ASSERT_GE(dense->triangles().size(), 200000u);
  renderer_.setObject(dense);
  const TactileFrame& frame = renderer_.render(pressedSphere(0, 0, 1.0), -1);
  // The pressed cap is h / 2R = 1/10 of the sphere's area; triangles straddling its rim add a
  // little (more at finer pixels, where fewer small triangles fall between pixel centres).
  EXPECT_LT(frame.raster.triangles_rasterized, static_cast<int>(dense->triangles().size() / 8));
  EXPECT_NEAR(contactRadiusMm(frame, model_.mm_per_pixel), std::sqrt(2 * kRadiusMm - 1.0),
              1.5 * model_.mm_per_pixel);
}

// --- GelModel against the same pyramid run entirely at full resolution -----------------------

/// The GelModel's pyramid without its shortcuts: every level at full resolution over the whole
/// image. Truth for the reduced-resolution levels.
cv::Mat1f fullResolutionGel(const SensorModel& model, const cv::Mat1f& indentation) {
  double max_indentation = 0.0;
  cv::minMaxLoc(indentation, nullptr, &max_indentation);
  const cv::Mat1b core = indentation > model.gel.core_fraction * max_indentation;
  cv::Mat1f gel = indentation.clone();
  const auto blur = [&](double sigma_mm) {
    const double sigma = sigma_mm / model.mm_per_pixel;
    const int radius = static_cast<int>(std::ceil(3.0 * sigma));
    cv::GaussianBlur(gel.clone(), gel, cv::Size(2 * radius + 1, 2 * radius + 1), sigma, sigma,
                     cv::BORDER_REPLICATE);
  };
  for (const double sigma_mm : model.gel.pyramid_sigmas_mm) {
    blur(sigma_mm);
    indentation.copyTo(gel, core);
  }
  blur(model.gel.final_sigma_mm);
  cv::min(gel, model.gel_thickness_mm, gel);
  return gel;
}

/// A ball of `radius_mm` pressed `depth_mm` at (x, y) mm from the gel centre.
cv::Mat1f ballIndentation(const SensorModel& model, double radius_mm, double depth_mm, double x,
                          double y) {
  cv::Mat1f h(model.imageSize(), 0.0f);
  for (int r = 0; r < h.rows; ++r) {
    for (int c = 0; c < h.cols; ++c) {
      const cv::Point2d p = model.pixelToGelMm(r, c);
      const double d2 = (p.x - x) * (p.x - x) + (p.y - y) * (p.y - y);
      if (d2 < radius_mm * radius_mm) {
        h(r, c) = static_cast<float>(
            std::max(0.0, depth_mm - (radius_mm - std::sqrt(radius_mm * radius_mm - d2))));
      }
    }
  }
  return h;
}

TEST(GelModel, ReducedResolutionLevelsMatchTheFullResolutionPyramid) {
  const SensorModel model = makeDigitSensorModel();
  const GelModel gel_model(model);
  cv::Mat1f edge(model.imageSize(), 0.0f);  // the held cube's edge: a flat face ending in a step
  edge.rowRange(0, 2 * model.rows / 3).setTo(1.0f);
  const std::vector<std::pair<const char*, cv::Mat1f>> presses = {
      {"8.8 mm ball 1.5 mm deep", ballIndentation(model, 4.4, 1.5, 0.5, -1.0)},
      {"6 mm ball 0.4 mm deep near the corner", ballIndentation(model, 3.0, 0.4, -5.0, 7.0)},
      {"flat face with an edge, 1 mm deep", edge}};
  for (const auto& [what, indentation] : presses) {
    cv::Mat1f gel;
    gel_model.apply(indentation, gel);
    const cv::Mat1f truth = fullResolutionGel(model, indentation);
    double max_indentation = 0.0;
    cv::minMaxLoc(indentation, nullptr, &max_indentation);
    // Measured: 0.4 % (ball), 4.1 % (small ball near the corner), 1.1 % (edge); the version
    // with only the 0.5 mm level at quarter resolution: 0.3 %, 3.7 %, 0.6 %.
    const double worst = cv::norm(gel, truth, cv::NORM_INF);
    EXPECT_LT(worst, 0.05 * max_indentation) << what << ": " << worst << " mm";
    // Inside the core, beyond the reach of the final bending blur (which rounds a curved surface
    // by a few um), the gel is the input.
    cv::Mat1b core = indentation > model.gel.core_fraction * max_indentation;
    const int reach =
        static_cast<int>(std::ceil(3.0 * model.gel.final_sigma_mm / model.mm_per_pixel)) + 1;
    cv::erode(core, core, cv::Mat(), cv::Point(-1, -1), reach);
    double core_error = 0.0;
    cv::minMaxLoc(cv::abs(gel - indentation), nullptr, &core_error, nullptr, nullptr, core);
    EXPECT_LT(core_error, 0.01 * max_indentation) << what;
    double lowest = 0.0, highest = 0.0;
    cv::minMaxLoc(gel, &lowest, &highest);
    EXPECT_GE(lowest, 0.0) << what;
    EXPECT_LE(highest, max_indentation + 1e-6) << what;
  }
}

TEST(GelModel, BlurringOnlyOutsideTheCoreMatchesTheWholePyramidExactly) {
  // Sigmas of 3 pixels or less run every level at full resolution, so the only shortcuts left
  // are the ones this checks: each blur covers the deformation's box and writes only pixels
  // outside the contact core (the core is restored after it). Against the plain pyramid over
  // the whole image the result is the same (measured: 0 where the gel moved; a read region one
  // pixel too small gives 2e-6 to 2e-5 mm).
  SensorModel model = makeDigitSensorModel();
  model.gel.pyramid_sigmas_mm = {0.15, 0.1, 0.05};
  const GelModel gel_model(model);
  cv::Mat1f edge(model.imageSize(), 0.0f);  // the held cube: a flat face over 2/3 of the gel
  edge.rowRange(0, 2 * model.rows / 3).setTo(1.0f);
  cv::Mat1f textured_edge = edge.clone();  // the same with relief: a ragged core
  cv::Mat1f relief(model.imageSize());
  cv::randu(relief, -0.7f, 0.3f);
  cv::GaussianBlur(relief, relief, cv::Size(0, 0), 1.5);
  textured_edge += relief.mul(edge);
  cv::Mat1f tilted(model.imageSize());  // a face over the whole gel, tilted: core on one side
  for (int r = 0; r < tilted.rows; ++r) tilted.row(r).setTo(0.2f + 0.8f * r / tilted.rows);
  const std::vector<std::pair<const char*, cv::Mat1f>> presses = {
      {"8.8 mm ball 1.5 mm deep", ballIndentation(model, 4.4, 1.5, 0.5, -1.0)},
      {"flat face with an edge", edge},
      {"textured face with an edge", cv::max(textured_edge, 0.0f)},
      {"tilted face over the whole gel", tilted}};
  for (const auto& [what, indentation] : presses) {
    cv::Mat1f gel;
    gel_model.apply(indentation, gel);
    const cv::Mat1f truth = fullResolutionGel(model, indentation);
    // Compared where the gel moved by 10 um or more, away from the cut-offs' 0.1 um effects.
    const double worst = cv::norm(gel, truth, cv::NORM_INF, truth > 0.01f);
    EXPECT_LE(worst, 1e-6) << what << ": " << worst << " mm";
  }
}

TEST(GelModel, HarderPressWidensTheSkirt) {
  const SensorModel model = makeDigitSensorModel();
  const GelModel gel_model(model);
  int previous = 0;
  for (const double depth : {0.2, 0.6, 1.2}) {
    cv::Mat1f gel;
    gel_model.apply(ballIndentation(model, 4.4, depth, 0.0, 0.0), gel);
    const int deformed = cv::countNonZero(gel > 0.01f);
    EXPECT_GT(deformed, previous) << depth << " mm";
    previous = deformed;
  }
}

TEST(RenderErrors, BadInputIsAClearError) {
  TactileRenderer renderer(makeDigitSensorModel());
  EXPECT_THROW(renderer.render(Eigen::Isometry3d::Identity(), -1), Error) << "no object";
  renderer.setObject(sphere());
  Eigen::Isometry3d nan_pose = Eigen::Isometry3d::Identity();
  nan_pose.translation().x() = std::nan("");
  EXPECT_THROW(renderer.render(nan_pose, -1), Error);
  EXPECT_THROW(renderer.setObject(sphere(), randomAtlas(), -0.1), Error);
  EXPECT_THROW(renderer.setObject(nullptr), Error);
  SensorModel empty = makeDigitSensorModel();
  empty.rows = 0;
  EXPECT_THROW(TactileRenderer{empty}, Error);
  SensorModel missing_background = makeDigitSensorModel();
  missing_background.background_image = "/nonexistent/bg.png";
  EXPECT_THROW(TactileRenderer{missing_background}, Error);
  EXPECT_THROW(TexturedMesh({}, {}), Error) << "no triangles";
}

}  // namespace
}  // namespace norm2tex
