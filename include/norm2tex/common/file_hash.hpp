#pragma once

#include <cstdint>
#include <string>

namespace norm2tex {

/// 64-bit FNV-1a of a file's bytes, as 16 lower-case hex digits. A cache key, not a
/// cryptographic digest. Throws Error if the file cannot be read.
std::string hashFile(const std::string& path);

/// 64-bit FNV-1a of a string, continuing from `seed` (chain calls to hash several parts).
std::uint64_t fnv1a64(const std::string& bytes, std::uint64_t seed = 14695981039346656037ull);

/// 16 lower-case hex digits.
std::string toHex(std::uint64_t value);

}  // namespace norm2tex
