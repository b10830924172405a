#include "norm2tex/common/output_directory.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "norm2tex/common/error.hpp"

namespace norm2tex {

double freeMegabytes(const std::string& dir) {
  std::error_code ec;
  const std::filesystem::space_info space = std::filesystem::space(dir, ec);
  if (ec) return std::numeric_limits<double>::infinity();
  return static_cast<double>(space.available) / 1e6;
}

void checkOutputDirectory(const std::string& dir, double min_free_mb) {
  if (dir.empty()) throw Error("output directory is empty: give a directory to write into");
  const std::string what = "output directory '" + dir + "'";
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error(what + " cannot be written: " + ec.message());
  if (!std::filesystem::is_directory(dir, ec)) throw Error(what + " is not a directory");
  const std::string probe = dir + "/.norm2tex_write_test";
  errno = 0;
  if (!std::ofstream(probe)) {
    throw Error(what + " cannot be written" + (errno ? ": " + std::string(std::strerror(errno)) : ""));
  }
  std::filesystem::remove(probe, ec);
  const double free_mb = freeMegabytes(dir);
  if (min_free_mb > 0.0 && free_mb < min_free_mb) {
    std::ostringstream message;
    message << what << " has " << free_mb << " MB free, under the " << min_free_mb
            << " MB asked for (min_free_mb)";
    throw Error(message.str());
  }
}

}  // namespace norm2tex
