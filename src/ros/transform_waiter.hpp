#pragma once
// Waiting for a transform at an exact stamp, woken by the TF buffer when it arrives.

#include <condition_variable>
#include <mutex>
#include <set>
#include <string>

#include <ros/callback_queue.h>
#include <ros/time.h>
#include <tf2/buffer_core.h>

namespace norm2tex {

/// Waits until a tf2 buffer can transform between two frames at one stamp (interpolated between
/// received transforms, never extrapolated). One waiter per buffer user; wait() is for one
/// thread at a time. Two ways to be woken:
/// - By the thread that inserts the transform (a TransformListener with its own thread): tf2's
///   transformable requests, as tf2_ros::MessageFilter uses, so a frame that arrives before its
///   pose costs one thread wake-up, not a polling interval.
/// - With `tf_queue`, the callback queue of a TransformListener without a thread: the waiting
///   thread inserts the TF messages itself, in arrival order, as it waits. A pose published just
///   before its frame is then already in the queue when the frame is handled: no other thread
///   has to be scheduled first (on two busy cores that hand-over took up to a few ms).
class TransformWaiter {
 public:
  explicit TransformWaiter(tf2::BufferCore& buffer);
  TransformWaiter(tf2::BufferCore& buffer, ros::CallbackQueue& tf_queue);
  ~TransformWaiter();
  TransformWaiter(const TransformWaiter&) = delete;
  TransformWaiter& operator=(const TransformWaiter&) = delete;

  /// True once `source` -> `target` at `stamp` is available; false after `timeout_s` seconds of
  /// wall time, with tf2's reason in `why` (if given).
  bool wait(const std::string& target, const std::string& source, const ros::Time& stamp,
            double timeout_s, std::string* why = nullptr);

  /// With a `tf_queue`: inserts the TF messages received so far, without waiting (a caller that
  /// skips a frame keeps the queue short).
  void insertReceived();

 private:
  void onTransformable(tf2::TransformableRequestHandle request);
  bool waitServingQueue(const std::string& target, const std::string& source,
                        const ros::Time& stamp, double timeout_s, std::string* why);

  tf2::BufferCore& buffer_;
  ros::CallbackQueue* tf_queue_ = nullptr;
  tf2::TransformableCallbackHandle callback_;
  std::mutex mutex_;
  std::condition_variable arrived_;
  std::set<tf2::TransformableRequestHandle> answered_;
};

}  // namespace norm2tex
