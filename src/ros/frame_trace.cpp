#include "frame_trace.hpp"

#include <time.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>

#include <ros/console.h>

#include "norm2tex/common/error.hpp"

namespace norm2tex {

FrameTrace::FrameTrace(const std::string& path, std::vector<std::string> stages,
                       std::size_t capacity)
    : path_(path), stages_(std::move(stages)), capacity_(capacity) {
  if (path_.empty()) return;
  {
    std::ofstream probe(path_);
    if (!probe) throw Error("cannot write the trace file " + path_ + ": " + std::strerror(errno));
  }
  // Touched now: a page fault per first write would land in the frames it times.
  rows_.assign(capacity_ * (1 + stages_.size()), -1);
}

FrameTrace::~FrameTrace() {
  std::string why;
  if (enabled() && !written_ && !write(&why)) ROS_ERROR("%s", why.c_str());
}

std::int64_t FrameTrace::now() {
  timespec t;
  clock_gettime(CLOCK_REALTIME, &t);
  return static_cast<std::int64_t>(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

void FrameTrace::begin(const ros::Time& stamp) {
  if (!enabled()) return;
  open_ = false;
  if (used_ == capacity_) {
    ++overflow_;
    return;
  }
  rows_[used_ * (1 + stages_.size())] = static_cast<std::int64_t>(stamp.toNSec());
  ++used_;
  open_ = true;
}

void FrameTrace::markAt(std::size_t stage, std::int64_t wall_ns) {
  if (!open_ || stage >= stages_.size()) return;
  rows_[(used_ - 1) * (1 + stages_.size()) + 1 + stage] = wall_ns;
}

bool FrameTrace::write(std::string* why) {
  written_ = true;
  std::ofstream out(path_);
  out << "stamp_ns";
  for (const std::string& stage : stages_) out << ',' << stage << "_ns";
  out << '\n';
  const std::size_t width = 1 + stages_.size();
  for (std::size_t r = 0; r < used_; ++r) {
    for (std::size_t c = 0; c < width; ++c) out << (c ? "," : "") << rows_[r * width + c];
    out << '\n';
  }
  out.flush();
  if (!out) {
    if (why) *why = "cannot write the trace file " + path_ + ": " + std::strerror(errno);
    return false;
  }
  if (overflow_ > 0) {
    ROS_WARN("trace %s: %zu frames beyond its %zu were not recorded", path_.c_str(), overflow_,
             capacity_);
  }
  return true;
}

}  // namespace norm2tex
