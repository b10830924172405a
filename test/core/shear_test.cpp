// The shear stage against analytic truth: Cerruti's half-space under a uniform traction on a
// circle, Mindlin's stick radius for a sphere, the traction's balance and friction limit, markers
// that follow the shear (and stay put under a pure press), and the marker grid as configured.
#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "norm2tex/shear/cerruti_kernel.hpp"
#include "norm2tex/shear/contact_traction.hpp"
#include "norm2tex/shear/layer_compliance.hpp"
#include "norm2tex/shear/marker_pattern.hpp"
#include "norm2tex/shear/shear_field.hpp"
#include "norm2tex/shear/shear_grid.hpp"
#include "norm2tex/shear/surface_displacement.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

constexpr double kPi = 3.14159265358979323846;

// u_x at (x, y) of a uniform traction q along x on the disc of radius a at the origin, by
// quadrature of Cerruti's point kernel in polar coordinates about the field point (whose 1/r
// singularity the r dr of the area element cancels): an independent reference, to 1e-5.
double discDisplacementX(double x, double y, double a, double q, double g) {
  const int angles = 4000;
  double sum = 0.0;
  for (int n = 0; n < angles; ++n) {
    const double t = (n + 0.5) * 2.0 * kPi / angles;
    const double c = std::cos(t), s = std::sin(t);
    // The ray from (x, y) along (c, s) lies in the disc for rho in [lo, hi].
    const double b = x * c + y * s;
    const double disc = b * b - (x * x + y * y - a * a);
    if (disc <= 0.0) continue;
    const double hi = -b + std::sqrt(disc);
    const double lo = std::max(0.0, -b - std::sqrt(disc));
    if (hi <= lo) continue;
    // Integrand (1/rho + c^2/rho) rho = 1 + c^2, constant along the ray.
    sum += (1.0 + c * c) * (hi - lo);
  }
  return q / (4.0 * kPi * g) * sum * 2.0 * kPi / angles;
}

TEST(CerrutiKernel, CellIntegralIsExactUnderTheCellAndTheAreaTimesThePointKernelFarAway) {
  const double g = 0.1, cell = 0.2;
  const LateralInfluence self = cerrutiCellInfluence(0.0, 0.0, cell, g);
  // Over a square of side 2b: the integral of 1/r is 8 b asinh(1), of x^2/r^3 half of that.
  const double b = 0.5 * cell;
  EXPECT_NEAR(self.xx, 1.0 / (4 * kPi * g) * 1.5 * 8 * b * std::asinh(1.0), 1e-12);
  EXPECT_NEAR(self.xy, 0.0, 1e-12);
  EXPECT_NEAR(self.yy, self.xx, 1e-12);
  const LateralInfluence far = cerrutiCellInfluence(6.0, 3.0, cell, g);
  const LateralInfluence point = cerrutiPointKernel(6.0, 3.0, g);
  EXPECT_NEAR(far.xx / (point.xx * cell * cell), 1.0, 1e-3);
  EXPECT_NEAR(far.xy / (point.xy * cell * cell), 1.0, 1e-3);
  EXPECT_NEAR(far.yy / (point.yy * cell * cell), 1.0, 1e-3);
}

