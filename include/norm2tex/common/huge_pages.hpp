#pragma once

#include <opencv2/core.hpp>

namespace norm2tex {

/// A cv::MatAllocator that backs matrices of 2 MB and more with transparent huge pages
/// (2 MB-aligned anonymous mappings marked MADV_HUGEPAGE), and smaller ones like OpenCV's own.
///
/// Why: on our VMs the first touch of a fresh 4 KB page costs about 13 us, so a 2048^2 bake
/// that touches ~300 MB spends most of its time in page faults; one huge-page fault covers
/// 512 pages for about the price of one (256 MB: ~0.75 s with 4 KB pages, ~25 ms with huge
/// pages when the kernel has them free). Where the kernel has no huge page at hand (THP off,
/// memory fragmented) the mapping simply falls back to 4 KB pages: same result, old speed.
/// Freed mappings (up to 512 MB) are kept and handed to the next matrix of the same mapping
/// length, already faulted in: contents are never zeroed. Thread-safe; lives for the whole
/// process.
cv::MatAllocator* hugePageAllocator();

/// Makes `matrix` a fresh rows x cols matrix of `type` from hugePageAllocator() (contents
/// unspecified), dropping whatever it held.
void createWithHugePages(cv::Mat& matrix, int rows, int cols, int type);

template <typename T>
void createWithHugePages(cv::Mat_<T>& matrix, int rows, int cols) {
  matrix.release();
  matrix.allocator = hugePageAllocator();
  matrix.create(rows, cols);
}

}  // namespace norm2tex
