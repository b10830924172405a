#include "transform_waiter.hpp"

#include <algorithm>
#include <chrono>

namespace norm2tex {
namespace {
// addTransformableRequest's answers: available now, or older than the buffer keeps.
constexpr tf2::TransformableRequestHandle kAvailableNow = 0;
constexpr tf2::TransformableRequestHandle kTooOld = 0xffffffffffffffffULL;
// tf2 tests pending requests only when a transform is inserted: one inserted between our check
// and our request would be seen at the next insertion only. Re-checking this often bounds that.
constexpr std::chrono::milliseconds kRecheck(1);
}  // namespace

TransformWaiter::TransformWaiter(tf2::BufferCore& buffer)
    : buffer_(buffer),
      callback_(buffer.addTransformableCallback(
          [this](tf2::TransformableRequestHandle request, const std::string&, const std::string&,
                 ros::Time, tf2::TransformableResult) { onTransformable(request); })) {}

TransformWaiter::TransformWaiter(tf2::BufferCore& buffer, ros::CallbackQueue& tf_queue)
    : TransformWaiter(buffer) {
  tf_queue_ = &tf_queue;
}

TransformWaiter::~TransformWaiter() { buffer_.removeTransformableCallback(callback_); }

void TransformWaiter::insertReceived() {
  if (tf_queue_ != nullptr) tf_queue_->callAvailable();
}

bool TransformWaiter::waitServingQueue(const std::string& target, const std::string& source,
                                       const ros::Time& stamp, double timeout_s, std::string* why) {
  tf_queue_->callAvailable();
  if (buffer_.canTransform(target, source, stamp)) return true;
  const std::chrono::steady_clock::time_point deadline =
      std::chrono::steady_clock::now() +
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(std::max(0.0, timeout_s)));
  for (auto now = std::chrono::steady_clock::now(); now < deadline;
       now = std::chrono::steady_clock::now()) {
    // Returns as soon as a message is queued (or after the wait): no polling interval.
    const std::chrono::duration<double> left = deadline - now;
    tf_queue_->callAvailable(ros::WallDuration(left.count()));
    if (buffer_.canTransform(target, source, stamp)) return true;
    if (!tf_queue_->isEnabled()) {  // disabled: its owner is shutting down
      if (why != nullptr) *why = "shutting down";
      return false;
    }
  }
  return buffer_.canTransform(target, source, stamp, why);
}

void TransformWaiter::onTransformable(tf2::TransformableRequestHandle request) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    answered_.insert(request);
  }
  arrived_.notify_all();
}

bool TransformWaiter::wait(const std::string& target, const std::string& source,
                           const ros::Time& stamp, double timeout_s, std::string* why) {
  if (tf_queue_ != nullptr) return waitServingQueue(target, source, stamp, timeout_s, why);
  if (buffer_.canTransform(target, source, stamp)) return true;
  const std::chrono::steady_clock::time_point deadline =
      std::chrono::steady_clock::now() +
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(std::max(0.0, timeout_s)));
  const tf2::TransformableRequestHandle request =
      buffer_.addTransformableRequest(callback_, target, source, stamp);
  if (request != kAvailableNow && request != kTooOld) {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!answered_.count(request)) {
      const auto now = std::chrono::steady_clock::now();
      if (now >= deadline) break;
      arrived_.wait_until(lock, std::min(deadline, now + kRecheck));
      if (answered_.count(request)) break;
      lock.unlock();
      const bool available = buffer_.canTransform(target, source, stamp);
      lock.lock();
      if (available) break;
    }
    // This answer, and any that came after an earlier wait gave up (handles only grow).
    answered_.erase(answered_.begin(), answered_.upper_bound(request));
    lock.unlock();
    buffer_.cancelTransformableRequest(request);  // no-op once answered
  }
  return buffer_.canTransform(target, source, stamp, why);
}

}  // namespace norm2tex
