#include "lock_step.hpp"

#include <chrono>

#include "norm2tex/common/error.hpp"
#include "params.hpp"

namespace norm2tex {

LockStep::LockStep(const ros::NodeHandle& private_nh, std::vector<std::string> renderers,
                   double timeout, double ready_timeout, std::string owner)
    : renderers_(std::move(renderers)),
      timeout_(timeout),
      ready_timeout_(ready_timeout),
      owner_(std::move(owner)) {
  if (renderers_.empty()) return;
  ros::NodeHandle nh(private_nh);
  nh.setCallbackQueue(&queue_);
  // One topic for every renderer's answers: answers name their sensor.
  sub_ = nh.subscribe("rendered", 100, &LockStep::onRendered, this);
  spinner_ = std::make_unique<ros::AsyncSpinner>(1, &queue_);
  spinner_->start();
}

LockStep::~LockStep() {
  if (spinner_) spinner_->stop();
}

void LockStep::onRendered(const FrameRendered::ConstPtr& msg) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    last_[msg->sensor] = *msg;  // a renderer's first message (latched) says it is ready
  }
  cv_.notify_all();
}

bool LockStep::hasAnswered(const std::string& sensor, const SimFrame* frame) const {
  const auto it = last_.find(sensor);
  if (it == last_.end()) return false;
  return frame == nullptr ||
         (it->second.frame == frame->frame && it->second.header.stamp == frame->header.stamp);
}

std::string LockStep::missing(const SimFrame* frame) const {
  std::string names;
  for (const std::string& sensor : renderers_) {
    if (!hasAnswered(sensor, frame)) names += " " + sensor;
  }
  return names;
}

void LockStep::waitUntilReady() {
  if (!waits()) return;
  std::unique_lock<std::mutex> lock(mutex_);
  auto ready = [&] { return missing(nullptr).empty(); };
  if (cv_.wait_for(lock, std::chrono::duration<double>(ready_timeout_), ready)) return;
  throw Error(owner_ + ": renderers" + missing(nullptr) +
              " not ready within ~ready_timeout = " + ros_params::text(ready_timeout_) +
              " s (are the tactile_renderer nodes running?)");
}

std::uint32_t LockStep::publishAndWait(const ros::Publisher& frame_pub, const SimFrame& frame) {
  if (!waits()) {
    frame_pub.publish(frame);
    return 0;
  }
  waitUntilReady();
  frame_pub.publish(frame);
  std::unique_lock<std::mutex> lock(mutex_);
  auto all_answered = [&] { return missing(&frame).empty(); };
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_);
  bool all = false;
  while (!(all = cv_.wait_for(lock, std::chrono::milliseconds(200), all_answered)) &&
         std::chrono::steady_clock::now() < deadline && ros::ok()) {
    frame_pub.publish(frame);
  }
  if (!all) {
    throw Error("no answer from" + missing(&frame) +
                " within ~render_timeout = " + ros_params::text(timeout_) + " s");
  }
  std::uint32_t missing_images = 0;
  for (const std::string& sensor : renderers_) {
    const FrameRendered& answer = last_.at(sensor);
    if (!answer.published) {
      ++missing_images;
      ROS_WARN("%s: %s published no image for frame %lu: %s", owner_.c_str(), sensor.c_str(),
               static_cast<unsigned long>(frame.frame), answer.reason.c_str());
    }
  }
  return missing_images;
}

}  // namespace norm2tex
