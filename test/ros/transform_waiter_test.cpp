// TransformWaiter: a pose at an exact stamp, waited for without polling (no master needed).
#include <atomic>
#include <chrono>
#include <string>
#include <thread>

#include <ros/callback_queue.h>

#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <tf2/buffer_core.h>
#include <boost/make_shared.hpp>

#include "transform_waiter.hpp"

namespace norm2tex {
namespace {

geometry_msgs::TransformStamped objectInGel(double stamp_s, double x) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time(stamp_s);
  t.header.frame_id = "gel";
  t.child_frame_id = "object";
  t.transform.translation.x = x;
  t.transform.rotation.w = 1.0;
  return t;
}

TEST(TransformWaiterTest, ReturnsAtOnceWhenTheStampIsBetweenReceivedPoses) {
  tf2::BufferCore buffer;
  TransformWaiter waiter(buffer);
  buffer.setTransform(objectInGel(1.0, 0.0), "test");
  buffer.setTransform(objectInGel(3.0, 2.0), "test");
  EXPECT_TRUE(waiter.wait("gel", "object", ros::Time(2.0), 0.0));
  EXPECT_DOUBLE_EQ(buffer.lookupTransform("gel", "object", ros::Time(2.0)).transform.translation.x,
                   1.0);
}

TEST(TransformWaiterTest, WakesWhenThePoseArrivesFromAnotherThread) {
  tf2::BufferCore buffer;
  TransformWaiter waiter(buffer);
  buffer.setTransform(objectInGel(1.0, 0.0), "test");
  ASSERT_FALSE(buffer.canTransform("gel", "object", ros::Time(2.0)));
  for (int frame = 2; frame <= 4; ++frame) {  // several waits on one waiter
    std::thread publisher([&buffer, frame] {
      // Arrives while the waiter waits (a late TF message); the wait below has 30 s for it.
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      buffer.setTransform(objectInGel(frame, frame), "test");
    });
    EXPECT_TRUE(waiter.wait("gel", "object", ros::Time(frame), 30.0)) << "frame " << frame;
    publisher.join();
  }
}

TEST(TransformWaiterTest, NeverExtrapolatesAndGivesTheReasonAfterTheTimeout) {
  tf2::BufferCore buffer;
  TransformWaiter waiter(buffer);
  buffer.setTransform(objectInGel(1.0, 0.0), "test");
  buffer.setTransform(objectInGel(2.0, 1.0), "test");
  std::string why;
  EXPECT_FALSE(waiter.wait("gel", "object", ros::Time(2.5), 0.05, &why));  // future: not yet
  EXPECT_NE(why.find("extrapolation"), std::string::npos) << why;
  why.clear();
  EXPECT_FALSE(waiter.wait("gel", "object", ros::Time(0.5), 0.05, &why));  // before the data
  EXPECT_NE(why.find("past"), std::string::npos) << why;
  why.clear();
  EXPECT_FALSE(waiter.wait("gel", "nowhere", ros::Time(1.5), 0.05, &why));
  EXPECT_NE(why.find("nowhere"), std::string::npos) << why;
  // A pose that arrives after a wait gave up does not confuse the next wait.
  buffer.setTransform(objectInGel(3.0, 2.0), "test");
  EXPECT_TRUE(waiter.wait("gel", "object", ros::Time(2.5), 0.0));
}

/// A TF message waiting in a TransformListener's queue: inserted by whoever serves the queue.
class QueuedPose : public ros::CallbackInterface {
 public:
  QueuedPose(tf2::BufferCore& buffer, geometry_msgs::TransformStamped pose,
             std::thread::id* inserted_by)
      : buffer_(buffer), pose_(std::move(pose)), inserted_by_(inserted_by) {}
  CallResult call() override {
    buffer_.setTransform(pose_, "test");
    if (inserted_by_ != nullptr) *inserted_by_ = std::this_thread::get_id();
    return Success;
  }

 private:
  tf2::BufferCore& buffer_;
  geometry_msgs::TransformStamped pose_;
  std::thread::id* inserted_by_;
};

TEST(TransformWaiterTest, WithItsQueueTheWaitingThreadInsertsThePosesItself) {
  tf2::BufferCore buffer;
  ros::CallbackQueue tf_queue;
  TransformWaiter waiter(buffer, tf_queue);
  std::thread::id inserted_by;
  // Published before the frame: already queued when the frame is handled, no wait at all.
  tf_queue.addCallback(boost::make_shared<QueuedPose>(buffer, objectInGel(1.0, 0.0), nullptr));
  tf_queue.addCallback(boost::make_shared<QueuedPose>(buffer, objectInGel(2.0, 1.0), &inserted_by));
  EXPECT_TRUE(waiter.wait("gel", "object", ros::Time(1.5), 0.0));
  EXPECT_EQ(inserted_by, std::this_thread::get_id()) << "inserted on the waiting thread";
  // Arriving later (a TF message on the wire): the wait returns once it is queued.
  for (int frame = 3; frame <= 5; ++frame) {
    std::thread transport([&, frame] {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));  // the message is late
      tf_queue.addCallback(
          boost::make_shared<QueuedPose>(buffer, objectInGel(frame, frame), &inserted_by));
    });
    EXPECT_TRUE(waiter.wait("gel", "object", ros::Time(frame), 30.0)) << "frame " << frame;
    EXPECT_EQ(inserted_by, std::this_thread::get_id());
    transport.join();
  }
  // Never extrapolated: past the last pose it times out with tf2's reason.
  std::string why;
  EXPECT_FALSE(waiter.wait("gel", "object", ros::Time(5.5), 0.05, &why));
  EXPECT_NE(why.find("extrapolation"), std::string::npos) << why;
  // insertReceived() empties the queue without waiting.
  tf_queue.addCallback(boost::make_shared<QueuedPose>(buffer, objectInGel(6.0, 6.0), nullptr));
  waiter.insertReceived();
  EXPECT_TRUE(tf_queue.empty());
  EXPECT_TRUE(buffer.canTransform("gel", "object", ros::Time(5.5)));
}

TEST(TransformWaiterTest, AWaitReturnsWhenItsQueueIsDisabledAtShutdown) {
  // The renderer disables its TF queue when it is destroyed: a wait under way must end then,
  // not run to its timeout (the destructor joins the thread that waits).
  tf2::BufferCore buffer;
  ros::CallbackQueue tf_queue;
  TransformWaiter waiter(buffer, tf_queue);
  buffer.setTransform(objectInGel(1.0, 0.0), "test");
  std::thread owner([&tf_queue] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // the wait is under way
    tf_queue.disable();
  });
  std::string why;
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(waiter.wait("gel", "object", ros::Time(2.0), 30.0, &why));
  const double waited =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  owner.join();
  EXPECT_EQ(why, "shutting down");
  EXPECT_LT(waited, 15.0) << "the wait ran towards its 30 s timeout";
}

}  // namespace
}  // namespace norm2tex