// Johnson (1985) 3.6: a uniform tangential traction q on a disc of radius a moves its centre by
// u_x = (2 - nu) q a / (2 G) = 0.75 q a / G at nu = 1/2. Outside, the displacement decays towards
// the point force's (1 - nu)/r + nu x^2/r^3 = 1/r along x.
TEST(SurfaceDisplacement, UniformTractionOnADiscMatchesCerrutiAtTheCentreAndAsItDecays) {
  const double g = 0.05, a = 2.0, q = 0.01, cell = 0.05;
  const int n = 241;  // cells; the disc's centre is the middle cell's
  SurfaceDisplacement solver(n, n, cell, g);
  cv::Mat1f qx = cv::Mat1f::zeros(n, n), qy = cv::Mat1f::zeros(n, n);
  const int mid = n / 2;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      if (std::hypot((i - mid) * cell, (j - mid) * cell) <= a) qx(i, j) = static_cast<float>(q);
    }
  }
  cv::Mat1f ux, uy;
  solver.solve(qx, qy, ux, uy);
  const double centre = 0.75 * q * a / g;
  EXPECT_NEAR(ux(mid, mid) / centre, 1.0, 0.03);
  EXPECT_NEAR(centre / discDisplacementX(0.0, 0.0, a, q, g), 1.0, 1e-4) << "the reference itself";
  for (const double r : {1.0, 1.5, 2.5, 3.0, 4.0, 5.5}) {
    const int j = mid + static_cast<int>(std::lround(r / cell));
    const double along = discDisplacementX((j - mid) * cell, 0.0, a, q, g);
    EXPECT_NEAR(ux(mid, j) / along, 1.0, 0.03) << "at x = " << r << " mm";
    EXPECT_NEAR(uy(mid, j), 0.0, 1e-6 * centre) << "symmetric about the x axis";
    const double across = discDisplacementX(0.0, (j - mid) * cell, a, q, g);
    EXPECT_NEAR(ux(j, mid) / across, 1.0, 0.03) << "at y = " << r << " mm";
  }
  // Far from the disc it acts as its point force, Q / (4 pi G) (1/r + x^2/r^3): twice as far
  // reaching along the force as across it.
  const double far = (n - 1 - mid) * cell;
  const double force = q * kPi * a * a;
  EXPECT_NEAR(ux(mid, n - 1) / (force / (4 * kPi * g) * 2.0 / far), 1.0, 0.03);
  EXPECT_NEAR(ux(mid, n - 1) / ux(n - 1, mid), 2.0, 0.1);
}

// The layer's compliance between its two limits: a half-space's 1/k and 1/(2k) at wavelengths
// far below the thickness, the simple shear h / G of a thin layer far above it, and the
// antiplane mode's closed form tanh(kh) / k in between.
TEST(LayerCompliance, TendsToTheHalfSpaceAndToSimpleShear) {
  const double h = 4.0;
  for (const double kh : {8.0, 12.0, 14.9}) {
    const LayerCompliance c = layerCompliance(kh / h, h);
    EXPECT_NEAR(c.transverse * kh / h, 1.0, 1e-5) << kh;
    EXPECT_NEAR(c.longitudinal * kh / h, 0.5, 2e-3) << kh;
  }
  for (const double kh : {1e-3, 1e-2}) {
    const LayerCompliance c = layerCompliance(kh / h, h);
    EXPECT_NEAR(c.transverse / h, 1.0, 1e-4) << kh;
    EXPECT_NEAR(c.longitudinal / h, 1.0, 1e-3) << kh;
  }
  EXPECT_NEAR(layerCompliance(0.25, h).transverse, std::tanh(1.0) / 0.25, 1e-12);
  // Continuous across the shortcut at k h = 15.
  EXPECT_NEAR(layerCompliance(14.999 / h, h).longitudinal / layerCompliance(15.001 / h, h).longitudinal,
              1.0, 1e-3);
  test::expectError([] { layerCompliance(0.0, 1.0); }, {"> 0"});
}

