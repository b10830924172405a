#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace norm2tex {
namespace cli {

/// A labelled grid of equally sized BGR tiles: one label per row (left margin) and per column
/// (top margin). Used for the figures in docs/; `tiles[row][column]`.
cv::Mat3b makeContactSheet(const std::vector<std::vector<cv::Mat3b>>& tiles,
                           const std::vector<std::string>& row_labels,
                           const std::vector<std::string>& column_labels);

}  // namespace cli
}  // namespace norm2tex
