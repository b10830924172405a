#pragma once

namespace norm2tex {

/// Makes glibc keep freed memory for reuse instead of handing it back to the kernel:
/// allocations come from the heap (none is mapped on its own while a heap can hold it), and up
/// to 512 MB of freed heap is kept. Process-wide; idempotent; returns false if glibc refused.
///
/// Why: on our VMs the first touch of a fresh 4 KB page costs ~13 us. By default glibc maps
/// blocks over 128 KB (adaptively up to 32 MB) fresh and unmaps them on free, so a process that
/// renders frames, writes bags or bakes textures again and again faults the same memory in
/// over and over (a print3d variant, 2048^2, took 748-772 ms instead of 641-673 ms before its
/// 32 MB blocks came from the heap too).
/// Long-running nodes and repeated-work tools call this once at start.
bool keepFreedMemoryForReuse();

}  // namespace norm2tex
