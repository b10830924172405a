// The gel contact geometry against analytic truth: where boxes, tilted boxes, spheres and
// capsules reach into a gel pad and how deep, clipping at the pad's edges, the four points a
// manifold keeps, and how deep a mesh's hollows lie under its hull.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "norm2tex/sim/gel_contact.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

const GelPad kPad{0.0096, 0.0128};  // the DIGIT's 19.2 x 25.6 mm pad

ConvexPolytope cube(double size) {
  std::vector<Eigen::Vector3d> corners;
  for (int k = 0; k < 8; ++k) {
    corners.push_back(0.5 * size * Eigen::Vector3d(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1));
  }
  return ConvexPolytope::hullOf(corners);
}

Eigen::Isometry3d at(const Eigen::Vector3d& position,
                     const Eigen::Matrix3d& rotation = Eigen::Matrix3d::Identity()) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation;
  pose.translation() = position;
  return pose;
}

double deepest(const std::vector<GelContactPoint>& points) {
  double d = 0;
  for (const GelContactPoint& p : points) d = std::max(d, p.depth);
  return d;
}

TEST(GelContactTest, HullOfACubeHasItsSixFacesAndEightCorners) {
  const ConvexPolytope c = cube(0.01);
  EXPECT_EQ(c.vertices.size(), 8u);
  EXPECT_EQ(c.faces.size(), 6u);
  EXPECT_NEAR(c.radius, 0.005 * std::sqrt(3.0), 1e-9);
  test::expectError([] { ConvexPolytope::hullOf({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}); },
                    {"no volume"});
}

TEST(GelContactTest, AFlatFacePressedIntoThePadGivesItsFourCornersAtTheDepth) {
  // A 10 mm cube 0.5 mm into the gel, 2 mm off the pad's centre.
  const auto points = gelContactPoints(cube(0.01), at({0.002, -0.001, 0.005 - 0.5e-3}), kPad);
  ASSERT_EQ(points.size(), 4u);
  for (const GelContactPoint& p : points) {
    EXPECT_NEAR(p.depth, 0.5e-3, 1e-9);
    EXPECT_NEAR(p.position.z(), -0.5e-3, 1e-9);
    EXPECT_NEAR(std::abs(p.position.x() - 0.002), 0.005, 1e-9);
    EXPECT_NEAR(std::abs(p.position.y() + 0.001), 0.005, 1e-9);
  }
  // Just above the surface: nothing.
  EXPECT_TRUE(gelContactPoints(cube(0.01), at({0, 0, 0.005 + 1e-6}), kPad).empty());
}

TEST(GelContactTest, AFaceLargerThanThePadIsClippedToThePadsCorners) {
  const auto points = gelContactPoints(cube(0.04), at({0, 0, 0.02 - 1e-3}), kPad);
  ASSERT_EQ(points.size(), 4u);
  for (const GelContactPoint& p : points) {
    EXPECT_NEAR(std::abs(p.position.x()), kPad.half_width_m, 1e-9);
    EXPECT_NEAR(std::abs(p.position.y()), kPad.half_height_m, 1e-9);
    EXPECT_NEAR(p.depth, 1e-3, 1e-9);
  }
}

TEST(GelContactTest, ATiltedCubePressesItsEdgeAsDeepAsGeometrySays) {
  // Rotated 30 degrees about x: its lowest edge runs along x, h = s/2 (cos a + sin a) below
  // the centre (the support of a rotated square).
  const double s = 0.01, a = 30 * M_PI / 180, h = s / 2 * (std::cos(a) + std::sin(a));
  const Eigen::Matrix3d r = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const auto points = gelContactPoints(cube(s), at({0, 0, h - 0.3e-3}, r), kPad);
  EXPECT_NEAR(deepest(points), 0.3e-3, 1e-9);
  // The deepest points are the edge's two ends, at x = +-5 mm; every point lies on the cube.
  int at_edge = 0;
  for (const GelContactPoint& p : points) {
    if (std::abs(p.depth - 0.3e-3) < 1e-9) {
      ++at_edge;
      EXPECT_NEAR(std::abs(p.position.x()), s / 2, 1e-9);
    }
  }
  EXPECT_EQ(at_edge, 2);
}

TEST(GelContactTest, SphereTouchesAtItsLowestPointAndReachesOverThePadsEdge) {
  const Capsule ball{{0, 0, 0}, {0, 0, 0}, 0.004};
  auto points = gelContactPoints(ball, at({0.001, 0.002, 0.004 - 0.6e-3}), kPad);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_NEAR(points[0].depth, 0.6e-3, 1e-12);
  EXPECT_NEAR(points[0].position.x(), 0.001, 1e-12);
  EXPECT_NEAR(points[0].position.y(), 0.002, 1e-12);
  // Centre 1 mm beyond the pad's right edge, 1 mm deep at its lowest: over the pad it reaches
  // sqrt(r^2 - 1 mm^2) - (r - 1 mm) deep at the edge.
  const double r = 0.004, z = r - 1e-3;
  points = gelContactPoints(ball, at({kPad.half_width_m + 1e-3, 0, z}), kPad);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_NEAR(points[0].depth, std::sqrt(r * r - 1e-6) - z, 1e-6 * 1e-3);
  EXPECT_NEAR(points[0].position.x(), kPad.half_width_m, 1e-12);
  EXPECT_TRUE(gelContactPoints(ball, at({kPad.half_width_m + r + 1e-4, 0, 0}), kPad).empty());
}

