#include "norm2tex/texture/uv_islands.hpp"

#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/common/huge_pages.hpp"

namespace norm2tex {

UvIslands findUvIslands(const cv::Mat1b& valid) {
  if (valid.empty()) throw Error("findUvIslands: empty mask");
  UvIslands result;
  cv::Mat stats, centroids;
  createWithHugePages(result.labels, valid.rows, valid.cols);  // a bake's largest label map
  // Every texel valid (a tiling texture without alpha, the common case): one island, the
  // whole map. connectedComponents would first clear a 32 MB table at 4096^2 for this.
  if (cv::countNonZero(valid) == valid.rows * valid.cols) {
    result.labels.setTo(1);
    result.islands.push_back({1, cv::Rect(0, 0, valid.cols, valid.rows), valid.rows * valid.cols});
    return result;
  }
  const int count =
      cv::connectedComponentsWithStats(valid, result.labels, stats, centroids, 4, CV_32S);
  result.islands.reserve(count > 0 ? count - 1 : 0);
  for (int label = 1; label < count; ++label) {  // label 0 is the background
    UvIsland island;
    island.label = label;
    island.bounding_box =
        cv::Rect(stats.at<int>(label, cv::CC_STAT_LEFT), stats.at<int>(label, cv::CC_STAT_TOP),
                 stats.at<int>(label, cv::CC_STAT_WIDTH), stats.at<int>(label, cv::CC_STAT_HEIGHT));
    island.texel_count = stats.at<int>(label, cv::CC_STAT_AREA);
    result.islands.push_back(island);
  }
  return result;
}

}  // namespace norm2tex
