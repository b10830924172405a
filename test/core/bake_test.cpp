#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/texture/analytic_surface.hpp"
#include "norm2tex/texture/frankot_chellappa.hpp"
#include "norm2tex/texture/height_atlas_baker.hpp"
#include "norm2tex/texture/normal_encoding.hpp"
#include "norm2tex/texture/uv_islands.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

// Minimum per-island correlation of H_global with the true height. Thresholds are what the
// bake reaches with the paper's defaults (smoothing included), with a small margin.
struct Case {
  const char* name;
  int depth;
  double min_correlation;
};

/// The paper's defaults without the relief high-pass: what integration against the analytic
/// truth measures (the truths here have relief at wavelengths near the default cutoff).
BakeOptions withoutReliefFilter() {
  BakeOptions options;
  options.relief_cutoff_texels = 0.0;
  return options;
}

AnalyticSurface mixedSurface(cv::Size size) {
  AnalyticSurface s = makeWaves(size, {{2.0, 45.0, 0.3, 0.0}, {0.8, 19.0, 2.1, 1.0}});
  s += makeBumps(size, {{{70, 60}, 10.0, 8.0}, {{190, 170}, 14.0, -6.0}});
  s += makeRidges(size, {1.1, 31.0, 2.5, 1.5});
  return s;
}

void expectIslandsMatchTruth(const AnalyticSurface& truth, const cv::Mat1b& mask, int depth,
                             double min_correlation, const std::string& what) {
  const NormalMap map = test::quantisedNormalMap(truth, mask, depth);
  BakeReport report;
  const HeightAtlas atlas = bakeHeightAtlas(map, withoutReliefFilter(), {}, &report);
  const UvIslands islands = findUvIslands(mask);
  ASSERT_EQ(report.island_count, static_cast<int>(islands.islands.size())) << what;
  double worst = 1.0;
  for (const UvIsland& island : islands.islands) {
    const cv::Mat1b island_mask = islands.labels == island.label;
    const cv::Mat1f expected = test::withoutMeanSlope(truth, island_mask);
    worst = std::min(worst, test::correlation(atlas.heights(), expected, island_mask));
  }
  EXPECT_GT(worst, min_correlation) << what << " (" << (depth == CV_8U ? 8 : 16) << "-bit)";
  testing::Test::RecordProperty(what + (depth == CV_8U ? "_8bit" : "_16bit"),
                                std::to_string(worst));
}

TEST(Bake, SingleIslandMatchesAnalyticTruth) {
  const cv::Size size(256, 224);
  const cv::Mat1b all(size, 255);
  for (const Case& c : {Case{"waves", CV_16U, 0.995}, Case{"waves", CV_8U, 0.99}}) {
    expectIslandsMatchTruth(makeWaves(size, {{2.0, 40.0, 0.3, 0.0}, {1.0, 23.0, 1.8, 0.0}}), all,
                            c.depth, c.min_correlation, c.name);
  }
  for (const Case& c : {Case{"bumps", CV_16U, 0.995}, Case{"bumps", CV_8U, 0.99}}) {
    expectIslandsMatchTruth(makeBumps(size, {{{60, 80}, 12, 9}, {{180, 120}, 20, -7}}), all,
                            c.depth, c.min_correlation, c.name);
  }
  for (const Case& c : {Case{"ridges", CV_16U, 0.99}, Case{"ridges", CV_8U, 0.98}}) {
    expectIslandsMatchTruth(makeRidges(size, {0.6, 28.0, 3.0, 2.0}), all, c.depth,
                            c.min_correlation, c.name);
  }
}

TEST(Bake, SeveralIrregularIslandsEachMatchTruth) {
  const cv::Size size(256, 256);
  const cv::Mat1b mask = makeIslandMask(size, 3, 6);  // rectangles, discs, triangles
  ASSERT_EQ(findUvIslands(mask).islands.size(), 9u);
  expectIslandsMatchTruth(mixedSurface(size), mask, CV_16U, 0.99, "mixed_islands");
  expectIslandsMatchTruth(mixedSurface(size), mask, CV_8U, 0.98, "mixed_islands");
}

