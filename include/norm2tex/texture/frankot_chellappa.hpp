#pragma once

#include <opencv2/core.hpp>

namespace norm2tex {

/// Boundary model of the Fourier-domain Poisson solve.
enum class PoissonBoundary {
  /// The paper's formula verbatim: the patch is assumed periodic; FFT, divide by
  /// lambda(u,v) = 2cos(2 pi u/W) + 2cos(2 pi v/H) - 4. Exact for periodic height fields, but a
  /// height field that does not tile leaks a seam across the patch.
  kPeriodic,
  /// The same periodic solve applied to the patch's mirror-symmetric extension (2W x 2H),
  /// which always tiles: the discrete cosine transform computes exactly this, 4x cheaper,
  /// with lambda(u,v) = 2cos(pi u/W) + 2cos(pi v/H) - 4 (Neumann boundary). Default.
  kMirror,
};

struct IntegrationOptions {
  PoissonBoundary boundary = PoissonBoundary::kMirror;
  /// Texels of the bounding box outside the island (the "apron") carry no data. The first
  /// solve gives them zero slope (a flat apron); each refinement re-solves with the apron's
  /// slopes taken from the previous solution, which removes the apron's pull on the island
  /// (fixed-point iteration towards the least-squares solution over island edges only).
  int apron_refinements = 2;
};

/// Throws Error when an option is out of range.
void validate(const IntegrationOptions& options);

/// Least-squares integration of a gradient field over one island (Frankot-Chellappa).
///
/// Inputs are in height units per texel, image frame: dx = dh/dcolumn, dy = dh/drow, all of
/// the same size; `mask` (CV_8UC1, non-zero = island) selects the island inside the patch.
/// The discrete model is h[i][j+1] - h[i][j] = (dx[i][j] + dx[i][j+1]) / 2 on every edge
/// joining two island texels (likewise along rows); its normal equations are the 5-point
/// Poisson equation Laplace(h) = div(d), solved in the Fourier (periodic) or cosine (mirror)
/// domain with H(0,0) = 0. The result has zero mean over the island and is 0 outside it.
/// Patches of any size work (odd, prime, 1 texel wide): the transform size is padded to a fast
/// (and, for the cosine transform, even) length by continuing the last row and column flat, which
/// leaves the solution on the patch unchanged.
cv::Mat1f integrateFrankotChellappa(const cv::Mat1f& dx, const cv::Mat1f& dy, const cv::Mat1b& mask,
                                    const IntegrationOptions& options = {});

}  // namespace norm2tex
