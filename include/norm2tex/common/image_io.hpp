#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace norm2tex {

/// Reads an image (cv::IMREAD_* `flags`) and throws norm2tex::Error naming `what` and the path
/// when the file is missing, a directory, unreadable, zero-sized, truncated or corrupt. PNG,
/// JPEG and TIFF files are checked to be complete before decoding (decoders accept a truncated
/// JPEG and fill the missing rows with grey).
cv::Mat readImage(const std::string& path, int flags, const std::string& what);

/// decodes an image file held in memory (e.g. a texture embedded in a GLB) with the same
/// checks; `what` names it in errors ("mesh 'x.glb' normal texture '*0'").
cv::Mat decodeImage(const std::vector<unsigned char>& bytes, int flags, const std::string& what);

/// Throws Error unless the format chosen by `path`'s extension stores pixels of `type` without
/// loss of range: floating point only in .tiff/.tif (or .exr/.pfm/.hdr), 16-bit integers also in
/// .png/.pgm/.ppm. Call it before the work when a tool writes several files.
void requireFormatHolds(const std::string& path, int type);

/// Writes an image (after requireFormatHolds); throws norm2tex::Error when the extension is
/// unsupported for the pixel type or the write fails (missing directory, full disk, permissions).
/// Writes to a temporary file first and renames, so a failed write never leaves a truncated file at
/// `path`.
void writeImage(const std::string& path, const cv::Mat& image);

/// Lower-case extension including the dot ("" if none), e.g. ".tiff".
std::string lowerCaseExtension(const std::string& path);

}  // namespace norm2tex