// A layer much thinner than a uniformly sheared patch is in simple shear under its middle:
// u = q h / G. A layer much thicker than the patch is a half-space under it.
TEST(SurfaceDisplacement, ALayerShearsSimplyWhenThinAndAsAHalfSpaceWhenThick) {
  const double g = 0.1, q = 0.01, cell = 0.1;
  const int n = 120;
  cv::Mat1f qx = cv::Mat1f::zeros(n, n), qy = cv::Mat1f::zeros(n, n), ux, uy;
  qx(cv::Rect(30, 30, 60, 60)).setTo(q);  // a 6 mm square
  SurfaceDisplacement thin(n, n, cell, g, 0.5);
  thin.solve(qx, qy, ux, uy);
  EXPECT_NEAR(ux(60, 60) / (q * 0.5 / g), 1.0, 0.03);
  // 4 h beyond the patch's edge the layer has nearly let go (a half-space would still move by
  // 45 % of its own centre's displacement there): along the traction, and faster across it.
  EXPECT_LT(std::abs(ux(60, 109)), 0.03 * ux(60, 60)) << "2 mm beyond the edge along x";
  EXPECT_LT(std::abs(ux(109, 60)), 0.001 * ux(60, 60)) << "2 mm beyond the edge along y";
  EXPECT_NEAR(uy(60, 60), 0.0, 1e-6);

  cv::Mat1f disc = cv::Mat1f::zeros(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      if (std::hypot(i - 60, j - 60) * cell <= 1.0) disc(i, j) = static_cast<float>(q);
    }
  }
  cv::Mat1f half_x, half_y;
  SurfaceDisplacement half_space(n, n, cell, g);
  half_space.solve(disc, qy, half_x, half_y);
  SurfaceDisplacement thick(n, n, cell, g, 40.0);
  thick.solve(disc, qy, ux, uy);
  EXPECT_NEAR(ux(60, 60) / half_x(60, 60), 1.0, 0.03) << "h = 40 radii";
  SurfaceDisplacement gel(n, n, cell, g, 2.0);
  gel.solve(disc, qy, ux, uy);
  EXPECT_LT(ux(60, 60), half_x(60, 60)) << "h = 2 radii: stiffer than a half-space";
  EXPECT_GT(ux(60, 60), 0.5 * half_x(60, 60));
  EXPECT_LT(ux(60, 110), 0.3 * half_x(60, 110)) << "5 mm away the layer has hardly moved";
}

TEST(SurfaceDisplacement, BadGridsAndTractionsAreErrors) {
  test::expectError([] { SurfaceDisplacement(0, 5, 0.1, 0.1); }, {"empty"});
  test::expectError([] { SurfaceDisplacement(5, 5, 0.0, 0.1); }, {"> 0"});
  test::expectError([] { SurfaceDisplacement(5, 5, 0.1, 0.1, -1.0); }, {"thickness"});
  SurfaceDisplacement solver(4, 5, 0.1, 0.1);
  cv::Mat1f q = cv::Mat1f::zeros(5, 4), ux, uy;
  test::expectError([&] { solver.solve(q, q, ux, uy); }, {"4 x 5"});
}

// A sphere's penetration d = delta (1 - r^2 / a^2) on a fine grid.
cv::Mat1f spherePenetration(int n, double cell, double a, double delta) {
  cv::Mat1f d = cv::Mat1f::zeros(n, n);
  const double mid = 0.5 * n;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double r2 = std::pow((i + 0.5 - mid) * cell, 2) + std::pow((j + 0.5 - mid) * cell, 2);
      d(i, j) = static_cast<float>(std::max(0.0, delta * (1.0 - r2 / (a * a))));
    }
  }
  return d;
}

