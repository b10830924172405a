// The GelSight Mini profile (config/gelsight_mini.yaml): it loads as the product is documented, its
// synthetic no-contact frame looks like a Mini's, and a ball press renders landscape with the
// contact where the ball is, coloured by the LEDs where the yaml puts them, among the markers.
#include <cmath>
#include <memory>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/render/synthetic_background.hpp"
#include "norm2tex/render/tactile_renderer.hpp"

namespace norm2tex {
namespace {

const char* const kMiniYaml = NORM2TEX_SOURCE_DIR "/config/gelsight_mini.yaml";

SensorModel miniModel() { return loadSensorModel(kMiniYaml); }

// Direction of an LED in the image plane, degrees: 0 right, 90 down (the gel frame's +y).
double imageAngleDeg(const LedModel& led) {
  return std::atan2(led.position_mm[1], led.position_mm[0]) * 180.0 / CV_PI;
}

double brightness(const cv::Vec3b& pixel) { return pixel[0] + pixel[1] + pixel[2]; }

// Mean BGR of a region given in thirds of the image (column third, row third).
cv::Vec3d thirdMean(const cv::Mat3b& image, int column, int row) {
  const int w = image.cols / 3, h = image.rows / 3;
  const cv::Scalar m = cv::mean(image(cv::Rect(column * w, row * h, w, h)));
  return {m[0], m[1], m[2]};
}

TEST(GelSightMiniProfile, LoadsAsTheProductIsDocumented) {
  const SensorModel m = miniModel();
  EXPECT_EQ(m.rows, 240);  // landscape, as the SDK publishes
  EXPECT_EQ(m.cols, 320);
  EXPECT_DOUBLE_EQ(m.mm_per_pixel, 0.0634);
  EXPECT_NEAR(m.gelWidthMm(), 20.3, 0.05);
  EXPECT_NEAR(m.gelHeightMm(), 15.2, 0.05);
  EXPECT_GT(m.gel_pad_width_mm, m.gelWidthMm());  // the camera sees the middle of the pad
  EXPECT_GT(m.gel_pad_height_mm, m.gelHeightMm());
  EXPECT_DOUBLE_EQ(m.gel_thickness_mm, 4.0);
  EXPECT_DOUBLE_EQ(m.cx, 0.5 * m.cols - 0.5);
  EXPECT_DOUBLE_EQ(m.cy, 0.5 * m.rows - 0.5);
  // A pinhole at the gel surface's distance sees mm_per_pixel there: ~28 mm away.
  EXPECT_NEAR(m.fx * m.mm_per_pixel, 28.0, 0.05);
  EXPECT_DOUBLE_EQ(m.fx, m.fy);
  EXPECT_EQ(m.shading.kind, ShadingKind::kAnalyticLeds);
  EXPECT_TRUE(m.background_image.empty());
  EXPECT_EQ(m.synthetic_background.glows.size(), 3u);
  EXPECT_DOUBLE_EQ(m.shear.shear_modulus_mpa, 0.145);  // FEATS: 2 x C10 = 2 x 0.0725 MPa
  // The dot grid: 7 x 9 on the landscape frame, all of it inside the image.
  EXPECT_TRUE(m.markers.enabled);
  EXPECT_EQ(m.markers.rows, 7);
  EXPECT_EQ(m.markers.cols, 9);
  EXPECT_LT((m.markers.cols - 1) * m.markers.pitch_mm + m.markers.dot_diameter_mm, m.gelWidthMm());
  EXPECT_LT((m.markers.rows - 1) * m.markers.pitch_mm + m.markers.dot_diameter_mm,
            m.gelHeightMm());
}

// The manufacturer's published presses: faces turned up blue, left red, right green.
TEST(GelSightMiniProfile, LedsSitWherePublishedPressesBrightenEachColour) {
  const SensorModel m = miniModel();
  for (const LedModel& led : m.leds) {
    SCOPED_TRACE(led.name);
    EXPECT_LT(led.position_mm[2], 0.0);  // behind the gel surface
    const double angle = imageAngleDeg(led);
    if (led.name == "blue") {
      EXPECT_NEAR(angle, -90.0, 1e-6);
      EXPECT_EQ(led.color_bgr, cv::Vec3d(1.0, 0.0, 0.0));
    } else if (led.name == "red") {
      EXPECT_NEAR(angle, 150.0, 1.0);
      EXPECT_EQ(led.color_bgr, cv::Vec3d(0.0, 0.0, 1.0));
    } else {
      EXPECT_EQ(led.name, "green");
      EXPECT_NEAR(angle, 30.0, 1.0);
      EXPECT_EQ(led.color_bgr, cv::Vec3d(0.0, 1.0, 0.0));
    }
  }
}

// Teal along the top, a lavender centre, olive towards the bottom, darker corners: the regions
// measured on two published Mini frames (the yaml's table), within a few grey levels.
TEST(GelSightMiniProfile, SyntheticBackgroundLooksLikeAMiniFrame) {
  const SensorModel m = miniModel();
  const cv::Mat3b frame = makeSyntheticBackground(m);
  ASSERT_EQ(frame.size(), cv::Size(320, 240));
  const auto expectNear = [&](int column, int row, cv::Vec3d target) {
    const cv::Vec3d mean = thirdMean(frame, column, row);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(mean[k], target[k], 8.0) << "third (" << column << ", " << row << ") channel "
                                            << k;
    }
  };
  expectNear(0, 0, {114, 108, 50});   // top-left
  expectNear(2, 0, {111, 98, 47});    // top-right
  expectNear(1, 1, {154, 126, 126});  // centre
  expectNear(0, 2, {92, 101, 70});    // bottom-left
  expectNear(1, 2, {103, 111, 98});   // bottom-centre
  expectNear(2, 2, {85, 91, 68});     // bottom-right
  // Not the DIGIT's look: its top-left is red-dominated, the Mini's is blue-green.
  const cv::Mat3b digit_look = makeSyntheticBackground(SyntheticBackgroundOptions{}, {320, 240});
  const cv::Vec3d digit = thirdMean(digit_look, 0, 0);
  const cv::Vec3d mini = thirdMean(frame, 0, 0);
  EXPECT_GT(digit[2], digit[0]);
  EXPECT_GT(mini[0], mini[2] + 40.0);
}

class GelSightMiniPress : public testing::Test {
 protected:
  static constexpr double kRadiusMm = 4.0;
  GelSightMiniPress() : model_(miniModel()), renderer_(model_) {
    renderer_.setObject(std::make_shared<const TexturedMesh>(makeUvSphere(kRadiusMm * 1e-3)));
  }
  // The ball's centre over gel point (x, y), its lowest point press_mm into the gel.
  const TactileFrame& press(double x_mm, double y_mm, double press_mm) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Vector3d(x_mm, y_mm, kRadiusMm - press_mm) * 1e-3;
    return renderer_.render(pose, -1);
  }
  SensorModel model_;
  TactileRenderer renderer_;
};

