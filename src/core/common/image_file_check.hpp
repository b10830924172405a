#pragma once
// Structural checks of image files before decoding. Decoders are lenient where we must not be:
// libjpeg decodes a truncated JPEG with a warning and fills the missing rows with grey (for a
// normal map, a constant tilt), and a TIFF whose last strip is cut short can decode too.

#include <cstddef>
#include <string>
#include <vector>

namespace norm2tex {
namespace detail {

/// A file's bytes wherever they live (a vector, a huge-page buffer).
struct ByteView {
  const unsigned char* bytes;
  size_t length;
  size_t size() const { return length; }
  const unsigned char* data() const { return bytes; }
  const unsigned char& operator[](size_t i) const { return bytes[i]; }
};

/// Empty when `bytes` holds a complete PNG, JPEG or TIFF file (or a format not checked here);
/// otherwise a short reason, e.g. "JPEG data ends before its end-of-image marker (truncated?)".
std::string incompleteImageReason(ByteView bytes);
inline std::string incompleteImageReason(const std::vector<unsigned char>& bytes) {
  return incompleteImageReason(ByteView{bytes.data(), bytes.size()});
}

}  // namespace detail
}  // namespace norm2tex
