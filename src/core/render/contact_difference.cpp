#include "norm2tex/render/contact_difference.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "norm2tex/common/error.hpp"

namespace norm2tex {

ContactDifference measureContactDifference(const cv::Mat3b& frame, const cv::Mat3b& background,
                                           const cv::Mat1b& contact_mask) {
  if (frame.empty() || frame.size() != background.size() ||
      contact_mask.size() != frame.size()) {
    throw Error("measureContactDifference: the frame, background and contact mask must be "
                "non-empty and of one size");
  }
  // Grey-level differences are integers 0-255: a histogram gives the mean and the percentile
  // exactly, without sorting.
  std::vector<long> histogram(256, 0);
  ContactDifference out;
  long sum = 0;
  for (int r = 0; r < frame.rows; ++r) {
    const cv::Vec3b* f = frame.ptr<cv::Vec3b>(r);
    const cv::Vec3b* b = background.ptr<cv::Vec3b>(r);
    const std::uint8_t* m = contact_mask.ptr<std::uint8_t>(r);
    for (int c = 0; c < frame.cols; ++c) {
      if (!m[c]) continue;
      ++out.pixels;
      for (int k = 0; k < 3; ++k) {
        const int d = std::abs(static_cast<int>(f[c][k]) - static_cast<int>(b[c][k]));
        ++histogram[d];
        sum += d;
      }
    }
  }
  const long values = 3L * out.pixels;
  if (values == 0) return out;
  out.mean_abs = static_cast<double>(sum) / values;
  // The value at rank floor(0.95 (n - 1)) of the sorted values, as the calibration report's.
  const long rank = static_cast<long>(0.95 * (values - 1));
  long seen = 0;
  for (int d = 0; d < 256; ++d) {
    seen += histogram[d];
    if (seen > rank) {
      out.p95_abs = d;
      break;
    }
  }
  return out;
}

}  // namespace norm2tex