// Mindlin (1949), Johnson 7.2: a sphere under a growing tangential force Q < mu P sticks inside
// c / a = (1 - Q / (mu P))^(1/3) and slips outside it; at Q = mu P the whole contact slides.
TEST(ContactTraction, ASphereSticksInsideMindlinsRadiusAndSlidesAtTheFrictionLimit) {
  const double cell = 0.02, a = 2.0, force = 5.0, mu = 0.8;
  const cv::Mat1f d = spherePenetration(240, cell, a, 0.2);
  for (const double ratio : {0.1, 0.3, 0.5, 0.7, 0.9}) {
    ShearLoad load;
    load.force_n = {ratio * mu * force * 0.6, ratio * mu * force * 0.8};
    const ContactTraction t = solveContactTraction(d, cell, force, load, mu);
    const double c_over_a = std::sqrt(static_cast<double>(t.stick_cells) / t.contact_cells);
    EXPECT_NEAR(c_over_a, std::cbrt(1.0 - ratio), 0.05 * std::cbrt(1.0 - ratio))
        << "Q / mu P = " << ratio;
    EXPECT_FALSE(t.gross_slip);
    EXPECT_NEAR(t.slip_fraction, 1.0 - c_over_a * c_over_a, 1e-9);
    // The traction carries Q, along Q; the pressure carries P; nowhere more than friction's.
    const double area = cell * cell;
    EXPECT_NEAR(cv::sum(t.qx_mpa)[0] * area, load.force_n.x(), 1e-3 * load.force_n.norm());
    EXPECT_NEAR(cv::sum(t.qy_mpa)[0] * area, load.force_n.y(), 1e-3 * load.force_n.norm());
    EXPECT_NEAR(cv::sum(t.pressure_mpa)[0] * area, force, 1e-4 * force);
    cv::Mat1f q_mag;
    cv::magnitude(t.qx_mpa, t.qy_mpa, q_mag);
    cv::Mat1f excess = q_mag - mu * t.pressure_mpa;
    double worst = 0.0;
    cv::minMaxLoc(excess, nullptr, &worst);
    EXPECT_LE(worst, 1e-6);
  }
  ShearLoad limit;
  limit.force_n = {mu * force, 0.0};
  const ContactTraction slide = solveContactTraction(d, cell, force, limit, mu);
  EXPECT_TRUE(slide.gross_slip);
  EXPECT_EQ(slide.stick_cells, 0);
  EXPECT_DOUBLE_EQ(slide.slip_fraction, 1.0);
  EXPECT_NEAR(cv::sum(slide.qx_mpa)[0] * cell * cell, mu * force, 1e-3);
}

// A twist gives the moment asked for, circles the pressure centre in its sense, starts slipping
// at the rim, and slides when it asks more than friction gives.
TEST(ContactTraction, ATwistGivesItsMomentAndSlipsFromTheRim) {
  const double cell = 0.04, a = 2.0, force = 4.0, mu = 1.0;
  const cv::Mat1f d = spherePenetration(120, cell, a, 0.2);
  ShearLoad load;
  load.torque_nm = 1.5e-3;  // N m; friction's most is 3 pi mu P a / 16 = 4.7e-3 N m for Hertz
  const ContactTraction t = solveContactTraction(d, cell, force, load, mu);
  double moment = 0.0;
  for (int i = 0; i < d.rows; ++i) {
    for (int j = 0; j < d.cols; ++j) {
      const double x = (j + 0.5) * cell - t.pressure_centre_mm.x();
      const double y = (i + 0.5) * cell - t.pressure_centre_mm.y();
      moment += (x * t.qy_mpa(i, j) - y * t.qx_mpa(i, j)) * cell * cell;
    }
  }
  EXPECT_NEAR(moment * 1e-3, load.torque_nm, 1e-3 * load.torque_nm);
  EXPECT_GT(t.slip_fraction, 0.0);
  EXPECT_LT(t.slip_fraction, 1.0);
  EXPECT_EQ(t.stick(60, 60), 255) << "the centre sticks";
  EXPECT_EQ(t.stick(60, 60 + 48), 0) << "the rim slips";
  EXPECT_NEAR(cv::sum(t.qx_mpa)[0], 0.0, 1e-3 * cv::norm(t.qx_mpa, cv::NORM_L1));
  load.torque_nm = -1e-2;
  const ContactTraction beyond = solveContactTraction(d, cell, force, load, mu);
  EXPECT_TRUE(beyond.gross_slip);
  EXPECT_DOUBLE_EQ(beyond.slip_fraction, 1.0);
  EXPECT_LT(beyond.qy_mpa(60, 60 + 30), 0.0f) << "clockwise: -y on the +x side";
}

