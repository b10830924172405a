#pragma once
// Waiting on a condition with a deadline while callbacks run (clients, tools and tests): never
// a sleep used to synchronise.

#include <functional>

#include <ros/callback_queue.h>
#include <ros/ros.h>

namespace norm2tex {

/// Spins the global queue until `done()` holds or `seconds` of wall time pass; returns done().
/// done() is checked after every batch of callbacks and at least every `poll_seconds`: raise it
/// when done() is costly (e.g. asks the master).
inline bool waitFor(const std::function<bool()>& done, double seconds,
                    double poll_seconds = 0.0005) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(seconds);
  ros::CallbackQueue* queue = ros::getGlobalCallbackQueue();
  while (ros::ok() && ros::WallTime::now() < deadline) {
    if (done()) return true;
    // Blocks until a callback is queued (or poll_seconds pass) and runs it at once, so a
    // message is handled when it arrives, not at the next poll.
    queue->callAvailable(ros::WallDuration(poll_seconds));
  }
  ros::spinOnce();
  return done();
}

}  // namespace norm2tex
