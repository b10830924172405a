#pragma once
// Shared helpers of the core tests: statistics against analytic truth and scratch directories.

#include <exception>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "norm2tex/texture/analytic_surface.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/mesh/textured_mesh.hpp"
#include "norm2tex/texture/normal_map.hpp"

namespace norm2tex {
namespace test {

/// Pearson correlation of a and b over the texels where mask != 0.
double correlation(const cv::Mat1f& a, const cv::Mat1f& b, const cv::Mat1b& mask);

/// The surface's height minus the plane of its mean slope over `mask`: what a bake with
/// remove_mean_slope reconstructs (up to scale and offset).
cv::Mat1f withoutMeanSlope(const AnalyticSurface& surface, const cv::Mat1b& mask);

/// Standard deviation of a over the texels where mask != 0.
double maskedStdDev(const cv::Mat1f& a, const cv::Mat1b& mask);

/// Encodes a surface's exact gradients at `depth` (CV_8U / CV_16U) and decodes the image
/// again, the way a normal map file would arrive.
NormalMap quantisedNormalMap(const AnalyticSurface& surface, const cv::Mat1b& mask, int depth,
                             NormalConvention convention = NormalConvention::kOpenGL);

/// A ramp winding 1.5 turns around z (radii 5 and 10 mm, 1 mm rise, 90 steps of two triangles):
/// every face looks up (one class, one component), but its projection onto the ground plane
/// covers itself, so unwrapUvs must cut it.
TexturedMesh makeHelicoidRamp();

/// Expects `code` to throw norm2tex::Error with a one-line message containing every one of
/// `parts` (a file name, a parameter, the valid choices...).
template <typename F>
void expectError(F code, const std::vector<std::string>& parts) {
  try {
    code();
    ADD_FAILURE() << "no Error thrown; expected one mentioning " << parts.front();
  } catch (const Error& e) {
    const std::string message = e.what();
    for (const std::string& part : parts) {
      EXPECT_NE(message.find(part), std::string::npos)
          << "message '" << message << "' lacks '" << part << "'";
    }
    EXPECT_EQ(message.find('\n'), std::string::npos) << "multi-line message: " << message;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "threw a non-Error exception: " << e.what();
  }
}

/// A fresh directory under the system temp dir, removed with its content on destruction.
class ScratchDirectory {
 public:
  ScratchDirectory();
  ~ScratchDirectory();
  ScratchDirectory(const ScratchDirectory&) = delete;
  ScratchDirectory& operator=(const ScratchDirectory&) = delete;
  std::string path(const std::string& name) const;
  const std::string& root() const { return root_; }

 private:
  std::string root_;
};

}  // namespace test
}  // namespace norm2tex
