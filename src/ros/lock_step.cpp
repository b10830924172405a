#include "lock_step.hpp"

#include <algorithm>
#include <chrono>

#include "norm2tex/common/error.hpp"
#include "params.hpp"

namespace norm2tex {

void readLockStepParams(const ros::NodeHandle& pnh, std::vector<std::string>& renderers,
                        double& render_timeout, double& ready_timeout) {
  using ros_params::badParameter;
  using ros_params::readParam;
  using ros_params::text;
  readParam(pnh, "renderers", renderers, renderers);
  for (const std::string& name : renderers) {
    if (name.empty() || name.find(' ') != std::string::npos) {
      badParameter("renderers", "['" + name + "', ...]", "names such as digit_left");
    }
  }
  readParam(pnh, "render_timeout", render_timeout, render_timeout);
  if (!(render_timeout > 0.0 && render_timeout <= 600.0)) {
    badParameter("render_timeout", text(render_timeout), "(0, 600] s");
  }
  readParam(pnh, "ready_timeout", ready_timeout, ready_timeout);
  if (!(ready_timeout > 0.0 && ready_timeout <= 3600.0)) {
    badParameter("ready_timeout", text(ready_timeout), "(0, 3600] s");
  }
}

LockStep::LockStep(const ros::NodeHandle& private_nh, std::vector<std::string> renderers,
                   double timeout, double ready_timeout, std::string owner, int window)
    : renderers_(std::move(renderers)),
      timeout_(timeout),
      ready_timeout_(ready_timeout),
      owner_(std::move(owner)),
      window_(static_cast<std::size_t>(std::max(1, window))) {
  if (renderers_.empty()) return;
  ros::NodeHandle nh(private_nh);
  nh.setCallbackQueue(&queue_);
  // One topic for every renderer's answers: answers name their sensor.
  sub_ = nh.subscribe("rendered", 1000, &LockStep::onRendered, this,
                      ros::TransportHints().tcpNoDelay());
}

LockStep::~LockStep() = default;

bool LockStep::serveAnswersUntil(std::unique_lock<std::mutex>& lock,
                                 const std::function<bool()>& done, double seconds) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!done()) {
    // Shutting down (ros::shutdown, e.g. after another nodelet's start-up failed) or unloaded:
    // nobody will answer any more.
    if (cancelled_ || !ros::ok()) throw Error(owner_ + ": stopped while waiting for the renderers");
    const double left =
        std::chrono::duration<double>(until - std::chrono::steady_clock::now()).count();
    if (left <= 0.0) return false;
    lock.unlock();
    // Wakes as soon as an answer is queued and handles it on this thread.
    queue_.callAvailable(ros::WallDuration(std::min(left, 0.05)));
    lock.lock();
  }
  return true;
}

void LockStep::onRendered(const FrameRendered::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  const bool listed =
      std::find(renderers_.begin(), renderers_.end(), msg->sensor) != renderers_.end();
  if (msg->reason == lock_step::kLeaving) {
    // Announced, then not waited for: neither for the next frames nor for those in flight.
    if (listed && left_.insert(msg->sensor).second) {
      ROS_INFO("%s: %s left the lock-step; frames no longer wait for it", owner_.c_str(),
               msg->sensor.c_str());
      ++answers_;  // progress: the frames it held may leave now
      releaseAnswered();
    }
    return;
  }
  ready_.insert(msg->sensor);  // a renderer's first message (latched) says it is ready
  if (msg->reason == lock_step::kReady && left_.erase(msg->sensor)) {
    ROS_INFO("%s: %s joined the lock-step again", owner_.c_str(), msg->sensor.c_str());
  }
  const auto it = in_flight_.find(msg->frame);
  if (listed && it != in_flight_.end() && it->second.frame.header.stamp == msg->header.stamp &&
      it->second.answered.insert(msg->sensor).second) {
    ++answers_;
    if (!msg->published) {
      ++missing_images_;
      ROS_WARN("%s: %s published no image for frame %lu: %s", owner_.c_str(), msg->sensor.c_str(),
               static_cast<unsigned long>(msg->frame), msg->reason.c_str());
    }
    releaseAnswered();
  }
}

bool LockStep::waitsFor(const std::string& sensor) const { return !left_.count(sensor); }

void LockStep::releaseAnswered() {
  // Frames leave in order once every participant still waited for has answered them.
  while (!in_flight_.empty()) {
    const std::set<std::string>& answered = in_flight_.begin()->second.answered;
    for (const std::string& r : renderers_) {
      if (waitsFor(r) && !answered.count(r)) return;
    }
    in_flight_.erase(in_flight_.begin());
  }
}

std::string LockStep::notReady() const {
  std::string names;
  for (const std::string& sensor : renderers_) {
    if (waitsFor(sensor) && !ready_.count(sensor)) names += " " + sensor;
  }
  return names;
}

void LockStep::waitUntilReady() {
  if (!waits()) return;
  std::unique_lock<std::mutex> lock(mutex_);
  auto ready = [&] { return notReady().empty(); };
  if (serveAnswersUntil(lock, ready, ready_timeout_)) return;
  throw Error(owner_ + ": renderers" + notReady() + " not ready within ~ready_timeout = " +
              ros_params::text(ready_timeout_) + " s (are the tactile_renderer nodes running?)");
}

std::uint32_t LockStep::waitForAnswers(std::unique_lock<std::mutex>& lock,
                                       const ros::Publisher& pub, std::size_t limit) {
  auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_);
  std::uint64_t seen = answers_;
  while (in_flight_.size() > limit) {
    if (serveAnswersUntil(
            lock, [&] { return in_flight_.size() <= limit; }, 0.2))
      break;
    if (!ros::ok()) throw Error(owner_ + ": shutting down");
    if (answers_ != seen) {  // progress: the timeout counts from the latest answer
      seen = answers_;
      deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_);
    } else if (std::chrono::steady_clock::now() > deadline) {
      std::string missing;
      const InFlight& oldest = in_flight_.begin()->second;
      for (const std::string& r : renderers_) {
        if (waitsFor(r) && !oldest.answered.count(r)) missing += " " + r;
      }
      throw Error("no answer from" + missing + " to frame " + std::to_string(oldest.frame.frame) +
                  " within ~render_timeout = " + ros_params::text(timeout_) + " s");
    }
    for (const auto& [number, f] : in_flight_) pub.publish(f.frame);  // offer them again
  }
  const std::uint32_t missing = missing_images_;
  missing_images_ = 0;
  return missing;
}

std::uint32_t LockStep::publish(const ros::Publisher& frame_pub, const SimFrame& frame) {
  if (!waits()) {
    frame_pub.publish(frame);
    return 0;
  }
  waitUntilReady();
  std::unique_lock<std::mutex> lock(mutex_);
  std::uint32_t missing = waitForAnswers(lock, frame_pub, window_ - 1);
  in_flight_[frame.frame] = InFlight{frame, {}};
  frame_pub.publish(frame);
  releaseAnswered();  // every participant may have left: then nobody answers
  if (window_ == 1) missing += waitForAnswers(lock, frame_pub, 0);
  return missing;
}

std::uint32_t LockStep::drain(const ros::Publisher& frame_pub) {
  if (!waits()) return 0;
  std::unique_lock<std::mutex> lock(mutex_);
  return waitForAnswers(lock, frame_pub, 0);
}

}  // namespace norm2tex