TEST_F(GelSightMiniPress, ABallPressIsLandscapeWithTheContactWhereTheBallIs) {
  const double x_mm = 3.0, y_mm = -2.0;
  const TactileFrame& frame = press(x_mm, y_mm, 1.0);
  ASSERT_EQ(frame.image.size(), cv::Size(320, 240));
  ASSERT_EQ(frame.contact_mask.size(), cv::Size(320, 240));
  const cv::Moments m = cv::moments(frame.contact_mask, true);
  ASSERT_GT(m.m00, 0.0);
  const cv::Point2d expected(x_mm / model_.mm_per_pixel + 0.5 * model_.cols - 0.5,
                             y_mm / model_.mm_per_pixel + 0.5 * model_.rows - 0.5);
  EXPECT_NEAR(m.m10 / m.m00, expected.x, 1.0);
  EXPECT_NEAR(m.m01 / m.m00, expected.y, 1.0);
  // The gel takes the ball's shape: a disc of the chord's radius sqrt(2 R d - d^2), 2.65 mm, to
  // within a pixel and a half (the Mini's pixels are larger than a DIGIT's).
  const double radius_mm = std::sqrt(m.m00 / CV_PI) * model_.mm_per_pixel;
  EXPECT_NEAR(radius_mm, std::sqrt(2.0 * kRadiusMm * 1.0 - 1.0), 1.5 * model_.mm_per_pixel);
}

