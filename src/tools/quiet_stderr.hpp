#pragma once

#include <fcntl.h>
#include <unistd.h>

namespace norm2tex {
namespace cli {

/// Sends file descriptor 2 to /dev/null for its lifetime. Image decoders (libpng, libtiff)
/// print their own complaints on stderr; the tools report one clear line of their own instead.
/// Single-threaded command-line use only.
class QuietStderr {
 public:
  QuietStderr() : saved_(::dup(2)) {
    const int null_fd = ::open("/dev/null", O_WRONLY);
    if (saved_ >= 0 && null_fd >= 0) ::dup2(null_fd, 2);
    if (null_fd >= 0) ::close(null_fd);
  }
  ~QuietStderr() {
    if (saved_ < 0) return;
    ::dup2(saved_, 2);
    ::close(saved_);
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;

 private:
  int saved_;
};

}  // namespace cli
}  // namespace norm2tex
