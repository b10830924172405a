#pragma once
// Memory kept across calls, handed out as matrix views: a bake touches its scratch pages once
// instead of once per island and pass (a first touch costs ~13 us per 4 KB page on our VMs).

#include <cstddef>
#include <vector>

#include <opencv2/core.hpp>

namespace norm2tex {
namespace detail {

template <typename T>
class ScratchBuffer {
 public:
  /// A continuous rows x cols view of this buffer's memory. Contents are unspecified; the view
  /// is valid until the next call of view() on the same buffer.
  cv::Mat_<T> view(int rows, int cols) {
    const size_t needed = static_cast<size_t>(rows) * static_cast<size_t>(cols);
    if (storage_.size() < needed) storage_.resize(needed);
    return cv::Mat_<T>(rows, cols, storage_.data());
  }
  cv::Mat_<T> view(cv::Size size) { return view(size.height, size.width); }

 private:
  std::vector<T> storage_;
};

}  // namespace detail
}  // namespace norm2tex
