#include "norm2tex/common/image_io.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <system_error>

#include <opencv2/imgcodecs.hpp>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace fs = std::filesystem;

std::string lowerCaseExtension(const std::string& path) {
  std::string extension = fs::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

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
  cv::Mat image;
  try {
    image = cv::imread(path, flags);
  } catch (const cv::Exception& e) {
    throw Error(what + " '" + path + "' cannot be decoded: " + e.what());
  }
  if (image.empty()) {
    throw Error(what + " '" + path +
                "' cannot be decoded (corrupt, truncated or not a PNG/JPEG/TIFF image)");
  }
  return image;
}

void writeImage(const std::string& path, const cv::Mat& image) {
  if (image.empty()) throw Error("refusing to write an empty image to '" + path + "'");
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
