#include "common/image_file_check.hpp"

#include <cstdint>
#include <cstring>

namespace norm2tex {
namespace detail {
namespace {

using Bytes = ByteView;

bool startsWith(const Bytes& bytes, const char* magic, size_t length) {
  return bytes.size() >= length && std::memcmp(bytes.data(), magic, length) == 0;
}

std::uint32_t bigEndian32(const Bytes& b, size_t at) {
  return std::uint32_t(b[at]) << 24 | std::uint32_t(b[at + 1]) << 16 |
         std::uint32_t(b[at + 2]) << 8 | std::uint32_t(b[at + 3]);
}

/// Chunks laid end to end up to IEND, each inside the file.
std::string checkPng(const Bytes& bytes) {
  size_t at = 8;
  while (at + 12 <= bytes.size()) {
    const std::uint64_t length = bigEndian32(bytes, at);
    const bool end = std::memcmp(&bytes[at + 4], "IEND", 4) == 0;
    at += 12 + length;
    if (at > bytes.size()) break;
    if (end) return "";
  }
  return "PNG data ends before its IEND chunk (truncated?)";
}

/// Segments up to the first frame's start of scan, then an end-of-image marker after it.
/// Segment lengths are followed so an EXIF thumbnail (a whole JPEG inside APP1) cannot pass
/// for the image's own end.
std::string checkJpeg(const Bytes& bytes) {
  size_t at = 2;
  for (;;) {
    while (at < bytes.size() && bytes[at] == 0xFF) ++at;  // fill bytes before a marker code
    if (at >= bytes.size()) return "JPEG data ends before its first scan (truncated?)";
    const unsigned char marker = bytes[at++];
    if (marker == 0xD9) return "JPEG ends before any image data";
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;  // no length field
    if (at + 2 > bytes.size()) return "JPEG data ends inside a segment header (truncated?)";
    const size_t length = size_t(bytes[at]) << 8 | bytes[at + 1];
    if (length < 2 || at + length > bytes.size()) {
      return "JPEG data ends inside a segment (truncated?)";
    }
    at += length;
    if (marker == 0xDA) break;  // entropy-coded data follows
  }
  for (size_t i = at; i + 1 < bytes.size(); ++i) {
    if (bytes[i] == 0xFF && bytes[i + 1] == 0xD9) return "";
  }
  return "JPEG data ends before its end-of-image marker (truncated?)";
}

/// Every directory, and every strip or tile it points to, inside the file (classic TIFF;
/// BigTIFF is left to the decoder).
std::string checkTiff(const Bytes& bytes) {
  const bool little = bytes[0] == 'I';
  const auto read = [&](size_t at, int size) -> std::uint64_t {
    std::uint64_t value = 0;
    for (int i = 0; i < size; ++i) {
      const std::uint64_t byte = bytes[at + i];
      value |= little ? byte << (8 * i) : byte << (8 * (size - 1 - i));
    }
    return value;
  };
  if (bytes.size() < 8) return "TIFF header is incomplete (truncated?)";
  if (read(2, 2) != 42) return "";  // BigTIFF or unknown: the decoder decides
  std::uint64_t directory = read(4, 4);
  for (int directories = 0; directory != 0 && directories < 64; ++directories) {
    if (directory + 2 > bytes.size()) return "TIFF directory lies beyond the end of the file";
    const std::uint64_t entries = read(directory, 2);
    if (directory + 2 + entries * 12 + 4 > bytes.size()) {
      return "TIFF directory runs past the end of the file (truncated?)";
    }
    std::vector<std::uint64_t> offsets, counts;
    for (std::uint64_t e = 0; e < entries; ++e) {
      const size_t entry = directory + 2 + e * 12;
      const std::uint64_t tag = read(entry, 2), type = read(entry + 2, 2);
      const std::uint64_t count = read(entry + 4, 4);
      const int size = type == 3 ? 2 : (type == 4 ? 4 : 0);
      const bool wanted = tag == 273 || tag == 279 || tag == 324 || tag == 325;
      if (!wanted || size == 0) continue;
      // Values of up to 4 bytes sit in the entry itself, longer arrays elsewhere.
      const std::uint64_t values = count * size <= 4 ? entry + 8 : read(entry + 8, 4);
      if (values + count * size > bytes.size()) {
        return "TIFF strip table lies beyond the end of the file (truncated?)";
      }
      auto& list = (tag == 273 || tag == 324) ? offsets : counts;
      for (std::uint64_t i = 0; i < count; ++i) list.push_back(read(values + i * size, size));
    }
    for (size_t i = 0; i < offsets.size() && i < counts.size(); ++i) {
      if (offsets[i] + counts[i] > bytes.size()) {
        return "TIFF image data ends before its last strip or tile (truncated?)";
      }
    }
    directory = read(directory + 2 + entries * 12, 4);
  }
  return "";
}

}  // namespace

std::string incompleteImageReason(ByteView bytes) {
  if (startsWith(bytes, "\x89PNG\r\n\x1a\n", 8)) return checkPng(bytes);
  if (startsWith(bytes, "\xFF\xD8", 2)) return checkJpeg(bytes);
  if (startsWith(bytes, "II", 2) || startsWith(bytes, "MM", 2)) return checkTiff(bytes);
  return "";
}

}  // namespace detail
}  // namespace norm2tex
