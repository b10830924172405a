#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/calibrate/shading_fit.hpp"

namespace norm2tex {

/// How a simulated set of presses compares with the real one, with the measures real DIGIT
/// captures were characterised by (reference/digit_facts.md). Radii are the contact radii
/// the fit settled on (detected radius x radius factor).
struct FitQuality {
  int presses = 0;
  /// 1 - sum (real - sim)^2 / sum (real - mean real)^2 over all channels of the pixels within
  /// kQualityRegionRadii of each press, pooled.
  double variance_explained = 0.0;
  double real_contact_mean = 0.0, sim_contact_mean = 0.0;  ///< mean |diff| inside the contact
  double real_contact_p95 = 0.0, sim_contact_p95 = 0.0;    ///< 95th percentile of |diff| there
  /// The darkest of 8 sectors of the ring 1-1.3 contact radii (mean of B, G, R diff; negative =
  /// darker than the background), averaged over presses.
  double real_rim_darkest = 0.0, sim_rim_darkest = 0.0;
  /// Which side of a press each channel (B, G, R) brightens: the direction of sum diff_c * u
  /// over the pixels within 1.2 contact radii (u: unit vector from the centre), in degrees in
  /// the image frame (0 = right, 90 = down), pooled over presses.
  cv::Vec3d real_side_deg, sim_side_deg;
  cv::Vec3d side_error_deg;  ///< |real - sim|, wrapped to [0, 180]
};

constexpr double kQualityRegionRadii = 1.5;

/// Compares `simulated` (one diff per press, image size) with the presses' real diffs.
FitQuality compareWithReal(const std::vector<PressObservation>& real,
                           const std::vector<cv::Mat3f>& simulated,
                           const std::vector<double>& contact_radii_px);

}  // namespace norm2tex
