#include "norm2tex/render/block_mean.hpp"

#include <algorithm>

#include <string>
#include <vector>

#include "norm2tex/common/error.hpp"

namespace norm2tex {

cv::Mat3f blockMean(const cv::Mat3b& image, int factor, const cv::Mat3b& background) {
  cv::Mat3f out;
  blockMean(image, factor, background, out);
  return out;
}

void blockMean(const cv::Mat3b& image, int factor, const cv::Mat3b& background, cv::Mat3f& out) {
  if (factor < 1) {
    throw Error("block mean: factor " + std::to_string(factor) +
                                "; valid: an integer >= 1");
  }
  if (image.rows < factor || image.cols < factor) {
    throw Error("block mean: a " + std::to_string(image.cols) + " x " +
                                std::to_string(image.rows) + " image has no whole " +
                                std::to_string(factor) + " x " + std::to_string(factor) +
                                " block");
  }
  const bool subtract = !background.empty();
  if (subtract && background.size() != image.size()) {
    throw Error("block mean: background " + std::to_string(background.cols) +
                                " x " + std::to_string(background.rows) + " differs from the " +
                                std::to_string(image.cols) + " x " + std::to_string(image.rows) +
                                " image");
  }
  const int rows = image.rows / factor, cols = image.cols / factor;
  out.create(rows, cols);
  const float count = static_cast<float>(factor * factor);
  // Column sums of one block row, accumulated row by row (cache-friendly: each source row is
  // read once, left to right). int: at most factor^2 * 255 per entry.
  std::vector<int> sums(static_cast<std::size_t>(cols) * 3);
  for (int br = 0; br < rows; ++br) {
    std::fill(sums.begin(), sums.end(), 0);
    for (int r = br * factor; r < (br + 1) * factor; ++r) {
      const cv::Vec3b* px = image.ptr<cv::Vec3b>(r);
      const cv::Vec3b* bg = subtract ? background.ptr<cv::Vec3b>(r) : nullptr;
      for (int bc = 0; bc < cols; ++bc) {
        int* s = &sums[static_cast<std::size_t>(bc) * 3];
        for (int c = bc * factor; c < (bc + 1) * factor; ++c) {
          for (int k = 0; k < 3; ++k) s[k] += px[c][k] - (subtract ? bg[c][k] : 0);
        }
      }
    }
    cv::Vec3f* o = out.ptr<cv::Vec3f>(br);
    for (int bc = 0; bc < cols; ++bc) {
      for (int k = 0; k < 3; ++k) o[bc][k] = static_cast<float>(sums[bc * 3 + k]) / count;
    }
  }
}

}  // namespace norm2tex
