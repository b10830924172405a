#pragma once
// Structural checks of image files before decoding. Decoders are lenient where we must not be:
// libjpeg decodes a truncated JPEG with a warning and fills the missing rows with grey (for a
// normal map, a constant tilt), and a TIFF whose last strip is cut short can decode too.

#include <string>
#include <vector>

namespace norm2tex {
namespace detail {

/// Empty when `bytes` holds a complete PNG, JPEG or TIFF file (or a format not checked here);
/// otherwise a short reason, e.g. "JPEG data ends before its end-of-image marker (truncated?)".
std::string incompleteImageReason(const std::vector<unsigned char>& bytes);

}  // namespace detail
}  // namespace norm2tex
