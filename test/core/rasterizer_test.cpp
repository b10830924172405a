// ContactRasterizer: watertight coverage (every pixel exactly once under a closed surface seen
// from one side) and thread safety of the const rasterize().
#include <algorithm>
#include <cmath>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/render/contact_rasterizer.hpp"

namespace norm2tex {
namespace {

/// A flat grid of quads (two triangles each) in the object's z = 0 plane, `quads` per side,
/// `extent_mm` across, centred on the origin. Interior vertices are jittered by up to
/// `jitter` of a quad so that edges run at every angle; `centre_on_pixels` instead puts every
/// vertex exactly on a pixel centre of `model` (edges through centres: the fill rule decides).
TexturedMesh makeGrid(int quads, double extent_mm, double jitter, const SensorModel& model,
                      bool centre_on_pixels = false) {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
  cv::RNG rng(5);
  const double step = extent_mm / quads;
  for (int i = 0; i <= quads; ++i) {
    for (int j = 0; j <= quads; ++j) {
      double x = -0.5 * extent_mm + j * step, y = -0.5 * extent_mm + i * step;
      if (centre_on_pixels) {
        // Pixel centres sit at ((c + 0.5) - cols / 2) * mm_per_pixel.
        x = (std::round(x / model.mm_per_pixel + 0.5 * model.cols) - 0.5 * model.cols + 0.5) *
            model.mm_per_pixel;
        y = (std::round(y / model.mm_per_pixel + 0.5 * model.rows) - 0.5 * model.rows + 0.5) *
            model.mm_per_pixel;
      } else if (i > 0 && j > 0 && i < quads && j < quads) {
        x += rng.uniform(-jitter, jitter) * step;
        y += rng.uniform(-jitter, jitter) * step;
      }
      vertices.emplace_back(static_cast<float>(x * 1e-3), static_cast<float>(y * 1e-3), 0.0f);
    }
  }
  const auto index = [quads](int i, int j) { return i * (quads + 1) + j; };
  for (int i = 0; i < quads; ++i) {
    for (int j = 0; j < quads; ++j) {
      // Alternate the diagonal so edges of both slopes occur.
      if ((i + j) % 2 == 0) {
        triangles.emplace_back(index(i, j), index(i, j + 1), index(i + 1, j + 1));
        triangles.emplace_back(index(i, j), index(i + 1, j + 1), index(i + 1, j));
      } else {
        triangles.emplace_back(index(i, j), index(i, j + 1), index(i + 1, j));
        triangles.emplace_back(index(i, j + 1), index(i + 1, j + 1), index(i + 1, j));
      }
    }
  }
  return TexturedMesh(std::move(vertices), std::move(triangles));
}

Eigen::Isometry3d pressedAndTurned(double press_mm, double yaw) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.rotate(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  pose.translation() = Eigen::Vector3d(0.0, 0.0, -press_mm * 1e-3);
  return pose;
}

void expectEveryPixelExactlyOnce(const TexturedMesh& mesh, const Eigen::Isometry3d& pose,
                                 const SensorModel& model, const std::string& what) {
  const ContactRasterizer rasterizer(model);
  ContactRaster raster;
  rasterizer.rasterize(mesh, pose, 1.0, false, raster);
  const int pixels = model.rows * model.cols;
  EXPECT_EQ(cv::countNonZero(raster.face < 0), 0) << what << ": uncovered pixels (holes)";
  EXPECT_EQ(raster.pixel_hits, pixels) << what << ": pixels covered twice or not at all";
  double low, high;
  cv::minMaxLoc(raster.h_sensor_mm, &low, &high);
  EXPECT_NEAR(low, 0.5, 1e-4) << what;
  EXPECT_NEAR(high, 0.5, 1e-4) << what;
}

TEST(ContactRasterizer, FinelyTessellatedPlaneCoversEveryPixelExactlyOnce) {
  const SensorModel model = makeDigitSensorModel();
  // Quads of about 4 pixels, and sub-pixel triangles; jittered (by at most 0.2 of a quad, so
  // no triangle folds over) and turned: edges at all angles. 40 mm covers the turned gel.
  expectEveryPixelExactlyOnce(makeGrid(120, 40.0, 0.2, model), pressedAndTurned(0.5, 0.0), model,
                              "120x120 quads");
  expectEveryPixelExactlyOnce(makeGrid(120, 40.0, 0.2, model), pressedAndTurned(0.5, 0.37), model,
                              "120x120 quads, turned");
  expectEveryPixelExactlyOnce(makeGrid(700, 40.0, 0.2, model), pressedAndTurned(0.5, 0.11), model,
                              "700x700 sub-pixel quads");
  // Wide triangles (quads of ~90 pixels), whose rows are filled by closed-form spans.
  expectEveryPixelExactlyOnce(makeGrid(8, 40.0, 0.2, model), pressedAndTurned(0.5, 0.0), model,
                              "8x8 wide quads");
  expectEveryPixelExactlyOnce(makeGrid(8, 40.0, 0.2, model), pressedAndTurned(0.5, 0.37), model,
                              "8x8 wide quads, turned");
}

TEST(ContactRasterizer, CentresExactlyOnEdgesAndCornersAreDrawnOnce) {
  // Every vertex on a pixel centre, edges along rows, columns and diagonals through centres:
  // only the fill rule decides who owns them.
  const SensorModel model = makeDigitSensorModel();
  expectEveryPixelExactlyOnce(makeGrid(60, 30.0, 0.0, model, true), pressedAndTurned(0.5, 0.0),
                              model, "vertices on pixel centres");
  // The same mesh mirrored (triangles wound the other way seen from the gel).
  Eigen::Isometry3d flipped = pressedAndTurned(0.5, 0.0);
  flipped.rotate(Eigen::AngleAxisd(CV_PI, Eigen::Vector3d::UnitX()));
  expectEveryPixelExactlyOnce(makeGrid(60, 30.0, 0.0, model, true), flipped, model,
                              "vertices on pixel centres, flipped");
  // Wide triangles (~90 pixels a side): the closed-form row spans obey the same fill rule.
  for (const double yaw : {0.0, CV_PI / 2, CV_PI}) {
    expectEveryPixelExactlyOnce(makeGrid(6, 30.0, 0.0, model, true), pressedAndTurned(0.5, yaw),
                                model,
                                "wide triangles on pixel centres, yaw " + std::to_string(yaw));
  }
  expectEveryPixelExactlyOnce(makeGrid(6, 30.0, 0.0, model, true), flipped, model,
                              "wide triangles on pixel centres, flipped");
}

/// A square of two triangles, `extent_mm` across, on the plane z = z0 + zx x + zy y (mm, object
/// frame), with u = 0.5 + x / 40 mm and v = 0.5 + y / 60 mm (also affine, so exact for any
/// triangulation).
struct TiltedPlane {
  double z0, zx, zy;
  double z(double x, double y) const { return z0 + zx * x + zy * y; }
  static cv::Vec2f uv(double x, double y) {
    return cv::Vec2f(static_cast<float>(0.5 + x / 40.0), static_cast<float>(0.5 + y / 60.0));
  }
};

void addPlane(const TiltedPlane& plane, double extent_mm, std::vector<Eigen::Vector3f>& vertices,
              std::vector<Eigen::Vector2f>& uvs, std::vector<Eigen::Vector3i>& triangles) {
  const int first = static_cast<int>(vertices.size());
  const double h = 0.5 * extent_mm;
  for (const auto& [x, y] :
       {std::pair{-h, -h}, std::pair{h, -h}, std::pair{h, h}, std::pair{-h, h}}) {
    vertices.emplace_back(static_cast<float>(x * 1e-3), static_cast<float>(y * 1e-3),
                          static_cast<float>(plane.z(x, y) * 1e-3));
    const cv::Vec2f uv = TiltedPlane::uv(x, y);
    uvs.emplace_back(uv[0], uv[1]);
  }
  triangles.emplace_back(first, first + 1, first + 2);
  triangles.emplace_back(first, first + 2, first + 3);
}

/// Rasterizes `planes` (see addPlane) twice, the second frame starting from the first's raster
/// (only its covered box is cleared), and checks every pixel against the nearest plane.
void expectNearestPlaneEverywhere(const std::vector<TiltedPlane>& planes, double reach_mm,
                                  const std::string& what) {
  const SensorModel model = makeDigitSensorModel();
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector2f> uvs;
  std::vector<Eigen::Vector3i> triangles;
  for (const TiltedPlane& plane : planes) addPlane(plane, 40.0, vertices, uvs, triangles);
  const TexturedMesh mesh(std::move(vertices), std::move(triangles), std::move(uvs));
  const ContactRasterizer rasterizer(model);
  ContactRaster raster;
  for (int frame = 0; frame < 2; ++frame) {
    SCOPED_TRACE(what + ", frame " + std::to_string(frame));
    rasterizer.rasterize(mesh, Eigen::Isometry3d::Identity(), reach_mm, true, raster);
    int wrong_gap = 0, wrong_uv = 0, wrong_face = 0, wrong_empty = 0, covered = 0;
    std::vector<int> wins(planes.size(), 0);
    cv::Rect expected_box;
    for (int r = 0; r < model.rows; ++r) {
      for (int c = 0; c < model.cols; ++c) {
        const cv::Point2d p = model.pixelToGelMm(r, c);
        std::vector<double> z;
        for (const TiltedPlane& plane : planes) z.push_back(plane.z(p.x, p.y));
        const auto nearest = std::min_element(z.begin(), z.end());
        const int winner = static_cast<int>(nearest - z.begin());
        if (*nearest > reach_mm + 1e-4) {
          wrong_empty += std::isinf(raster.gap_mm(r, c)) && raster.face(r, c) < 0 ? 0 : 1;
          continue;
        }
        if (*nearest > reach_mm - 1e-4) continue;  // at the reach: float rounding decides
        ++covered;
        expected_box |= cv::Rect(c, r, 1, 1);
        wrong_gap += std::abs(raster.gap_mm(r, c) - *nearest) < 1e-4 ? 0 : 1;
        const bool tie = std::count_if(z.begin(), z.end(),
                                       [&](double other) { return other < *nearest + 1e-4; }) > 1;
        if (tie) continue;  // on a crossing: either plane is right
        ++wins[winner];
        wrong_face += raster.face(r, c) / 2 == winner ? 0 : 1;  // two triangles per plane
        wrong_uv += cv::norm(raster.uv(r, c) - TiltedPlane::uv(p.x, p.y)) < 1e-5 ? 0 : 1;
      }
    }
    EXPECT_GT(covered, model.rows * model.cols / 4);
    for (const int w : wins) EXPECT_GT(w, covered / 10) << "every plane is nearest somewhere";
    EXPECT_EQ(wrong_gap, 0);
    EXPECT_EQ(wrong_uv, 0);
    EXPECT_EQ(wrong_face, 0);
    EXPECT_EQ(wrong_empty, 0) << "pixels above the reach stay empty";
    // The box of written pixels: the expected one, give or take the pixels at the reach.
    EXPECT_LE(std::abs(raster.covered_box.x - expected_box.x), 1);
    EXPECT_LE(std::abs(raster.covered_box.y - expected_box.y), 1);
    EXPECT_LE(std::abs(raster.covered_box.br().x - expected_box.br().x), 1);
    EXPECT_LE(std::abs(raster.covered_box.br().y - expected_box.br().y), 1);
  }
}

TEST(ContactRasterizer, WideTrianglesGiveTheExactGapUvAndNearestSurfacePerPixel) {
  // Triangles far wider than the image: every row is a few long spans (the vectorised fill).
  // Two crossing planes: the depth test flips between them along each row. One plane rising to
  // the left: the reach cuts each row in the middle of a span, so the covered box starts there.
  expectNearestPlaneEverywhere({{-0.2, 0.05, 0.02}, {0.1, -0.06, 0.01}}, 0.25, "crossing planes");
  expectNearestPlaneEverywhere({{0.2, -0.05, 0.003}}, 0.25, "one plane cut by the reach");
}

TEST(ContactRasterizer, TwoThreadsSharingOneRasterizerGiveTheSameRastersAsOne) {
  const SensorModel model = makeDigitSensorModel();
  const ContactRasterizer rasterizer(model);
  const TexturedMesh sphere = makeUvSphere(5e-3, 48, 96);
  const int frames = 60;
  const auto poseOf = [](int frame) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.rotate(Eigen::AngleAxisd(0.05 * frame, Eigen::Vector3d::UnitY()));
    pose.translation() = Eigen::Vector3d(-3e-3 + 1e-4 * frame, 0.05e-3 * frame, 4.2e-3);
    return pose;
  };
  std::vector<ContactRaster> alone(frames);
  for (int f = 0; f < frames; ++f) rasterizer.rasterize(sphere, poseOf(f), 1.0, true, alone[f]);

  std::vector<ContactRaster> threaded(frames);
  const auto work = [&](int first) {
    ContactRaster raster;  // one reused raster per thread, as a renderer would hold
    for (int f = first; f < frames; f += 2) {
      rasterizer.rasterize(sphere, poseOf(f), 1.0, true, raster);
      threaded[f].gap_mm = raster.gap_mm.clone();
      threaded[f].uv = raster.uv.clone();
      threaded[f].face = raster.face.clone();
    }
  };
  std::thread even(work, 0), odd(work, 1);
  even.join();
  odd.join();
  int different = 0;
  for (int f = 0; f < frames; ++f) {
    const bool same = cv::norm(alone[f].face, threaded[f].face, cv::NORM_INF) == 0 &&
                      cv::norm(alone[f].uv, threaded[f].uv, cv::NORM_INF) == 0 &&
                      cv::countNonZero(alone[f].gap_mm != threaded[f].gap_mm) == 0;
    different += same ? 0 : 1;
  }
  EXPECT_EQ(different, 0) << "of " << frames << " frames";
  EXPECT_GT(cv::countNonZero(alone[frames / 2].face >= 0), 1000) << "the sphere touches";
}

}  // namespace
}  // namespace norm2tex
