#pragma once

#include <opencv2/core.hpp>

namespace norm2tex {

/// How strongly a frame answers a contact: |frame - background| over the contact's pixels, the
/// measure real DIGIT presses were characterised by (docs/calibration.md): B, G and R values
/// pooled, their mean and 95th percentile (grey levels).
struct ContactDifference {
  int pixels = 0;  ///< contact pixels (each counts three values)
  double mean_abs = 0.0;
  double p95_abs = 0.0;
};

/// Throws Error when the images' sizes differ or are empty, or the mask is not CV_8UC1 of the
/// same size. An empty mask gives zeros.
ContactDifference measureContactDifference(const cv::Mat3b& frame, const cv::Mat3b& background,
                                           const cv::Mat1b& contact_mask);

}  // namespace norm2tex
