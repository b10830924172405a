#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <ros/callback_queue.h>
#include <ros/ros.h>

#include "norm2tex/FrameRendered.h"
#include "norm2tex/SimFrame.h"

namespace norm2tex {

/// FrameRendered.reason of the two announcements a participant of the lock-step makes besides
/// its answers: it is ready for frames (its first, latched message), or it leaves for good (a
/// recorder that has its samples or was stopped): the source stops waiting for it from then on,
/// including for the frames already in flight. A later "ready" under the same name joins again.
namespace lock_step {
constexpr const char* kReady = "ready";
constexpr const char* kLeaving = "leaving";
}  // namespace lock_step

/// Reads a frame source's ~renderers (names, no spaces), ~render_timeout (0, 600] s and
/// ~ready_timeout (0, 3600] s, keeping the given values as defaults; throws Error naming the
/// parameter at fault.
void readLockStepParams(const ros::NodeHandle& private_nh, std::vector<std::string>& renderers,
                        double& render_timeout, double& ready_timeout);

/// Synchronous frames for a frame source (contact_sim, probe_sim): publish a SimFrame, and have
/// every listed renderer (or recorder) answer it on ~rendered (FrameRendered), so nothing
/// downstream is skipped or raced. Up to `window` frames may be in flight (published, not yet
/// answered by everyone): 1 is strict lock-step (a policy reads the images of a frame before the
/// next), more lets the source, the renderers and a recorder work on consecutive frames at once
/// (a dataset: still nothing lost, drain() waits for the rest). Answers arrive on a queue of
/// their own, which the waiting caller serves itself: it may hold the thread a nodelet manager
/// would deliver them on, and no thread hand-over stands between an answer and the caller.
/// A participant that announces it is leaving (lock_step::kLeaving) is not waited for any more.
/// Not for concurrent callers (the frame sources call it from one thread at a time).
class LockStep {
 public:
  /// `renderers`: names whose answers every frame waits for (empty: publish without waiting);
  /// `timeout`: wall-clock seconds without any answer before giving up; `ready_timeout`: for the
  /// renderers to become ready (they may bake textures first); `owner`: the node's name.
  LockStep(const ros::NodeHandle& private_nh, std::vector<std::string> renderers, double timeout,
           double ready_timeout, std::string owner, int window = 1);
  ~LockStep();

  bool waits() const { return !renderers_.empty(); }
  /// Waits until every renderer has said it is ready (its latched first answer). Throws Error
  /// naming the missing ones after the ready timeout.
  void waitUntilReady();
  /// Publishes `frame` once fewer than `window` frames are in flight; with window 1 returns only
  /// when every renderer has answered it. Frames must come in increasing frame numbers. Returns
  /// how many images the renderers reported missing (each is warned about) among the frames
  /// answered meanwhile. Throws Error naming the renderers that did not answer in time.
  std::uint32_t publish(const ros::Publisher& frame_pub, const SimFrame& frame);
  /// Waits until every frame in flight is answered; returns missing images as publish() does.
  std::uint32_t drain(const ros::Publisher& frame_pub);
  /// Makes every wait, now or later, end at once with an Error ("... stopped"): a frame source
  /// that is being unloaded (or a node shutting down) must not sit out ~ready_timeout. Any thread.
  void cancel() { cancelled_ = true; }

 private:
  struct InFlight {
    SimFrame frame;
    std::set<std::string> answered;
  };
  void onRendered(const FrameRendered::ConstPtr& msg);
  /// Waits (mutex_ held through `lock`) until at most `limit` frames are in flight; offers the
  /// unanswered ones again every 0.2 s without progress (a subscription still connecting misses
  /// a message; renderers answer a repeated frame without rendering it twice).
  std::uint32_t waitForAnswers(std::unique_lock<std::mutex>& lock, const ros::Publisher& pub,
                               std::size_t limit);
  /// Handles answers on the calling thread (mutex_ held through `lock`, released while waiting)
  /// until done() or `seconds` pass; returns done().
  bool serveAnswersUntil(std::unique_lock<std::mutex>& lock, const std::function<bool()>& done,
                         double seconds);
  /// " name name": renderers that have not said they are ready. Call with mutex_ held.
  std::string notReady() const;
  /// Whether frames wait for the answers of `sensor` (a listed one): it has not left. Call with
  /// mutex_ held.
  bool waitsFor(const std::string& sensor) const;
  /// Lets the frames in flight that every participant still waited for has answered leave, in
  /// order. Call with mutex_ held.
  void releaseAnswered();

  std::vector<std::string> renderers_;
  double timeout_, ready_timeout_;
  std::string owner_;
  std::size_t window_;
  ros::CallbackQueue queue_;
  ros::Subscriber sub_;
  std::mutex mutex_;
  std::set<std::string> ready_;
  std::set<std::string> left_;  ///< listed participants that announced they are leaving
  std::map<std::uint64_t, InFlight> in_flight_;  ///< by frame number
  std::uint32_t missing_images_ = 0;             ///< reported since the last publish/drain
  std::uint64_t answers_ = 0;                    ///< answers to frames in flight, ever
  std::atomic<bool> cancelled_{false};
};

}  // namespace norm2tex