TEST(ContactTraction, BadLoadsAreClearErrors) {
  const cv::Mat1f d = spherePenetration(20, 0.1, 0.8, 0.1);
  ShearLoad load;
  test::expectError([&] { solveContactTraction(d, 0.1, -1.0, load, 1.0); }, {"normal force"});
  test::expectError([&] { solveContactTraction(d, 0.1, NAN, load, 1.0); }, {"normal force"});
  test::expectError([&] { solveContactTraction(d, 0.1, 1.0, load, 0.0); }, {"friction"});
  load.force_n.x() = NAN;
  test::expectError([&] { solveContactTraction(d, 0.1, 1.0, load, 1.0); }, {"finite"});
  load.force_n.x() = 0.0;
  load.torque_nm = INFINITY;
  test::expectError([&] { solveContactTraction(d, 0.1, 1.0, load, 1.0); }, {"finite"});
}

SensorModel markedModel() {
  SensorModel m = makeDigitSensorModel();
  m.background_image.clear();
  m.markers.enabled = true;
  m.markers.rows = 7;
  m.markers.cols = 5;
  m.markers.pitch_mm = 2.0;
  m.markers.dot_diameter_mm = 0.6;
  m.markers.darkness = 0.8;
  m.markers.blur_mm = 0.02;
  return m;
}

// Dots measured in a drawn image: their centres at the pitch, their size the diameter.
TEST(ShearGrid, CellsAverageThePenetrationTheyCoverEvenWhereTheImageCutsThem) {
  SensorModel model = makeDigitSensorModel();
  const ShearGrid grid = ShearGrid::of(model);
  // 0.4 mm at 0.054 mm per pixel: 7 px cells, 35 x 46 of them over 240 x 320 px (the last
  // column and row of cells 2 and 5 px wide).
  EXPECT_EQ(grid.cell_px, 7);
  EXPECT_NEAR(grid.cell_mm, 7 * model.mm_per_pixel, 1e-12);
  EXPECT_EQ(grid.size, cv::Size(35, 46));
  EXPECT_EQ(grid.image, model.imageSize());
  EXPECT_EQ(ShearGrid::of(model, 16).size, cv::Size(15, 20));
  test::expectError([&] { ShearGrid::of(model, -1); }, {"cell_px"});

  // Rows of value = row index: a cell's mean is the mean of its rows, the cut last row's too.
  cv::Mat1f h(model.imageSize());
  for (int r = 0; r < h.rows; ++r) h.row(r).setTo(static_cast<float>(r));
  cv::Mat1f cells;
  meanCellPenetration(h, cv::Rect(), grid, cells);
  ASSERT_EQ(cells.size(), grid.size);
  EXPECT_FLOAT_EQ(cells(0, 0), 3.0f);        // rows 0..6
  EXPECT_FLOAT_EQ(cells(45, 34), 317.0f);    // rows 315..319, columns 238..239
  // Only cells the covered box reaches are read (whole: outside its box H_sensor is 0); the
  // others are 0.
  cv::Mat1f boxed;
  meanCellPenetration(h, cv::Rect(0, 0, 240, 10), grid, boxed);
  EXPECT_FLOAT_EQ(boxed(0, 0), 3.0f);
  EXPECT_FLOAT_EQ(boxed(1, 0), 10.0f);       // rows 7..13
  EXPECT_FLOAT_EQ(boxed(2, 0), 0.0f);
  test::expectError([&] { meanCellPenetration(cv::Mat1f(10, 10, 0.0f), cv::Rect(), grid, cells); },
                    {"10 x 10", "240 x 320"});
}

