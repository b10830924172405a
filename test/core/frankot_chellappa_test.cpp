#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/texture/analytic_surface.hpp"
#include "norm2tex/texture/frankot_chellappa.hpp"
#include "norm2tex/texture/normal_map.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

IntegrationOptions periodic() {
  IntegrationOptions options;
  options.boundary = PoissonBoundary::kPeriodic;
  return options;
}

/// The exact least-squares height over the island's edges, by a sparse Cholesky solve of the
/// normal equations with one texel pinned to 0 (the constant is free), then zero island mean.
/// Same discrete model as the integrator: target (d[p] + d[q]) / 2 on every island edge.
cv::Mat1f exactLeastSquares(const cv::Mat1f& dx, const cv::Mat1f& dy, const cv::Mat1b& mask) {
  cv::Mat1i index(mask.size(), -1);
  int n = 0;
  for (int r = 0; r < mask.rows; ++r)
    for (int c = 0; c < mask.cols; ++c)
      if (mask(r, c)) index(r, c) = n++;
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
  const auto edge = [&](int p, int q, double target) {  // wants h[q] - h[p] = target
    entries.emplace_back(p, p, 1.0);
    entries.emplace_back(q, q, 1.0);
    entries.emplace_back(p, q, -1.0);
    entries.emplace_back(q, p, -1.0);
    b[p] -= target;
    b[q] += target;
  };
  for (int r = 0; r < mask.rows; ++r) {
    for (int c = 0; c < mask.cols; ++c) {
      if (index(r, c) < 0) continue;
      if (c + 1 < mask.cols && index(r, c + 1) >= 0)
        edge(index(r, c), index(r, c + 1), 0.5 * (dx(r, c) + dx(r, c + 1)));
      if (r + 1 < mask.rows && index(r + 1, c) >= 0)
        edge(index(r, c), index(r + 1, c), 0.5 * (dy(r, c) + dy(r + 1, c)));
    }
  }
  entries.emplace_back(0, 0, 1.0);  // pins texel 0: h[0] = 0 makes the system definite
  Eigen::SparseMatrix<double> a(n, n);
  a.setFromTriplets(entries.begin(), entries.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(a);
  const Eigen::VectorXd h = solver.solve(b);
  const double mean = h.mean();
  cv::Mat1f result(mask.size(), 0.0f);
  for (int r = 0; r < mask.rows; ++r)
    for (int c = 0; c < mask.cols; ++c)
      if (index(r, c) >= 0) result(r, c) = static_cast<float>(h[index(r, c)] - mean);
  return result;
}

double relativeRms(const cv::Mat1f& h, const cv::Mat1f& reference, const cv::Mat1b& mask) {
  cv::Mat1f difference = h - reference;
  return cv::norm(difference, cv::NORM_L2, mask) / cv::norm(reference, cv::NORM_L2, mask);
}

struct Island {
  const char* name;
  cv::Mat1b mask;
};

/// Concave islands of real unwraps, each inside a box that is not a fast transform size.
std::vector<Island> concaveIslands(cv::Size size) {
  std::vector<Island> islands;
  cv::Mat1b l(size, uchar(0));
  l(cv::Rect(2, 2, 30, size.height - 4)).setTo(255);
  l(cv::Rect(2, size.height - 32, size.width - 4, 30)).setTo(255);
  islands.push_back({"L", l});
  cv::Mat1b c(size, uchar(0));
  c(cv::Rect(2, 2, size.width - 4, size.height - 4)).setTo(255);
  c(cv::Rect(30, 26, size.width - 30, size.height - 52)).setTo(0);
  islands.push_back({"C", c});
  cv::Mat1b ring(size, uchar(0));
  cv::circle(ring, {size.width / 2, size.height / 2}, size.height / 2 - 3, 255, cv::FILLED);
  cv::circle(ring, {size.width / 2, size.height / 2}, size.height / 4, 0, cv::FILLED);
  islands.push_back({"ring", ring});
  cv::Mat1b hole(size, uchar(0));
  hole(cv::Rect(3, 4, size.width - 7, size.height - 9)).setTo(255);
  hole(cv::Rect(size.width / 3, size.height / 2, 17, 11)).setTo(0);
  islands.push_back({"hole", hole});
  return islands;
}

AnalyticSurface tiltedRelief(cv::Size size) {
  // A long tilt plus relief: the border heights vary a lot, which any leak through the
  // island's concave gaps would show.
  AnalyticSurface s = makeWaves(size, {{6.0, 170.0, 0.5, 0.0}, {1.0, 17.0, 2.2, 0.3}});
  s += makeBumps(size, {{{40, 60}, 7.0, 5.0}});
  return s;
}

TEST(FrankotChellappa, ConcaveIslandsMatchTheExactLeastSquaresSolve) {
  const cv::Size size(131, 117);
  const AnalyticSurface s = tiltedRelief(size);
  for (const Island& island : concaveIslands(size)) {
    IntegrationReport report;
    const cv::Mat1f h = integrateFrankotChellappa(s.dx, s.dy, island.mask, {}, &report);
    const cv::Mat1f exact = exactLeastSquares(s.dx, s.dy, island.mask);
    const double error = relativeRms(h, exact, island.mask);
    EXPECT_LT(error, 1e-3) << island.name;
    EXPECT_TRUE(report.converged) << island.name;
    testing::Test::RecordProperty(std::string(island.name) + "_relative_rms",
                                  std::to_string(error));
    EXPECT_LE(report.solves, 40) << island.name;
    testing::Test::RecordProperty(std::string(island.name) + "_solves", report.solves);
  }
}

TEST(FrankotChellappa, ConcaveIslandsOf16BitMapsCorrelateWithTruth) {
  const cv::Size size(131, 117);
  const AnalyticSurface s = tiltedRelief(size);
  for (const Island& island : concaveIslands(size)) {
    const NormalMap map = test::quantisedNormalMap(s, island.mask, CV_16U);
    cv::Mat1f dx, dy;
    normalsToGradients(map.normals(), map.valid(), 1e-3, dx, dy);
    const cv::Mat1f h = integrateFrankotChellappa(dx, dy, island.mask);
    EXPECT_GE(test::correlation(h, s.height, island.mask), 0.999) << island.name;
  }
}

TEST(FrankotChellappa, NonFastSizeWithNoisySlopesIsTheExactSolution) {
  // 97 x 101 is padded to a fast transform size; noisy slopes are not integrable, so the
  // least-squares solution is all there is to compare with.
  const cv::Size size(97, 101);
  AnalyticSurface s = makeWaves(size, {{2.0, 31.0, 0.7, 0.0}});
  cv::Mat1f noise(size);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 0.3);
  s.dx += noise;
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 0.3);
  s.dy += noise;
  const cv::Mat1b all(size, 255);
  const cv::Mat1f h = integrateFrankotChellappa(s.dx, s.dy, all);
  EXPECT_LT(relativeRms(h, exactLeastSquares(s.dx, s.dy, all), all), 1e-3);
  cv::Mat1b disc(size, uchar(0));
  cv::circle(disc, {48, 50}, 44, 255, cv::FILLED);
  EXPECT_LT(relativeRms(integrateFrankotChellappa(s.dx, s.dy, disc),
                        exactLeastSquares(s.dx, s.dy, disc), disc),
            1e-3);
}

