#include "norm2tex/common/memory_reuse.hpp"

#include <malloc.h>

namespace norm2tex {

bool keepFreedMemoryForReuse() {
  static const bool done = [] {
    // mallopt returns 1 on success; 32 MB is the largest mmap threshold glibc accepts on 64-bit,
    // and blocks of 32 MB or more are mapped whatever the threshold unless mapping is off (a
    // 2048^2 texture's 16-bit BGRA normal map is 32 MB). With it off glibc still maps what no
    // heap can hold (a thread's heap stops at 64 MB) rather than fail.
    const bool mmap_ok = mallopt(M_MMAP_THRESHOLD, 32 << 20) == 1;
    const bool trim_ok = mallopt(M_TRIM_THRESHOLD, 512 << 20) == 1;
    const bool no_maps_ok = mallopt(M_MMAP_MAX, 0) == 1;
    return mmap_ok && trim_ok && no_maps_ok;
  }();
  return done;
}

}  // namespace norm2tex
