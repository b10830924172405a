#include "norm2tex/common/image_io.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <limits>
#include <system_error>

#include <opencv2/imgcodecs.hpp>

#include "common/image_file_check.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/huge_pages.hpp"

namespace norm2tex {
namespace fs = std::filesystem;

std::string lowerCaseExtension(const std::string& path) {
  std::string extension = fs::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

namespace {

/// `bytes`: one row of CV_8U, the whole file.
cv::Mat decode(const cv::Mat& bytes, int flags, const std::string& what) {
  if (const std::string reason =
          detail::incompleteImageReason(detail::ByteView{bytes.data, bytes.total()});
      !reason.empty()) {
    throw Error(what + " is corrupt: " + reason);
  }
  cv::Mat image;
  try {
    image = cv::imdecode(bytes, flags);
  } catch (const cv::Exception& e) {
    throw Error(what + " cannot be decoded: " + e.what());
  }
  if (image.empty()) {
    throw Error(what + " cannot be decoded (corrupt, truncated or not a PNG/JPEG/TIFF image)");
  }
  return image;
}

}  // namespace

cv::Mat readImage(const std::string& path, int flags, const std::string& what) {
  std::error_code ec;
  if (path.empty()) throw Error(what + ": no file name given");
  if (!fs::exists(path, ec)) throw Error(what + " '" + path + "' does not exist");
  if (fs::is_directory(path, ec))
    throw Error(what + " '" + path + "' is a directory, not an image");
  if (!std::ifstream(path, std::ios::binary).good()) {
    throw Error(what + " '" + path + "' cannot be opened (permissions?)");
  }
  if (fs::file_size(path, ec) == 0) throw Error(what + " '" + path + "' is an empty file");
  // One read of the whole file: checked for completeness, then decoded from memory. The
  // buffer is on huge pages and not zero-filled first: a 4096^2 16-bit PNG is ~56 MB, which
  // as a std::vector costs ~14 000 fresh 4 KB pages (about 0.2 s on our VMs) before the read.
  const std::uintmax_t size = fs::file_size(path, ec);
  if (size > static_cast<std::uintmax_t>(std::numeric_limits<int>::max())) {
    throw Error(what + " '" + path + "' is larger than 2 GB");
  }
  cv::Mat bytes;
  createWithHugePages(bytes, 1, static_cast<int>(size), CV_8U);
  {
    std::ifstream file(path, std::ios::binary);
    file.read(reinterpret_cast<char*>(bytes.data), static_cast<std::streamsize>(bytes.total()));
    if (!file || ec) throw Error(what + " '" + path + "' cannot be read");
  }
  return decode(bytes, flags, what + " '" + path + "'");
}

cv::Mat decodeImage(const std::vector<unsigned char>& bytes, int flags, const std::string& what) {
  if (bytes.empty()) throw Error(what + " is empty");
  return decode(
      cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, const_cast<unsigned char*>(bytes.data())),
      flags, what);
}

void requireFormatHolds(const std::string& path, int type) {
  const std::string extension = lowerCaseExtension(path);
  const int depth = CV_MAT_DEPTH(type);
  const bool float_data = depth == CV_32F || depth == CV_64F;
  const bool float_format = extension == ".tiff" || extension == ".tif" || extension == ".exr" ||
                            extension == ".pfm" || extension == ".hdr";
  const bool sixteen_bit_format = float_format || extension == ".png" || extension == ".pgm" ||
                                  extension == ".ppm" || extension == ".pnm";
  // OpenCV would convert silently: float depth in metres to PNG saturates to 0 or 1.
  if (float_data && !float_format) {
    throw Error("cannot write floating-point data to '" + path +
                "': " + (extension.empty() ? std::string("no extension") : extension) +
                " holds only integers; use .tiff");
  }
  if (depth == CV_16U && !sixteen_bit_format) {
    throw Error("cannot write 16-bit data to '" + path +
                "': " + (extension.empty() ? std::string("no extension") : extension) +
                " holds only 8 bits; use .png or .tiff");
  }
}

void writeImage(const std::string& path, const cv::Mat& image) {
  if (image.empty()) throw Error("refusing to write an empty image to '" + path + "'");
  requireFormatHolds(path, image.type());
  const fs::path target(path);
  std::error_code ec;
  if (target.has_parent_path() && !fs::is_directory(target.parent_path(), ec)) {
    throw Error("cannot write '" + path + "': directory '" + target.parent_path().string() +
                "' does not exist");
  }
  // Same extension on the temporary file so OpenCV picks the same encoder.
  const fs::path temporary =
      target.parent_path() / (".tmp-" + target.stem().string() + target.extension().string());
  bool written = false;
  try {
    written = cv::imwrite(temporary.string(), image);
  } catch (const cv::Exception& e) {
    fs::remove(temporary, ec);
    throw Error("cannot write '" + path + "': " + e.what());
  }
  if (!written) {
    fs::remove(temporary, ec);
    throw Error("cannot write '" + path +
                "' (unsupported extension for this pixel type, disk full or no permission)");
  }
  fs::rename(temporary, target, ec);
  if (ec) {
    fs::remove(temporary, ec);
    throw Error("cannot write '" + path + "': " + ec.message());
  }
}

}  // namespace norm2tex
