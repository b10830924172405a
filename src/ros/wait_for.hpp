#pragma once
// Waiting on a condition with a deadline while callbacks run (clients, tools and tests): never
// a sleep used to synchronise.

#include <functional>

#include <ros/ros.h>

namespace norm2tex {

/// Spins the global queue until `done()` holds or `seconds` of wall time pass; returns done().
/// `poll_seconds` between checks: raise it when done() is costly (e.g. asks the master).
inline bool waitFor(const std::function<bool()>& done, double seconds,
                    double poll_seconds = 0.0005) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::ok() && ros::WallTime::now() < deadline) {
    ros::spinOnce();
    if (done()) return true;
    ros::WallDuration(poll_seconds).sleep();
  }
  ros::spinOnce();
  return done();
}

}  // namespace norm2tex
