#pragma once
// Memory kept across calls, handed out as matrix views: a bake touches its scratch pages once
// instead of once per island and pass, and on huge pages (see huge_pages.hpp).

#include <opencv2/core.hpp>

#include "norm2tex/common/huge_pages.hpp"

namespace norm2tex {
namespace detail {

template <typename T>
class ScratchBuffer {
 public:
  /// A continuous rows x cols view of this buffer's memory. Contents are unspecified; the view
  /// is valid until the next call of view() on the same buffer.
  cv::Mat_<T> view(int rows, int cols) {
    const size_t needed = static_cast<size_t>(rows) * static_cast<size_t>(cols);
    if (storage_.total() < needed) createWithHugePages(storage_, 1, static_cast<int>(needed));
    return cv::Mat_<T>(rows, cols, storage_.template ptr<T>());
  }
  cv::Mat_<T> view(cv::Size size) { return view(size.height, size.width); }

 private:
  cv::Mat_<T> storage_;
};

}  // namespace detail
}  // namespace norm2tex
