#pragma once

#include <opencv2/core.hpp>

namespace norm2tex {

/// The mean of every `factor` x `factor` block of a bgr8 image, minus the same block of
/// `background` when one is given: what a learning pipeline feeds its network (a DIGIT frame
/// shrunk 4x to 80 x 60, background-subtracted). Rows and columns past the last whole block are
/// dropped. Each block's sum is exact (integers) and its mean one float division, so the result
/// equals numpy's `blocks.mean(axis=(2, 4), dtype=float32)` of the same crop bit for bit.
/// Throws Error for factor < 1, an image smaller than one block, or a
/// background of another size.
cv::Mat3f blockMean(const cv::Mat3b& image, int factor, const cv::Mat3b& background = cv::Mat3b());

/// As above, into `out` (reallocated only when its size differs): no allocation per frame.
void blockMean(const cv::Mat3b& image, int factor, const cv::Mat3b& background, cv::Mat3f& out);

}  // namespace norm2tex