TEST(MarkerPattern, DotsRenderAtTheConfiguredPitchAndDiameter) {
  const SensorModel m = markedModel();
  const MarkerPattern pattern(m);
  ASSERT_EQ(pattern.restPx().size(), 35u);
  cv::Mat3b image(m.rows, m.cols, cv::Vec3b(200, 200, 200));
  std::vector<Marker> markers;
  for (const cv::Point2f& p : pattern.restPx()) markers.push_back({p, p, {0, 0}});
  pattern.draw(image, markers);
  cv::Mat1b grey, dark;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  // Half the darkness: 200 (1 - 0.8 / 2) = 120.
  cv::threshold(grey, dark, 120, 255, cv::THRESH_BINARY_INV);
  cv::Mat labels, stats, centroids;
  const int found = cv::connectedComponentsWithStats(dark, labels, stats, centroids) - 1;
  ASSERT_EQ(found, 35);
  const double px_per_mm = 1.0 / m.mm_per_pixel;
  double area = 0.0;
  for (int k = 1; k <= found; ++k) area += stats.at<int>(k, cv::CC_STAT_AREA);
  const double diameter_mm = 2.0 * std::sqrt(area / found / kPi) / px_per_mm;
  EXPECT_NEAR(diameter_mm, 0.6, 0.03);
  // Components come out in raster order: along a row, neighbours are one pitch apart.
  double sum = 0.0;
  int pairs = 0;
  for (int k = 1; k < found; ++k) {
    if (k % 5 == 0) continue;  // the next row starts
    sum += centroids.at<double>(k + 1, 0) - centroids.at<double>(k, 0);
    ++pairs;
  }
  EXPECT_NEAR(sum / pairs / px_per_mm, 2.0, 0.01);
  EXPECT_NEAR(centroids.at<double>(1, 1), pattern.restPx()[0].y, 0.05);
  EXPECT_NEAR(grey(cvRound(pattern.restPx()[0].y), cvRound(pattern.restPx()[0].x)), 40, 3)
      << "the dot's centre keeps 1 - darkness of the light";
}

TEST(MarkerPattern, JitterIsSeededAndBounded) {
  SensorModel m = markedModel();
  m.markers.jitter_mm = 0.2;
  const MarkerPattern a(m), b(m);
  m.markers.seed = 1;
  const MarkerPattern c(m);
  m.markers.jitter_mm = 0.0;
  const MarkerPattern grid(m);
  bool differs = false;
  for (size_t k = 0; k < grid.restPx().size(); ++k) {
    EXPECT_EQ(a.restPx()[k], b.restPx()[k]);
    const cv::Point2f off = a.restPx()[k] - grid.restPx()[k];
    EXPECT_LE(std::max(std::abs(off.x), std::abs(off.y)) * m.mm_per_pixel, 0.2 + 1e-6);
    differs |= a.restPx()[k] != c.restPx()[k];
  }
  EXPECT_TRUE(differs) << "another seed, another jitter";
}

// The renderer with markers: a ball pressed and pushed along +x carries the markers near it
// along +x, those far away less; a pure press leaves every marker where it was (nu = 1/2); a
// twist turns them about the contact.
class ShearRender : public ::testing::Test {
 protected:
  static Eigen::Isometry3d pressed(double press_mm) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Vector3d(0.0, 0.0, (kRadiusMm - press_mm) * 1e-3);
    return pose;
  }
  void SetUp() override {
    renderer_.setObject(std::make_shared<const TexturedMesh>(makeUvSphere(kRadiusMm * 1e-3)));
  }
  static constexpr double kRadiusMm = 6.0;
  SensorModel model_ = markedModel();
  TactileRenderer renderer_{model_};
};

TEST_F(ShearRender, APurePressLeavesTheMarkersWhereTheyWere) {
  const TactileFrame& frame = renderer_.render(pressed(1.0), -1, 3.0, ShearLoad{});
  ASSERT_TRUE(frame.shear);
  ASSERT_EQ(frame.shear->markers.size(), 35u);
  for (const Marker& m : frame.shear->markers) {
    EXPECT_EQ(m.current_px, m.rest_px);
  }
  EXPECT_EQ(frame.shear->slipFraction(), 0.0);
  EXPECT_GT(frame.shear->traction.contact_cells, 10);
}

