#include "norm2tex/common/memory_reuse.hpp"

#include <malloc.h>

namespace norm2tex {

bool keepFreedMemoryForReuse() {
  static const bool done = [] {
    // mallopt returns 1 on success; 32 MB is the largest mmap threshold glibc accepts on 64-bit.
    const bool mmap_ok = mallopt(M_MMAP_THRESHOLD, 32 << 20) == 1;
    const bool trim_ok = mallopt(M_TRIM_THRESHOLD, 512 << 20) == 1;
    return mmap_ok && trim_ok;
  }();
  return done;
}

}  // namespace norm2tex
