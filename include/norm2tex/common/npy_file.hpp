#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace norm2tex {

/// Writes a float32 image as a NumPy .npy file (format 1.0, little-endian '<f4', C order):
/// shape (rows, cols) for one channel, (rows, cols, channels) otherwise, so numpy.load gives the
/// array as OpenCV holds it. Why a writer of our own: OpenCV writes no two-channel image
/// (imwrite takes 1, 3 or 4 channels) and Debian packages no C++ .npy library; the format is a
/// fixed header and the raw values (numpy.lib.format). Writes to a temporary file and renames;
/// throws Error for another type or when the write fails (missing directory, full disk).
void writeNpy(const std::string& path, const cv::Mat& array);

/// The header writeNpy puts before the values (magic, version, length, the dict padded with
/// spaces and a newline to a multiple of 64 bytes), as numpy.save writes it.
std::string npyHeader(int rows, int cols, int channels);

}  // namespace norm2tex