TEST_F(ShearRender, MarkersMoveWithTheShearAndTurnWithATwist) {
  ShearLoad push;
  push.force_n = {1.0, 0.0};
  const TactileFrame& frame = renderer_.render(pressed(1.0), -1, 3.0, push);
  ASSERT_TRUE(frame.shear);
  const std::vector<Marker> pushed = frame.shear->markers;
  const Marker& centre = pushed[17];  // row 3, column 2: the middle of a 7 x 5 grid
  EXPECT_GT(centre.displacement_mm.x, 0.05);
  EXPECT_NEAR(centre.displacement_mm.y, 0.0, 1e-3);
  EXPECT_GT(centre.displacement_mm.x, 2.0 * pushed[0].displacement_mm.x) << "decays with distance";
  EXPECT_GT(pushed[0].displacement_mm.x, 0.0f);
  EXPECT_GT(frame.shear->slipFraction(), 0.0) << "the rim of a sphere's contact slips at once";
  // The image: the centre dot drawn where the shear carried it.
  cv::Mat1b grey;
  cv::cvtColor(frame.image, grey, cv::COLOR_BGR2GRAY);
  const cv::Point moved(cvRound(centre.current_px.x), cvRound(centre.current_px.y));
  EXPECT_LT(grey(moved), grey(cvRound(centre.rest_px.y), cvRound(centre.rest_px.x) -
                                  cvRound(0.7 / model_.mm_per_pixel)));

  ShearLoad twist;
  twist.torque_nm = 2e-3;
  const TactileFrame& turned = renderer_.render(pressed(1.0), -1, 3.0, twist);
  // Counter-clockwise (x towards y): right of the centre moves +y, above it (-y) moves +x.
  const Marker& right = turned.shear->markers[18];
  const Marker& above = turned.shear->markers[12];
  EXPECT_GT(right.displacement_mm.y, 0.01);
  EXPECT_NEAR(right.displacement_mm.x, 0.0, 0.2 * right.displacement_mm.y);
  EXPECT_GT(above.displacement_mm.x, 0.01);
  EXPECT_NEAR(turned.shear->markers[17].displacement_mm.x, 0.0, 1e-3) << "the centre stays";
}

// Markers off: a shear load changes nothing in the image (DIGIT frames as before), and no
// load, no shear stage at all.
TEST(ShearRenderOff, WithoutMarkersTheImageIsTheSameWithOrWithoutALoad) {
  SensorModel model = makeDigitSensorModel();
  model.background_image.clear();
  TactileRenderer renderer(model);
  renderer.setObject(std::make_shared<const TexturedMesh>(makeUvSphere(6e-3)));
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation().z() = 5e-3;
  const cv::Mat3b plain = renderer.render(pose, 3).image.clone();
  EXPECT_FALSE(renderer.render(pose, 3).shear);
  ShearLoad load;
  load.force_n = {1.0, -0.5};
  const TactileFrame& sheared = renderer.render(pose, 3, std::nullopt, load);
  EXPECT_EQ(cv::norm(plain, sheared.image, cv::NORM_INF), 0.0);
  ASSERT_TRUE(sheared.shear);
  EXPECT_TRUE(sheared.shear->markers.empty());
  EXPECT_GT(cv::norm(sheared.shear->ux_mm, cv::NORM_INF), 0.0);
  const cv::Mat2f field = sheared.shear->displacementMetres(model.imageSize());
  EXPECT_EQ(field.size(), model.imageSize());
  EXPECT_GT(field(160, 120)[0], 0.0f);
  EXPECT_LT(field(160, 120)[1], 0.0f);
}

}  // namespace
}  // namespace norm2tex