// Above the contact the press turns blue, at its lower left red, at its lower right green: the
// shading difference (no background, no markers) at points 70 % of the way to the rim.
TEST_F(GelSightMiniPress, EachSideOfThePressTakesItsLedsColour) {
  const TactileFrame& frame = press(0.0, 0.0, 1.0);
  const cv::Mat3f diff = renderer_.shader().shadingDifference(frame.gel_mm);
  const double rim_px = 0.7 * std::sqrt(kRadiusMm * 1.0) / model_.mm_per_pixel;
  const cv::Point2d centre(0.5 * model_.cols - 0.5, 0.5 * model_.rows - 0.5);
  const auto at = [&](double angle_deg) {
    const double a = angle_deg * CV_PI / 180.0;
    const cv::Point p(static_cast<int>(std::lround(centre.x + rim_px * std::cos(a))),
                      static_cast<int>(std::lround(centre.y + rim_px * std::sin(a))));
    return cv::Vec3d(diff(p));
  };
  const cv::Vec3d up = at(-90.0), lower_left = at(150.0), lower_right = at(30.0);
  EXPECT_GT(up[0], 10.0);  // blue brightens above
  EXPECT_GT(up[0], up[1] + 10.0);
  EXPECT_GT(up[0], up[2] + 10.0);
  EXPECT_GT(lower_left[2], 10.0);  // red at the lower left
  EXPECT_GT(lower_left[2], lower_left[0] + 10.0);
  EXPECT_GT(lower_left[2], lower_left[1] + 10.0);
  EXPECT_GT(lower_right[1], 10.0);  // green at the lower right
  EXPECT_GT(lower_right[1], lower_right[0] + 10.0);
  EXPECT_GT(lower_right[1], lower_right[2] + 10.0);
}

// With no contact the frame is the synthetic background with the 63 dots drawn where the grid
// puts them, each darkened by about the measured 0.62 at its centre.
TEST_F(GelSightMiniPress, TheDotGridIsDrawnWhereTheYamlPutsIt) {
  const TactileFrame& frame = press(0.0, 0.0, -2.0);  // 2 mm above the gel
  EXPECT_EQ(cv::countNonZero(frame.contact_mask), 0);
  const cv::Mat3b background = makeSyntheticBackground(model_);
  const MarkerOptions& k = model_.markers;
  for (int row = 0; row < k.rows; ++row) {
    for (int col = 0; col < k.cols; ++col) {
      const double x_mm = (col - 0.5 * (k.cols - 1)) * k.pitch_mm;
      const double y_mm = (row - 0.5 * (k.rows - 1)) * k.pitch_mm;
      const cv::Point p(
          static_cast<int>(std::lround(x_mm / model_.mm_per_pixel + 0.5 * model_.cols - 0.5)),
          static_cast<int>(std::lround(y_mm / model_.mm_per_pixel + 0.5 * model_.rows - 0.5)));
      const double lit = brightness(frame.image(p));
      const double bare = brightness(background(p));
      EXPECT_NEAR(1.0 - lit / bare, k.darkness, 0.08) << "dot (" << row << ", " << col << ")";
    }
  }
  // Half-way between two dots the gel is bare.
  const cv::Point between(static_cast<int>(std::lround(0.5 * model_.cols - 0.5 +
                                                       0.5 * k.pitch_mm / model_.mm_per_pixel)),
                          static_cast<int>(std::lround(0.5 * model_.rows - 0.5)));
  EXPECT_EQ(frame.image(between), background(between));
}

}  // namespace
}  // namespace norm2tex
