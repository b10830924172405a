#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace norm2tex {

/// Reads an image with cv::imread(path, flags) and throws norm2tex::Error naming `what` and
/// the path when the file is missing, a directory, unreadable, corrupt or zero-sized.
cv::Mat readImage(const std::string& path, int flags, const std::string& what);

/// Throws Error unless the format chosen by `path`'s extension stores pixels of `type` without
/// loss of range: floating point only in .tiff/.tif (or .exr/.pfm/.hdr), 16-bit integers also in
/// .png/.pgm/.ppm. Call it before the work when a tool writes several files.
void requireFormatHolds(const std::string& path, int type);

/// Writes an image (after requireFormatHolds); throws norm2tex::Error when the extension is unsupported for the pixel type
/// or the write fails (missing directory, full disk, permissions). Writes to a temporary file
/// first and renames, so a failed write never leaves a truncated file at `path`.
void writeImage(const std::string& path, const cv::Mat& image);

/// Lower-case extension including the dot ("" if none), e.g. ".tiff".
std::string lowerCaseExtension(const std::string& path);

}  // namespace norm2tex