TEST(FrankotChellappa, FullBoxOfTransformSizeIsOneDirectSolve) {
  const cv::Size size(64, 48);
  AnalyticSurface s = tiltedRelief(size);
  const cv::Mat1b all(size, 255);
  IntegrationReport report;
  const cv::Mat1f h = integrateFrankotChellappa(s.dx, s.dy, all, {}, &report);
  EXPECT_EQ(report.solves, 1);
  EXPECT_LT(relativeRms(h, exactLeastSquares(s.dx, s.dy, all), all), 1e-4);
}

/// Largest |A h - b| relative to the largest |b|: A the graph Laplacian of the island's edges,
/// b = -div of the edge targets. Zero for the exact least-squares solution (its normal
/// equations), without a sparse solve (too slow at 540^2).
double normalEquationResidual(const cv::Mat1f& dx, const cv::Mat1f& dy, const cv::Mat1b& mask,
                              const cv::Mat1f& h) {
  cv::Mat1d residual(mask.size(), 0.0), b(mask.size(), 0.0);
  const auto edge = [&](cv::Point p, cv::Point q, double target) {  // wants h[q] - h[p] = target
    const double misfit = static_cast<double>(h(p)) - h(q);
    residual(p) += misfit + target;
    residual(q) -= misfit + target;
    b(p) -= target;
    b(q) += target;
  };
  for (int r = 0; r < mask.rows; ++r) {
    for (int c = 0; c < mask.cols; ++c) {
      if (!mask(r, c)) continue;
      if (c + 1 < mask.cols && mask(r, c + 1))
        edge({c, r}, {c + 1, r}, 0.5 * (dx(r, c) + dx(r, c + 1)));
      if (r + 1 < mask.rows && mask(r + 1, c))
        edge({c, r}, {c, r + 1}, 0.5 * (dy(r, c) + dy(r + 1, c)));
    }
  }
  return cv::norm(residual, cv::NORM_INF) / cv::norm(b, cv::NORM_INF);
}

