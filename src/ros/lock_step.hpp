#pragma once

#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <ros/callback_queue.h>
#include <ros/ros.h>

#include "norm2tex/FrameRendered.h"
#include "norm2tex/SimFrame.h"

namespace norm2tex {

/// Synchronous frames for a frame source (contact_sim, probe_sim): publish a SimFrame, then wait
/// until every listed renderer (or recorder) has answered it on ~rendered (FrameRendered), so
/// nothing downstream is skipped or raced. Answers arrive on a queue and thread of their own:
/// the waiting caller may hold the thread a nodelet manager would deliver them on.
class LockStep {
 public:
  /// `renderers`: names whose answers every frame waits for (empty: publish without waiting);
  /// `timeout`: wall-clock seconds to wait for each answer; `ready_timeout`: for the renderers
  /// to become ready (they may bake textures first); `owner`: the node's name, for errors.
  LockStep(const ros::NodeHandle& private_nh, std::vector<std::string> renderers, double timeout,
           double ready_timeout, std::string owner);
  ~LockStep();

  bool waits() const { return !renderers_.empty(); }
  /// Waits until every renderer has said it is ready (its latched first answer). Throws Error
  /// naming the missing ones after the ready timeout.
  void waitUntilReady();
  /// Publishes `frame` and waits for every renderer's answer to it, offering it again every
  /// 0.2 s (a subscription still connecting misses a message; renderers answer a repeated frame
  /// without rendering it twice). Returns how many renderers published no image for it (each is
  /// warned about). Throws Error naming the renderers that did not answer in time.
  std::uint32_t publishAndWait(const ros::Publisher& frame_pub, const SimFrame& frame);

 private:
  void onRendered(const FrameRendered::ConstPtr& msg);
  /// Has `sensor` answered `frame` (null: said anything, i.e. is ready)? Call with mutex_ held.
  bool hasAnswered(const std::string& sensor, const SimFrame* frame) const;
  /// " name name": the renderers that have not answered `frame`. Call with mutex_ held.
  std::string missing(const SimFrame* frame) const;

  std::vector<std::string> renderers_;
  double timeout_, ready_timeout_;
  std::string owner_;
  ros::CallbackQueue queue_;
  ros::Subscriber sub_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::map<std::string, FrameRendered> last_;  ///< latest answer of each renderer
  std::unique_ptr<ros::AsyncSpinner> spinner_;  // last: stopped first
};

}  // namespace norm2tex