TEST(Bake, IslandsDoNotBleedIntoEachOther) {
  // Left island: strong bumps. Right island, 2 texels away: perfectly flat.
  const cv::Size size(128, 64);
  const AnalyticSurface bumpy = makeBumps(size, {{{40, 32}, 6, 12}, {{58, 20}, 4, -8}});
  cv::Mat1b left(size, uchar(0)), right(size, uchar(0));
  left(cv::Rect(0, 0, 63, 64)).setTo(255);
  right(cv::Rect(65, 0, 63, 64)).setTo(255);
  AnalyticSurface truth = bumpy;
  truth.dx.setTo(0.0f, right);
  truth.dy.setTo(0.0f, right);
  const cv::Mat1b both = left | right;
  const HeightAtlas atlas = bakeHeightAtlas(test::quantisedNormalMap(truth, both, CV_16U));
  EXPECT_EQ(atlas.islandCount(), 2);
  EXPECT_GT(test::maskedStdDev(atlas.heights(), left), 0.1);
  EXPECT_LT(test::maskedStdDev(atlas.heights(), right), 1e-3) << "flat island picked up relief";
}

TEST(Bake, OutputRespectsRangeAndMask) {
  const cv::Size size(96, 96);
  const cv::Mat1b mask = makeIslandMask(size, 2, 4);
  const NormalMap map = test::quantisedNormalMap(mixedSurface(size), mask, CV_16U);
  for (const HeightRange range :
       {HeightRange::kRemove, HeightRange::kSymmetric, HeightRange::kAdd}) {
    BakeOptions options;
    options.range = range;
    const HeightAtlas atlas = bakeHeightAtlas(map, options);
    double low, high;
    cv::minMaxLoc(atlas.heights(), &low, &high, nullptr, nullptr, mask);
    const cv::Vec2f bounds = rangeBounds(range);
    EXPECT_FLOAT_EQ(low, bounds[0]) << toString(range);
    EXPECT_FLOAT_EQ(high, bounds[1]) << toString(range);
    cv::Mat1f outside = atlas.heights().clone();
    outside.setTo(0.0f, mask);
    EXPECT_EQ(cv::countNonZero(outside), 0) << "outside islands is 0";
    EXPECT_EQ(cv::countNonZero(atlas.valid() != mask), 0);
  }
}

TEST(Bake, FlatNormalMapGivesAFlatAtlas) {
  // 8-bit "flat" is (128, 128, 255): a +0.004 slope per texel after decoding, i.e. a tilt.
  for (const cv::Mat& image : {cv::Mat(32, 48, CV_8UC3, cv::Scalar(255, 128, 128)),
                               cv::Mat(32, 48, CV_16UC3, cv::Scalar(65535, 32768, 32768)),
                               cv::Mat(32, 48, CV_32FC3, cv::Scalar(1.0, 0.5, 0.5))}) {
    const HeightAtlas atlas = bakeHeightAtlas(NormalMap::fromImage(image));
    EXPECT_TRUE(cv::checkRange(atlas.heights()));
    EXPECT_EQ(cv::countNonZero(atlas.heights()), 0) << "depth " << image.depth();
  }
}

TEST(Bake, MeanSlopeRemovalIsAnOption) {
  // A tilted plane plus a bump: by default only the bump remains; without removal the tilt is
  // integrated too and dominates.
  const cv::Size size(128, 96);
  AnalyticSurface truth = makeBumps(size, {{{64, 48}, 8, 3}});
  truth += makeWaves(size, {{20.0, 2000.0, 0.0, 0.0}});  // slope ~0.06 per texel: a tilt
  const cv::Mat1b all(size, 255);
  const NormalMap map = test::quantisedNormalMap(truth, all, CV_16U);
  const AnalyticSurface bump_only = makeBumps(size, {{{64, 48}, 8, 3}});
  EXPECT_GT(test::correlation(bakeHeightAtlas(map, withoutReliefFilter()).heights(),
                              bump_only.height, all),
            0.99);
  BakeOptions keep_tilt = withoutReliefFilter();
  keep_tilt.remove_mean_slope = false;
  const cv::Mat1f tilted = bakeHeightAtlas(map, keep_tilt).heights();
  EXPECT_GT(test::correlation(tilted, truth.height, all), 0.995);
  EXPECT_LT(test::correlation(tilted, bump_only.height, all), 0.5);
}

TEST(Bake, IsDeterministic) {
  const cv::Size size(80, 72);
  const NormalMap map =
      test::quantisedNormalMap(mixedSurface(size), makeIslandMask(size, 2, 4), CV_8U);
  const HeightAtlas a = bakeHeightAtlas(map), b = bakeHeightAtlas(map);
  EXPECT_EQ(cv::norm(a.heights(), b.heights(), cv::NORM_INF), 0.0);
}

