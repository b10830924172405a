#include "norm2tex/common/npy_file.hpp"

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "norm2tex/common/error.hpp"

namespace norm2tex {

std::string npyHeader(int rows, int cols, int channels) {
  std::string dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (" +
                     std::to_string(rows) + ", " + std::to_string(cols) +
                     (channels > 1 ? ", " + std::to_string(channels) : std::string()) + "), }";
  // magic (6) + version (2) + length (2) + dict + padding + '\n': a multiple of 64 (numpy's
  // alignment, so the values can be memory-mapped).
  const std::size_t unpadded = 10 + dict.size() + 1;
  dict.append((64 - unpadded % 64) % 64, ' ');
  dict += '\n';
  const auto length = static_cast<std::uint16_t>(dict.size());
  std::string header("\x93NUMPY\x01\x00", 8);
  header += static_cast<char>(length & 0xff);
  header += static_cast<char>(length >> 8);
  return header + dict;
}

void writeNpy(const std::string& path, const cv::Mat& array) {
  if (array.depth() != CV_32F) {
    throw Error("'" + path + "': only float32 arrays are written as .npy");
  }
  static_assert(sizeof(float) == 4, "'<f4' is a 4-byte float");
  const std::uint16_t probe = 1;
  if (*reinterpret_cast<const unsigned char*>(&probe) != 1) {
    throw Error("'" + path + "': .npy files are written little-endian only");
  }
  const std::string temporary = path + ".partial";
  {
    std::ofstream out(temporary, std::ios::binary);
    if (!out) throw Error("cannot write '" + path + "' (missing directory or permissions?)");
    out << npyHeader(array.rows, array.cols, array.channels());
    const std::size_t row_bytes = array.cols * array.elemSize();
    for (int r = 0; r < array.rows; ++r) {
      out.write(reinterpret_cast<const char*>(array.ptr(r)), static_cast<std::streamsize>(row_bytes));
    }
    out.close();
    if (!out) {
      std::remove(temporary.c_str());
      throw Error("writing '" + path + "' failed (disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::remove(temporary.c_str());
    throw Error("writing '" + path + "' failed: " + ec.message());
  }
}

}  // namespace norm2tex