TEST(GelContactTest, ALyingCapsuleLongerThanThePadTouchesAlongItUpToThePadsEdges) {
  // Spine along x, 40 mm long, slightly tilted: 0.2 mm deeper at +x than at -x.
  const Capsule capsule{{-0.02, 0, 0}, {0.02, 0, 0}, 0.005};
  const double tilt = 0.2e-3 / 0.04;
  const Eigen::Matrix3d r = Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const auto points = gelContactPoints(capsule, at({0, 0, 0.005 - 0.5e-3}, r), kPad);
  ASSERT_EQ(points.size(), 2u);
  for (const GelContactPoint& p : points) {
    EXPECT_NEAR(std::abs(p.position.x()), kPad.half_width_m, 1e-9);
    // Depth along the spine: 0.5 mm at the centre, tilt * x more towards +x.
    EXPECT_NEAR(p.depth, 0.5e-3 + std::sin(tilt) * p.position.x(), 1e-8);
  }
}

TEST(GelContactTest, ABigHullIsSearchedFromItsDeepestVertexWithTheSameResult) {
  // A 2,000-vertex ball hull, pressed at poses over the pad and across its edge: the search from
  // the deepest vertex finds exactly the points of clipping every face.
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 2000; ++i) {  // a Fibonacci sphere of radius 8 mm
    const double z = 1 - (2 * i + 1) / 2000.0, r = std::sqrt(1 - z * z), a = i * 2.399963;
    points.push_back(0.008 * Eigen::Vector3d(r * std::cos(a), r * std::sin(a), z));
  }
  const ConvexPolytope ball = ConvexPolytope::hullOf(points);
  ASSERT_GT(ball.vertices.size(), 64u);
  ConvexPolytope every_face = ball;
  every_face.neighbours.clear();  // the face-by-face path
  const Eigen::Matrix3d tilt =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 0).normalized()).toRotationMatrix();
  for (const Eigen::Vector3d& centre :
       {Eigen::Vector3d(0, 0, 0.008 - 1e-3), Eigen::Vector3d(0.003, -0.002, 0.008 - 0.2e-3),
        Eigen::Vector3d(kPad.half_width_m + 0.002, 0, 0.008 - 1.5e-3),
        Eigen::Vector3d(0, 0, 0.008 + 1e-4)}) {
    const auto searched = gelContactPoints(ball, at(centre, tilt), kPad);
    const auto clipped = gelContactPoints(every_face, at(centre, tilt), kPad);
    ASSERT_EQ(searched.size(), clipped.size()) << centre.transpose();
    EXPECT_EQ(deepest(searched), deepest(clipped));
    for (const GelContactPoint& p : searched) {
      EXPECT_TRUE(std::any_of(clipped.begin(), clipped.end(), [&](const GelContactPoint& q) {
        return (q.position - p.position).norm() < 1e-9;
      }));
    }
  }
}

TEST(GelContactTest, SpanningPointsKeepTheDeepestAndTheWidestQuadrilateral) {
  std::vector<GelContactPoint> points;
  for (double x : {-2.0, -1.0, 0.0, 1.0, 2.0}) {
    for (double y : {-1.0, 0.0, 1.0}) {
      const double depth = 1e-3 + 1e-5 * (x == 1.0 && y == 0.0);  // one slightly deeper
      points.push_back({Eigen::Vector3d(x, y, -depth), depth});
    }
  }
  const auto kept = spanningContactPoints(points, 4);
  ASSERT_EQ(kept.size(), 4u);
  EXPECT_EQ(kept[0].position.head<2>(), Eigen::Vector2d(1, 0));
  // The farthest from it, then the two that span the most area on either side of that line.
  EXPECT_EQ(kept[1].position.x(), -2.0);
  EXPECT_NE(kept[2].position.y(), 0.0);
  EXPECT_EQ(kept[3].position.y(), -kept[2].position.y());
  EXPECT_EQ(spanningContactPoints(points, 1).size(), 1u);
  EXPECT_EQ(spanningContactPoints({points[0], points[1]}, 4).size(), 2u);
}

TEST(GelContactTest, HullDeviationIsTheDepthOfTheHollowsTheGelCanReach) {
  // A 20 x 10 x 10 mm block with a 3 mm deep, 4 mm wide notch in its +y face.
  std::vector<Eigen::Vector3d> mesh;
  for (double z : {-0.005, 0.005}) {
    for (const auto& [x, y] : {std::pair{-0.01, -0.005}, {0.01, -0.005}, {0.01, 0.005},
                               {0.002, 0.005}, {0.002, 0.002}, {-0.002, 0.002}, {-0.002, 0.005},
                               {-0.01, 0.005}}) {
      mesh.emplace_back(x, y, z);
    }
  }
  const ConvexPolytope hull = ConvexPolytope::hullOf(mesh);
  // The notch runs through the block: its corners lie on the hull's end faces.
  EXPECT_EQ(hullDeviation(hull, mesh), 0.0);
  // Seen along y: the notch is within a 4 mm reach of the +y face, beyond a 2 mm one.
  EXPECT_NEAR(hullDeviation(hull, mesh, Eigen::Vector3d::UnitY(), 0.004), 0.003, 1e-9);
  EXPECT_EQ(hullDeviation(hull, mesh, Eigen::Vector3d::UnitY(), 0.002), 0.0);
  EXPECT_NEAR(hullDeviation(cube(0.01), cube(0.01).vertices), 0.0, 1e-12);
}

}  // namespace
}  // namespace norm2tex