TEST(Bake, ConventionSettingMattersAndMatches) {
  // The same relief stored as DirectX bakes like the OpenGL map; read with the wrong
  // convention, the y slopes flip and the result no longer matches.
  const cv::Size size(128, 128);
  const AnalyticSurface truth = mixedSurface(size);
  const cv::Mat1b all(size, 255);
  const HeightAtlas gl =
      bakeHeightAtlas(test::quantisedNormalMap(truth, all, CV_16U, NormalConvention::kOpenGL),
                      withoutReliefFilter());
  const cv::Mat dx_image = encodeNormalMap(truth.dx, truth.dy, NormalConvention::kDirectX, CV_16U);
  BakeOptions dx_options = withoutReliefFilter();
  dx_options.normal_map.convention = NormalConvention::kDirectX;
  const HeightAtlas dx =
      bakeHeightAtlas(NormalMap::fromImage(dx_image, dx_options.normal_map), dx_options);
  const HeightAtlas wrong = bakeHeightAtlas(NormalMap::fromImage(dx_image), withoutReliefFilter());
  EXPECT_GT(test::correlation(gl.heights(), dx.heights(), all), 0.9999);
  const cv::Mat1f expected = test::withoutMeanSlope(truth, all);
  EXPECT_GT(test::correlation(gl.heights(), expected, all), 0.99);
  EXPECT_LT(test::correlation(wrong.heights(), expected, all), 0.9);
}

/// Amplitude of the known zero-mean pattern `relief` in `height`, by least squares over `mask`,
/// relative to the height's range (max - min over the mask).
double reliefAmplitudeRelativeToRange(const cv::Mat1f& height, const cv::Mat1f& relief,
                                      const cv::Mat1b& mask) {
  const double mean = cv::mean(height, mask)[0];
  double dot = 0.0, norm = 0.0;
  for (int r = 0; r < height.rows; ++r) {
    for (int c = 0; c < height.cols; ++c) {
      if (!mask(r, c)) continue;
      dot += (height(r, c) - mean) * relief(r, c);
      norm += relief(r, c) * relief(r, c);
    }
  }
  double low, high;
  cv::minMaxLoc(height, &low, &high, nullptr, nullptr, mask);
  return dot / norm / (high - low);
}

TEST(Bake, FineReliefSurvivesLargeDrift) {
  // A real normal map's integral: fine relief (8-texel bumps) under drift 30x its amplitude
  // at wavelengths of hundreds of texels.
  const cv::Size size(384, 320);
  const AnalyticSurface fine = makeWaves(size, {{0.5, 8.0, 0.4, 0.0}, {0.5, 11.0, 2.0, 0.7}});
  // (AnalyticSurface copies share their matrices: build the sum from a fresh surface.)
  AnalyticSurface drifting = makeWaves(size, {{15.0, 700.0, 0.3, 1.0}, {10.0, 450.0, 1.9, 0.2}});
  drifting += fine;
  const cv::Mat1b all(size, 255);
  const cv::Mat1f pattern = fine.height - cv::mean(fine.height)[0];
  const auto amplitude = [&](const AnalyticSurface& surface, const BakeOptions& options) {
    const HeightAtlas atlas =
        bakeHeightAtlas(test::quantisedNormalMap(surface, all, CV_16U), options);
    return reliefAmplitudeRelativeToRange(atlas.heights(), pattern, all);
  };
  const double alone = amplitude(fine, {});
  const double with_drift = amplitude(drifting, {});
  EXPECT_GE(with_drift, 0.8 * alone) << "the default bake keeps the relief";
  const double paper = amplitude(drifting, paperExactBakeOptions());
  EXPECT_LT(paper, 0.2 * alone) << "the paper's bake spends the range on the drift";
  testing::Test::RecordProperty("relief_kept_default", std::to_string(with_drift / alone));
  testing::Test::RecordProperty("relief_kept_paper", std::to_string(paper / alone));

  // The same on a ring-shaped island (the low-pass normalised by the island's own weights).
  cv::Mat1b ring(size, uchar(0));
  cv::circle(ring, {190, 160}, 150, 255, cv::FILLED);
  cv::circle(ring, {190, 160}, 50, 0, cv::FILLED);
  const auto island_amplitude = [&](const AnalyticSurface& surface) {
    const HeightAtlas atlas = bakeHeightAtlas(test::quantisedNormalMap(surface, ring, CV_16U));
    return reliefAmplitudeRelativeToRange(atlas.heights(), pattern, ring);
  };
  const double ring_kept = island_amplitude(drifting) / island_amplitude(fine);
  EXPECT_GE(ring_kept, 0.8);
  testing::Test::RecordProperty("relief_kept_ring", std::to_string(ring_kept));
}

