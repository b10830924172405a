#pragma once
// Where a tool or node writes its results: checked once, before any work, so an unwritable or
// full directory is a one-line start-up error instead of a failure at the first write.

#include <string>

namespace norm2tex {

/// Creates `dir` (and its parents) if needed, writes and removes a probe file in it, and checks
/// that its disk has at least `min_free_mb` MB free (0: no check). Throws Error naming the
/// directory and the reason (e.g. "output directory 'a/file/out' cannot be written: Not a
/// directory").
void checkOutputDirectory(const std::string& dir, double min_free_mb = 0.0);

/// Free space for an unprivileged writer on the disk that holds `dir`, in MB (1e6 bytes); +inf
/// when it cannot be measured.
double freeMegabytes(const std::string& dir);

}  // namespace norm2tex
