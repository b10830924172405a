#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace norm2tex {

/// Reads an image with cv::imread(path, flags) and throws norm2tex::Error naming `what` and
/// the path when the file is missing, a directory, unreadable, corrupt or zero-sized.
cv::Mat readImage(const std::string& path, int flags, const std::string& what);

/// Writes an image; throws norm2tex::Error when the extension is unsupported for the pixel type
/// or the write fails (missing directory, full disk, permissions). Writes to a temporary file
/// first and renames, so a failed write never leaves a truncated file at `path`.
void writeImage(const std::string& path, const cv::Mat& image);

/// Lower-case extension including the dot ("" if none), e.g. ".tiff".
std::string lowerCaseExtension(const std::string& path);

}  // namespace norm2tex
