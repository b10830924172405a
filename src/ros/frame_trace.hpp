#pragma once
// Per-frame wall-clock times of a node's stages, for the latency trace of
// `scripts/ros_benchmark --trace` (the ~trace_file parameter of contact_sim and tactile_renderer).

#include <cstdint>
#include <string>
#include <vector>

#include <ros/time.h>

namespace norm2tex {

/// Records, for each frame (its stamp), when each of a fixed list of stages was reached
/// (CLOCK_REALTIME, the clock of real-time stamps), in memory allocated up front, and writes them
/// as CSV (`stamp_ns,<stage>_ns,...`; -1 where a stage was not reached) when destroyed. The cost
/// per mark is a clock read and a store: tracing does not change what it measures. Disabled (an
/// empty path) it records nothing. One thread at a time (a node's frame thread).
class FrameTrace {
 public:
  FrameTrace() = default;
  /// Throws Error when `path` cannot be written (checked now, not at shutdown).
  FrameTrace(const std::string& path, std::vector<std::string> stages,
             std::size_t capacity = 100000);
  ~FrameTrace();
  FrameTrace(const FrameTrace&) = delete;
  FrameTrace& operator=(const FrameTrace&) = delete;

  bool enabled() const { return !path_.empty(); }
  /// Starts the row of the frame stamped `stamp`; marks until end() go to it. Frames beyond the
  /// capacity are counted, not recorded.
  void begin(const ros::Time& stamp);
  /// Closes the row: marks outside begin() ... end() (work that is not a traced frame) are
  /// ignored.
  void end() { open_ = false; }
  /// Stage `stage` (its index in the constructor's list) reached now.
  void mark(std::size_t stage) {
    if (open_) markAt(stage, now());
  }
  /// ... or at a time taken earlier (ns since the epoch).
  void markAt(std::size_t stage, std::int64_t wall_ns);
  /// Writes the CSV now (also done by the destructor); false with a reason on failure.
  bool write(std::string* why = nullptr);
  static std::int64_t now();

 private:
  std::string path_;
  std::vector<std::string> stages_;
  std::vector<std::int64_t> rows_;  ///< (1 + stages) values per frame
  std::size_t capacity_ = 0, used_ = 0, overflow_ = 0;
  bool open_ = false, written_ = false;
};

}  // namespace norm2tex
