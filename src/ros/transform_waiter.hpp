#pragma once
// Waiting for a transform at an exact stamp, woken by the TF buffer when it arrives.

#include <condition_variable>
#include <mutex>
#include <set>
#include <string>

#include <ros/time.h>
#include <tf2/buffer_core.h>

namespace norm2tex {

/// Waits until a tf2 buffer can transform between two frames at one stamp (interpolated between
/// received transforms, never extrapolated). The buffer wakes the waiter from the thread that
/// inserts the transform (tf2's transformable requests, as tf2_ros::MessageFilter uses), so a
/// frame that arrives before its pose costs one thread wake-up, not a polling interval. One
/// waiter per buffer user; wait() is for one thread at a time.
class TransformWaiter {
 public:
  explicit TransformWaiter(tf2::BufferCore& buffer);
  ~TransformWaiter();
  TransformWaiter(const TransformWaiter&) = delete;
  TransformWaiter& operator=(const TransformWaiter&) = delete;

  /// True once `source` -> `target` at `stamp` is available; false after `timeout_s` seconds of
  /// wall time, with tf2's reason in `why` (if given).
  bool wait(const std::string& target, const std::string& source, const ros::Time& stamp,
            double timeout_s, std::string* why = nullptr);

 private:
  void onTransformable(tf2::TransformableRequestHandle request);

  tf2::BufferCore& buffer_;
  tf2::TransformableCallbackHandle callback_;
  std::mutex mutex_;
  std::condition_variable arrived_;
  std::set<tf2::TransformableRequestHandle> answered_;
};

}  // namespace norm2tex
