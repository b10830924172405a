#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace norm2tex {

/// A height field with its exact gradients, all in texel units and the image frame
/// (dx = dh/dcolumn, dy = dh/drow). Ground truth for tests of the bake, and the source of the
/// benchmark and demo normal maps (encode it with encodeNormalMap).
struct AnalyticSurface {
  cv::Mat1f height, dx, dy;
  AnalyticSurface& operator+=(const AnalyticSurface& other);
};

/// h = amplitude * sin(2 pi (x cos(angle) + y sin(angle)) / wavelength + phase).
struct Wave {
  double amplitude = 1.0;  ///< texels
  double wavelength = 32;  ///< texels
  double angle = 0.0;      ///< radians, 0 = varies along columns
  double phase = 0.0;      ///< radians
};
AnalyticSurface makeWaves(cv::Size size, const std::vector<Wave>& waves);

/// h = amplitude * exp(-|p - centre|^2 / (2 sigma^2)).
struct Bump {
  cv::Point2d centre;      ///< (column, row), texels
  double sigma = 8.0;      ///< texels
  double amplitude = 4.0;  ///< texels (negative: a dimple)
};
AnalyticSurface makeBumps(cv::Size size, const std::vector<Bump>& bumps);

/// Parallel ridges of Gaussian profile: h = amplitude * exp(-t^2 / (2 width^2)) with t the
/// distance to the nearest ridge line. Keep width <= spacing / 8 so neighbours do not overlap.
struct Ridges {
  double angle = 0.0;      ///< radians; direction across the ridges
  double spacing = 24.0;   ///< texels between ridge lines
  double width = 2.5;      ///< texels
  double amplitude = 2.0;  ///< texels
};
AnalyticSurface makeRidges(cv::Size size, const Ridges& ridges);

/// A UV-atlas-like mask: a grid of cells_per_side^2 cells, each holding one island separated
/// from its neighbours by at least `gap` texels. Shapes cycle through rectangle, disc
/// and triangle (irregular = true) so islands have irregular borders. Labels follow row-major cell
/// order.
cv::Mat1b makeIslandMask(cv::Size size, int cells_per_side, int gap, bool irregular = true);

}  // namespace norm2tex
