#include "wall_clock_grid.hpp"

#include <time.h>

#include <ros/init.h>

#include "frame_trace.hpp"

namespace norm2tex {

WallClockGrid::WallClockGrid(std::int64_t period_ns, Tick tick, bool measure_wake)
    : period_ns_(period_ns), tick_(std::move(tick)), measure_wake_(measure_wake) {
  thread_ = std::thread(&WallClockGrid::run, this);
}

WallClockGrid::~WallClockGrid() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void WallClockGrid::run() {
  const std::int64_t period = period_ns_;
  std::int64_t next = ros::WallTime::now().toNSec() + period;
  while (!stop_ && ros::ok()) {
    timespec when;
    when.tv_sec = static_cast<time_t>(next / 1'000'000'000);
    when.tv_nsec = static_cast<long>(next % 1'000'000'000);
    if (clock_nanosleep(CLOCK_REALTIME, TIMER_ABSTIME, &when, nullptr) != 0) continue;  // EINTR
    if (stop_) break;
    const std::int64_t woke_ns = measure_wake_ ? FrameTrace::now() : 0;
    ros::WallTime scheduled;
    scheduled.fromNSec(static_cast<std::uint64_t>(next));
    tick_(scheduled, woke_ns);
    next += period;
    const std::int64_t now = ros::WallTime::now().toNSec();
    if (next < now - 4 * period) next += ((now - next) / period) * period;
  }
}

}  // namespace norm2tex
