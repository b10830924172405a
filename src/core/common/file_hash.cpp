#include "norm2tex/common/file_hash.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

#include "norm2tex/common/error.hpp"

namespace norm2tex {

std::uint64_t fnv1a64(const std::string& bytes, std::uint64_t seed) {
  std::uint64_t hash = seed;
  for (unsigned char byte : bytes) {
    hash ^= byte;
    hash *= 1099511628211ull;
  }
  return hash;
}

std::string toHex(std::uint64_t value) {
  char text[17];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(value));
  return text;
}

std::string hashFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error("'" + path + "' does not exist or is not a regular file");
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) throw Error("cannot read '" + path + "' (permissions?)");
  std::uint64_t hash = 14695981039346656037ull;
  std::vector<char> buffer(1 << 20);
  while (file) {
    file.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const std::streamsize count = file.gcount();
    for (std::streamsize i = 0; i < count; ++i) {
      hash ^= static_cast<unsigned char>(buffer[static_cast<size_t>(i)]);
      hash *= 1099511628211ull;
    }
  }
  if (file.bad()) throw Error("read error while hashing '" + path + "'");
  return toHex(hash);
}

}  // namespace norm2tex