TEST(FrankotChellappa, SquareAndOblongBoxesAreTheExactSolution) {
  // The cosine transform works in place. Square boxes of 512 and more are transposed in place
  // in 32-texel tiles (540 is not a multiple of the tile), smaller and oblong ones through a
  // second buffer. Full boxes take the direct solve; a disc in the box the iteration.
  for (const cv::Size size : {cv::Size(96, 96), cv::Size(64, 48), cv::Size(48, 64),
                              cv::Size(512, 512), cv::Size(540, 540)}) {
    const bool large = size.width >= 512;
    const AnalyticSurface s = tiltedRelief(size);
    const cv::Mat1b all(size, 255);
    IntegrationReport report;
    const cv::Mat1f full = integrateFrankotChellappa(s.dx, s.dy, all, {}, &report);
    EXPECT_EQ(report.solves, 1) << size;
    EXPECT_LT(normalEquationResidual(s.dx, s.dy, all, full), 1e-3) << size;
    if (!large) {
      EXPECT_LT(relativeRms(full, exactLeastSquares(s.dx, s.dy, all), all), 1e-4) << size;
    }
    cv::Mat1b disc(size, uchar(0));
    cv::ellipse(disc, {size.width / 2, size.height / 2}, {size.width / 2 - 3, size.height / 2 - 3},
                0, 0, 360, 255, cv::FILLED);
    const cv::Mat1f h = integrateFrankotChellappa(s.dx, s.dy, disc, {}, &report);
    EXPECT_GT(report.solves, 1) << size;
    EXPECT_TRUE(report.converged) << size;
    if (!large) {
      EXPECT_LT(relativeRms(h, exactLeastSquares(s.dx, s.dy, disc), disc), 1e-3) << size;
    }
  }
}

TEST(FrankotChellappa, PeriodicSolverIsExactOnATilingFieldOfAnySize) {
  // Whole periods across odd and prime sizes: no padding may break the tiling.
  for (const cv::Size size : {cv::Size(64, 64), cv::Size(97, 101), cv::Size(45, 27)}) {
    const AnalyticSurface s = makeWaves(
        size, {{2.0, size.width / 3.0, 0.0, 0.3}, {1.0, size.height / 2.0, CV_PI / 2, 1.0}});
    const cv::Mat1b all(size, 255);
    const cv::Mat1f h = integrateFrankotChellappa(s.dx, s.dy, all, periodic());
    EXPECT_GT(test::correlation(h, s.height, all), 0.9999) << size;
  }
}

