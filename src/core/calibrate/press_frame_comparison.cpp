#include "norm2tex/calibrate/press_frame_comparison.hpp"

#include <algorithm>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

double median(std::vector<double> values) {
  const size_t half = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + half, values.end());
  const double upper = values[half];
  if (values.size() % 2 == 1) return upper;
  return 0.5 * (*std::max_element(values.begin(), values.begin() + half) + upper);
}

}  // namespace

cv::Mat1b contactDiscMask(cv::Size size, cv::Point2d centre, double radius_px) {
  cv::Mat1b mask(size, 0);
  const double r2 = radius_px * radius_px;
  for (int r = 0; r < size.height; ++r) {
    for (int c = 0; c < size.width; ++c) {
      const double dx = c - centre.x, dy = r - centre.y;
      if (dx * dx + dy * dy <= r2) mask(r, c) = 255;
    }
  }
  return mask;
}

cv::Mat3b renderedPressFrame(const cv::Mat3b& background, const cv::Mat3f& simulated_diff) {
  cv::Mat3f sum;
  background.convertTo(sum, CV_32F);
  sum += simulated_diff;
  cv::Mat3b frame;
  sum.convertTo(frame, CV_8U);  // rounds and saturates
  return frame;
}

ImageSimilarity medianSimilarity(const std::vector<PressFrameComparison>& presses,
                                 ImageSimilarity PressFrameComparison::*measures) {
  if (presses.empty()) throw Error("median image similarity: no presses");
  std::vector<double> ssim, ssim_in_mask, psnr, mean_abs_diff;
  for (const PressFrameComparison& press : presses) {
    const ImageSimilarity& s = press.*measures;
    ssim.push_back(s.ssim);
    ssim_in_mask.push_back(s.ssim_in_mask);
    psnr.push_back(s.psnr_db);
    mean_abs_diff.push_back(s.mean_abs_diff);
  }
  ImageSimilarity medians;
  medians.ssim = median(ssim);
  medians.ssim_in_mask = median(ssim_in_mask);
  medians.psnr_db = median(psnr);
  medians.mean_abs_diff = median(mean_abs_diff);
  return medians;
}

}  // namespace norm2tex
