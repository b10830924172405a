#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <thread>

#include <ros/time.h>

namespace norm2tex {

/// Calls `tick` on a thread of its own at the absolute wall-clock times now + k * period (the
/// real-time frames of contact_sim and hand_sim), slept to with clock_nanosleep: one wake-up
/// per frame, straight into the physics. (A ros::WallTimer went through ROS's timer thread and
/// a callback queue: two thread hand-overs, ~0.25 ms late at the median here.) ros::WallTime
/// is CLOCK_REALTIME, so the ticks are wall-clock stamps. A tick that ran late is not repeated;
/// far behind (a stalled machine, more than four periods) the grid skips ahead: the tick
/// decides what to do with the frames that were due (see its `scheduled` time).
class WallClockGrid {
 public:
  /// `scheduled`: the tick's time on the grid; `woke_ns`: FrameTrace::now() at the wake-up when
  /// `measure_wake`, else 0.
  using Tick = std::function<void(const ros::WallTime& scheduled, std::int64_t woke_ns)>;

  /// Starts ticking one period from now.
  WallClockGrid(std::int64_t period_ns, Tick tick, bool measure_wake = false);
  /// Stops and waits for a running tick to end.
  ~WallClockGrid();
  WallClockGrid(const WallClockGrid&) = delete;
  WallClockGrid& operator=(const WallClockGrid&) = delete;

  /// No tick starts after this returns (one running may still end; the destructor waits).
  void requestStop() { stop_ = true; }

 private:
  void run();

  const std::int64_t period_ns_;
  const Tick tick_;
  const bool measure_wake_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace norm2tex