TEST(FrankotChellappa, PeriodicSolutionSatisfiesThePeriodicPoissonEquation) {
  // Any patch size, including 1-texel strips: the discrete periodic Laplacian of the result
  // equals the periodic divergence of the edge targets wherever the equation is defined.
  for (const cv::Size size : {cv::Size(1, 37), cv::Size(41, 1), cv::Size(7, 13), cv::Size(97, 101),
                              cv::Size(2, 3), cv::Size(127, 64)}) {
    const AnalyticSurface s = makeWaves(size, {{1.0, 9.0, 0.6, 0.0}});
    const cv::Mat1b all(size, 255);
    const cv::Mat1f h = integrateFrankotChellappa(s.dx, s.dy, all, periodic());
    ASSERT_EQ(h.size(), size);
    double worst = 0.0, scale = 0.0;
    const int rows = size.height, cols = size.width;
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        const int cp = (c + 1) % cols, cm = (c + cols - 1) % cols;
        const int rp = (r + 1) % rows, rm = (r + rows - 1) % rows;
        const double laplace = h(r, cp) + h(r, cm) + h(rp, c) + h(rm, c) - 4.0 * h(r, c);
        const double gx = 0.5 * (s.dx(r, c) + s.dx(r, cp)),
                     gx_left = 0.5 * (s.dx(r, cm) + s.dx(r, c));
        const double gy = 0.5 * (s.dy(r, c) + s.dy(rp, c)),
                     gy_up = 0.5 * (s.dy(rm, c) + s.dy(r, c));
        const double div = gx - gx_left + gy - gy_up;
        scale = std::max(scale, std::fabs(div));
        worst = std::max(worst, std::fabs(laplace - div));
      }
    }
    // The constant mode of div is dropped (H(0,0) = 0): compare against its mean.
    EXPECT_LT(worst, 1e-3 * std::max(scale, 1.0) + 1e-4) << size;
    EXPECT_NEAR(cv::mean(h)[0], 0.0, 1e-5) << size;
  }
}

TEST(FrankotChellappa, AnyPatchSizeIsTheExactSolution) {
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(1, 37), cv::Size(41, 1), cv::Size(7, 13),
                              cv::Size(2, 3), cv::Size(127, 64)}) {
    const AnalyticSurface s = makeWaves(size, {{1.0, 9.0, 0.6, 0.0}});
    const cv::Mat1b all(size, 255);
    const cv::Mat1f h = integrateFrankotChellappa(s.dx, s.dy, all);
    ASSERT_EQ(h.size(), size);
    if (size.area() == 1) {
      EXPECT_EQ(h(0, 0), 0.0f);
      continue;
    }
    EXPECT_LT(relativeRms(h, exactLeastSquares(s.dx, s.dy, all), all), 1e-3) << size;
  }
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

TEST(FrankotChellappa, SlopesOutsideTheIslandDoNotChangeIt) {
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

TEST(FrankotChellappa, ReusedIntegratorGivesTheSameBitsAsAFreshOne) {
  // Scratch buffers carry nothing from one island to the next.
  const cv::Size size(131, 117);
  const AnalyticSurface s = tiltedRelief(size);
  FrankotChellappaIntegrator reused;
  cv::Mat1f h;
  for (const Island& island : concaveIslands(size)) {
    reused.integrate(s.dx, s.dy, island.mask, h);
    const cv::Mat1f fresh = integrateFrankotChellappa(s.dx, s.dy, island.mask);
    EXPECT_EQ(cv::norm(h, fresh, cv::NORM_INF), 0.0) << island.name;
    // The height may be written over the slopes (the bake does, to save a buffer).
    cv::Mat1f in_place = s.dx.clone();
    reused.integrate(in_place, s.dy, island.mask, in_place);
    EXPECT_EQ(cv::norm(in_place, fresh, cv::NORM_INF), 0.0) << island.name << " in place";
    cv::Mat1f over_dy = s.dy.clone();
    reused.integrate(s.dx, over_dy, island.mask, over_dy);
    EXPECT_EQ(cv::norm(over_dy, fresh, cv::NORM_INF), 0.0) << island.name << " over dy";
  }
}

TEST(FrankotChellappa, RejectsMismatchedInput) {
  EXPECT_THROW(integrateFrankotChellappa(cv::Mat1f(3, 3), cv::Mat1f(3, 4), cv::Mat1b(3, 3)), Error);
  EXPECT_THROW(integrateFrankotChellappa(cv::Mat1f(), cv::Mat1f(), cv::Mat1b()), Error);
  IntegrationOptions bad;
  bad.max_iterations = 0;
  EXPECT_THROW(validate(bad), Error);
  bad = IntegrationOptions();
  bad.tolerance = 0.0;
  EXPECT_THROW(validate(bad), Error);
}

}  // namespace
}  // namespace norm2tex
