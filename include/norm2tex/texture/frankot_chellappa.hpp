#pragma once

#include <memory>

#include <opencv2/core.hpp>

namespace norm2tex {

/// Boundary model of the Poisson solve.
enum class PoissonBoundary {
  /// The paper's formula verbatim: the patch's box is assumed periodic; FFT of the box at its own
  /// size, divide by lambda(u,v) = 2cos(2 pi u/W) + 2cos(2 pi v/H) - 4. Exact for periodic height
  /// fields; a field that does not tile leaks a seam across the patch, and texels of the box
  /// outside the island count as flat.
  kPeriodic,
  /// Least squares over the island's own edges and nothing else (the natural, Neumann boundary
  /// at the island's border), for convex and concave islands alike: conjugate gradients
  /// preconditioned by the cosine-transform Poisson solve of the island's box. Default.
  kNeumann,
};

struct IntegrationOptions {
  PoissonBoundary boundary = PoissonBoundary::kNeumann;
  /// kNeumann: conjugate gradients stop once the preconditioned residual norm sqrt(r.Mr) has
  /// fallen by this factor. At 1e-4 the height differs from the exact least-squares solution by
  /// 3e-5..1e-4 relative RMS on L, C, ring and holed islands (8-12 solves each).
  double tolerance = 1e-4;
  /// kNeumann: at most this many conjugate-gradient iterations (each one cosine-transform solve).
  int max_iterations = 300;
};

/// Throws Error when an option is out of range.
void validate(const IntegrationOptions& options);

/// How one integration went (kNeumann; kPeriodic reports 1 solve, residual 0).
struct IntegrationReport {
  int solves = 0;                ///< cosine/Fourier Poisson solves done
  double relative_residual = 0;  ///< final sqrt(r.Mr / b.Mb)
  bool converged = true;         ///< false when max_iterations ran out first
};

/// Least-squares integration of a gradient field over one island (Frankot-Chellappa).
///
/// Inputs are in height units per texel, image frame: dx = dh/dcolumn, dy = dh/drow, all of
/// the same size; `mask` (CV_8UC1, non-zero = island) selects the island inside the patch.
/// The discrete model is h[i][j+1] - h[i][j] = (dx[i][j] + dx[i][j+1]) / 2 on every edge
/// joining two island texels (likewise along rows). With kNeumann the result minimises the
/// squared misfit over exactly these edges: slopes outside the island, the shape of the island
/// and the padding of the transform to a fast size do not change it. The result has zero mean
/// over the island and is 0 outside it. Patches of any size work (odd, prime, 1 texel wide).
///
/// Keeps its scratch buffers between calls (a bake reuses one integrator for all islands);
/// one integrator must not be used from two threads at once.
class FrankotChellappaIntegrator {
 public:
  explicit FrankotChellappaIntegrator(const IntegrationOptions& options = {});
  ~FrankotChellappaIntegrator();
  FrankotChellappaIntegrator(FrankotChellappaIntegrator&&) noexcept;
  FrankotChellappaIntegrator& operator=(FrankotChellappaIntegrator&&) noexcept;

  /// Writes the height into `height` (reallocated unless it already has dx's size and type).
  /// `height` may be `dx` or `dy` itself: the slopes are read in full before it is written.
  /// Throws Error on empty or mismatched input.
  void integrate(const cv::Mat1f& dx, const cv::Mat1f& dy, const cv::Mat1b& mask, cv::Mat1f& height,
                 IntegrationReport* report = nullptr);

 private:
  struct Workspace;
  IntegrationOptions options_;
  std::unique_ptr<Workspace> workspace_;
};

/// One-off integration with a fresh integrator.
cv::Mat1f integrateFrankotChellappa(const cv::Mat1f& dx, const cv::Mat1f& dy, const cv::Mat1b& mask,
                                    const IntegrationOptions& options = {},
                                    IntegrationReport* report = nullptr);

}  // namespace norm2tex
