#include "contact_sheet.hpp"

#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace cli {
namespace {

constexpr int kGap = 4;
constexpr int kTopMargin = 28;
constexpr int kLeftMargin = 150;
const cv::Scalar kPaper(255, 255, 255);
const cv::Scalar kInk(30, 30, 30);

void putLabel(cv::Mat3b& sheet, const std::string& text, cv::Point origin, int max_width) {
  double scale = 0.5;
  int baseline = 0;
  while (scale > 0.25 &&
         cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline).width > max_width) {
    scale -= 0.05;
  }
  cv::putText(sheet, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, kInk, 1, cv::LINE_AA);
}

}  // namespace

cv::Mat3b makeContactSheet(const std::vector<std::vector<cv::Mat3b>>& tiles,
                           const std::vector<std::string>& row_labels,
                           const std::vector<std::string>& column_labels) {
  if (tiles.empty() || tiles[0].empty()) throw Error("contact sheet: no tiles");
  const cv::Size tile = tiles[0][0].size();
  const int rows = static_cast<int>(tiles.size());
  const int cols = static_cast<int>(tiles[0].size());
  cv::Mat3b sheet(kTopMargin + rows * (tile.height + kGap),
                  kLeftMargin + cols * (tile.width + kGap), cv::Vec3b(255, 255, 255));
  for (int r = 0; r < rows; ++r) {
    if (static_cast<int>(tiles[r].size()) != cols) throw Error("contact sheet: ragged rows");
    const int y = kTopMargin + r * (tile.height + kGap);
    if (r < static_cast<int>(row_labels.size())) {
      putLabel(sheet, row_labels[r], {6, y + tile.height / 2}, kLeftMargin - 10);
    }
    for (int c = 0; c < cols; ++c) {
      if (tiles[r][c].size() != tile) throw Error("contact sheet: tiles differ in size");
      tiles[r][c].copyTo(
          sheet(cv::Rect(kLeftMargin + c * (tile.width + kGap), y, tile.width, tile.height)));
    }
  }
  for (int c = 0; c < cols && c < static_cast<int>(column_labels.size()); ++c) {
    putLabel(sheet, column_labels[c], {kLeftMargin + c * (tile.width + kGap) + 4, 19},
             tile.width - 8);
  }
  return sheet;
}

}  // namespace cli
}  // namespace norm2tex
