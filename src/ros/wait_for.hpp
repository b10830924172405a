#pragma once
// Waiting on a condition with a deadline while callbacks run (clients, tools and tests): never
// a sleep used to synchronise.

#include <functional>

#include <ros/ros.h>

namespace norm2tex {

/// Spins the global queue until `done()` holds or `seconds` of wall time pass; returns done().
inline bool waitFor(const std::function<bool()>& done, double seconds) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::ok() && ros::WallTime::now() < deadline) {
    ros::spinOnce();
    if (done()) return true;
    ros::WallDuration(0.0005).sleep();
  }
  ros::spinOnce();
  return done();
}

}  // namespace norm2tex
