#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "norm2tex/texture/analytic_surface.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/texture/frankot_chellappa.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

IntegrationOptions withBoundary(PoissonBoundary boundary, int refinements = 2) {
  IntegrationOptions options;
  options.boundary = boundary;
  options.apron_refinements = refinements;
  return options;
}

TEST(FrankotChellappa, PeriodicSolverIsExactOnATilingField) {
  // Integer numbers of periods across 64 x 64: the paper's periodic model holds exactly.
  const cv::Size size(64, 64);
  const AnalyticSurface s = makeWaves(size, {{2.0, 16.0, 0.0, 0.3}, {1.0, 32.0, CV_PI / 2, 1.0}});
  const cv::Mat1b all(size, 255);
  const cv::Mat1f h =
      integrateFrankotChellappa(s.dx, s.dy, all, withBoundary(PoissonBoundary::kPeriodic));
  EXPECT_GT(test::correlation(h, s.height, all), 0.9999);
}

TEST(FrankotChellappa, MirrorSolverHandlesFieldsThatDoNotTile) {
  // A ramp plus a bump never tiles: the periodic model leaks a seam, the mirror one does not.
  const cv::Size size(96, 80);
  AnalyticSurface s = makeWaves(size, {{3.0, 500.0, 0.4, 0.0}});  // nearly a ramp
  s += makeBumps(size, {{{30, 50}, 7.0, 4.0}});
  const cv::Mat1b all(size, 255);
  const double mirror = test::correlation(
      integrateFrankotChellappa(s.dx, s.dy, all, withBoundary(PoissonBoundary::kMirror)), s.height,
      all);
  const double periodic = test::correlation(
      integrateFrankotChellappa(s.dx, s.dy, all, withBoundary(PoissonBoundary::kPeriodic)),
      s.height, all);
  EXPECT_GT(mirror, 0.999);
  EXPECT_LT(periodic, mirror);
}

TEST(FrankotChellappa, ResultHasZeroMeanOnTheIslandAndZeroOutside) {
  const cv::Size size(40, 30);
  const AnalyticSurface s = makeBumps(size, {{{20, 15}, 5.0, 3.0}});
  cv::Mat1b mask(size, uchar(0));
  mask(cv::Rect(5, 5, 25, 18)).setTo(255);
  cv::Mat1f h = integrateFrankotChellappa(s.dx, s.dy, mask);
  EXPECT_NEAR(cv::mean(h, mask)[0], 0.0, 1e-5);
  EXPECT_EQ(cv::countNonZero(h.setTo(0.0f, mask)), 0);  // nothing outside the island
}

TEST(FrankotChellappa, AnyPatchSizeWorks) {
  // Odd, prime, one texel wide or tall, and a single texel.
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(1, 37), cv::Size(41, 1), cv::Size(7, 13),
                              cv::Size(97, 101), cv::Size(2, 3), cv::Size(127, 64)}) {
    const AnalyticSurface s = makeWaves(size, {{1.0, 9.0, 0.6, 0.0}});
    const cv::Mat1b all(size, 255);
    for (const PoissonBoundary boundary : {PoissonBoundary::kMirror, PoissonBoundary::kPeriodic}) {
      const cv::Mat1f h = integrateFrankotChellappa(s.dx, s.dy, all, withBoundary(boundary));
      ASSERT_EQ(h.size(), size);
      ASSERT_TRUE(cv::checkRange(h)) << size;
      if (size.area() == 1) {
        EXPECT_EQ(h(0, 0), 0.0f);
      } else if (boundary == PoissonBoundary::kMirror) {
        EXPECT_GT(test::correlation(h, s.height, all), 0.99) << size;
      }
    }
  }
}

TEST(FrankotChellappa, OneTexelWideStripIsExactlyTheRunningSum) {
  // In 1-D the least-squares model is h[j+1] - h[j] = (d[j] + d[j+1]) / 2, nothing else.
  cv::Mat1f dx(1, 6), dy(1, 6, 0.0f);
  const float slopes[6] = {1, 2, 0, -1, 3, 0.5};
  for (int j = 0; j < 6; ++j) dx(0, j) = slopes[j];
  const cv::Mat1f h = integrateFrankotChellappa(dx, dy, cv::Mat1b(1, 6, uchar(255)));
  for (int j = 0; j + 1 < 6; ++j) {
    EXPECT_NEAR(h(0, j + 1) - h(0, j), 0.5 * (slopes[j] + slopes[j + 1]), 1e-4) << j;
  }
}

TEST(FrankotChellappa, IrregularIslandWithApronRefinementMatchesTruth) {
  // A disc inside its bounding box: the corners are apron. A tilted wave makes the island's
  // border heights vary, which a flat apron would fight.
  const cv::Size size(120, 100);
  AnalyticSurface s = makeWaves(size, {{4.0, 150.0, 0.5, 0.0}, {1.0, 23.0, 2.2, 0.0}});
  cv::Mat1b disc(size, uchar(0));
  cv::circle(disc, {60, 50}, 45, 255, cv::FILLED);
  const double flat = test::correlation(
      integrateFrankotChellappa(s.dx, s.dy, disc, withBoundary(PoissonBoundary::kMirror, 0)),
      s.height, disc);
  const double refined = test::correlation(
      integrateFrankotChellappa(s.dx, s.dy, disc, withBoundary(PoissonBoundary::kMirror, 2)),
      s.height, disc);
  EXPECT_GT(refined, 0.999);
  EXPECT_GE(refined, flat);
}

TEST(FrankotChellappa, ApronSlopesDoNotLeakIntoTheIsland) {
  // Garbage gradients outside the island must not change the result.
  const cv::Size size(50, 50);
  const AnalyticSurface s = makeBumps(size, {{{25, 25}, 6.0, 3.0}});
  cv::Mat1b mask(size, uchar(0));
  cv::circle(mask, {25, 25}, 18, 255, cv::FILLED);
  cv::Mat1f noisy_dx = s.dx.clone(), noisy_dy = s.dy.clone();
  cv::Mat1f noise(size);
  cv::randu(noise, -5.0f, 5.0f);
  noise.copyTo(noisy_dx, mask == 0);
  noise.copyTo(noisy_dy, mask == 0);
  const cv::Mat1f clean = integrateFrankotChellappa(s.dx, s.dy, mask);
  const cv::Mat1f noisy = integrateFrankotChellappa(noisy_dx, noisy_dy, mask);
  EXPECT_LT(cv::norm(clean, noisy, cv::NORM_INF), 1e-5);
}

TEST(FrankotChellappa, RejectsMismatchedInput) {
  EXPECT_THROW(integrateFrankotChellappa(cv::Mat1f(3, 3), cv::Mat1f(3, 4), cv::Mat1b(3, 3)), Error);
  EXPECT_THROW(integrateFrankotChellappa(cv::Mat1f(), cv::Mat1f(), cv::Mat1b()), Error);
  IntegrationOptions bad;
  bad.apron_refinements = -1;
  EXPECT_THROW(validate(bad), Error);
}

}  // namespace
}  // namespace norm2tex