TEST(Bake, OneSolveOfTheBlendedSlopesIsTheBlendOfTwoSolves) {
  // Integration is linear, so integrating (1 - alpha) g_fine + alpha g_coarse once equals
  // (1 - alpha) H_fine + alpha H_coarse. Heights compared unscaled by percentiles (physical
  // scale, range -1,1: only multiplied by mm per texel).
  const cv::Size size(128, 128);
  for (const bool irregular : {false, true}) {
    const cv::Mat1b mask = irregular ? makeIslandMask(size, 2, 4) : cv::Mat1b(size, 255);
    const NormalMap map = test::quantisedNormalMap(mixedSurface(size), mask, CV_16U);
    const auto heights = [&](double alpha) {
      BakeOptions options;
      options.alpha = alpha;
      options.mm_per_texel = 0.05;
      options.physical_scale = true;
      options.integration.tolerance = 1e-6;  // the iteration's error below the 1e-5 compared
      options.integration.max_iterations = 2000;
      return cv::Mat1f(bakeHeightAtlas(map, options).heights());
    };
    const cv::Mat1f fine = heights(0.0), coarse = heights(1.0), blended = heights(0.2);
    const cv::Mat1f two_solves = 0.8f * fine + 0.2f * coarse;
    double low, high;
    cv::minMaxLoc(blended, &low, &high, nullptr, nullptr, map.valid());
    const double difference = cv::norm(blended, two_solves, cv::NORM_INF, map.valid());
    EXPECT_LT(difference / (high - low), 1e-5) << (irregular ? "irregular islands" : "one island");
    EXPECT_GT(cv::norm(fine, coarse, cv::NORM_INF, map.valid()) / (high - low), 1e-2)
        << "the passes differ, so the blend is tested";
  }
}

TEST(Bake, PhysicalScaleGivesMillimetresAndReportsTheAmplitude) {
  // Slopes are dh/dx: a wave of amplitude 2 texels at 0.05 mm per texel is 0.1 mm high.
  const cv::Size size(128, 128);
  const AnalyticSurface s = makeWaves(size, {{2.0, 16.0, 0.0, 0.0}});
  const cv::Mat1b all(size, 255);
  BakeOptions options;
  options.mm_per_texel = 0.05;
  options.physical_scale = true;
  BakeReport report;
  const HeightAtlas atlas =
      bakeHeightAtlas(test::quantisedNormalMap(s, all, CV_16U), options, {}, &report);
  double low, high;
  cv::minMaxLoc(atlas.heights(), &low, &high);
  EXPECT_NEAR(high - low, 0.2, 0.01) << "peak to valley, mm";
  EXPECT_NEAR(report.relief_amplitude_mm, 0.2, 0.01);
  EXPECT_NEAR(report.relief_cutoff_texels, 2.0 / 0.05, 1e-9) << "2 mm cutoff in texels";
  BakeOptions no_scale;
  no_scale.physical_scale = true;
  test::expectError([&] { validate(no_scale); }, {"physical_scale", "mm_per_texel"});
}

TEST(Bake, ReportsProgressUpToOne) {
  const cv::Size size(64, 64);
  const NormalMap map =
      test::quantisedNormalMap(mixedSurface(size), makeIslandMask(size, 2, 4), CV_8U);
  std::vector<double> fractions;
  bakeHeightAtlas(map, {}, [&](double f) { fractions.push_back(f); });
  ASSERT_EQ(fractions.size(), 4u);
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
  EXPECT_DOUBLE_EQ(fractions.back(), 1.0);
}

TEST(BakeErrors, AllInvalidMaskIsAClearError) {
  const cv::Mat image(16, 16, CV_8UC4, cv::Scalar(255, 128, 128, 0));
  try {
    bakeHeightAtlas(NormalMap::fromImage(image));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no valid texel"), std::string::npos) << e.what();
  }
}

TEST(BakeErrors, OptionsOutOfRangeNameTheParameter) {
  const auto expectRejected = [](BakeOptions options, const std::string& name) {
    try {
      validate(options);
      ADD_FAILURE() << name << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  };
  BakeOptions o;
  o.alpha = 1.5;
  expectRejected(o, "alpha");
  o = {};
  o.sigma_fine = -1;
  expectRejected(o, "sigma_fine");
  o = {};
  o.sigma_coarse = std::nan("");
  expectRejected(o, "sigma_coarse");
  o = {};
  o.percentile_low = 60;
  expectRejected(o, "percentile_low");
  o = {};
  o.percentile_high = 101;
  expectRejected(o, "percentile_high");
  EXPECT_NO_THROW(validate(BakeOptions{}));
}

}  // namespace
}  // namespace norm2tex
