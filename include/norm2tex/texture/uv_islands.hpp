#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace norm2tex {

/// One connected patch of valid texels of a UV atlas.
struct UvIsland {
  int label = 0;          ///< value of this island in UvIslands::labels (1..N)
  cv::Rect bounding_box;  ///< in texels
  int texel_count = 0;
};

/// UV islands of a validity mask. Texels are connected through their 4 edge neighbours only:
/// two patches touching at a corner share no finite-difference edge, so their relative height
/// is unknown and they must be integrated separately.
struct UvIslands {
  cv::Mat1i labels;  ///< 0 outside every island, otherwise the island's label
  std::vector<UvIsland> islands;
};

/// Finds the connected patches of non-zero texels of `valid` (CV_8UC1).
UvIslands findUvIslands(const cv::Mat1b& valid);

}  // namespace norm2tex
