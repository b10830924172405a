// rostest (dataset_recorder.test): recording in lock-step, Ctrl-C, and bad input;
// (dataset_recorder_leaves.test): a recorder that has its samples leaves the lock-step. Waits on
// conditions with deadlines.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/master.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>

#include "norm2tex/EpisodeInfo.h"
#include "norm2tex/Step.h"
#include "run_node.hpp"
#include "wait_for.hpp"

namespace {

using norm2tex::waitFor;

struct BagCounts {
  std::map<std::string, int> per_topic;
  std::map<std::string, std::vector<ros::Time>> image_stamps;  // per sensor
  std::string material;
};

BagCounts readBags(const std::string& dir) {
  BagCounts counts;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".bag") continue;
    rosbag::Bag bag(entry.path().string(), rosbag::bagmode::Read);
    for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
      ++counts.per_topic[m.getTopic()];
      if (const auto image = m.instantiate<sensor_msgs::Image>()) {
        if (m.getTopic().find("/image_raw") != std::string::npos) {
          counts.image_stamps[m.getTopic()].push_back(image->header.stamp);
        }
      }
      if (const auto info = m.instantiate<norm2tex::EpisodeInfo>())
        counts.material = info->material;
    }
  }
  return counts;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(DatasetRecorder, RecordsEveryLockStepFrameAndCtrlCLeavesAValidBag) {
  ros::NodeHandle nh;
  std::string main_dir;
  ASSERT_TRUE(nh.getParam("/dataset_recorder/output_dir", main_dir));
  const std::string sigint_dir = main_dir + "_sigint";

  // A second recorder, started here so the test can Ctrl-C it.
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    execl(NORM2TEX_DATASET_RECORDER_EXECUTABLE, NORM2TEX_DATASET_RECORDER_EXECUTABLE,
          "__name:=sigint_recorder", ("_output_dir:=" + sigint_dir).c_str(),
          "_answer_as:=sigint_recorder", "_samples:=0", static_cast<char*>(nullptr));
    _exit(127);
  }
  // However the test ends, the child does not outlive it.
  struct Reaper {
    pid_t pid;
    ~Reaper() {
      if (waitpid(pid, nullptr, WNOHANG) == 0) {
        kill(pid, SIGKILL);
        waitpid(pid, nullptr, 0);
      }
    }
  } reaper{pid};

  // 10 frames in lock-step: each waits for both renderers and both recorders.
  ros::ServiceClient step = nh.serviceClient<norm2tex::Step>("/contact_sim/step");
  ASSERT_TRUE(step.waitForExistence(ros::Duration(60.0)));
  norm2tex::Step srv;
  std::vector<ros::Time> stamps;
  for (int i = 0; i < 10; ++i) {
    srv.request.frames = 1;
    ASSERT_TRUE(step.call(srv)) << "frame " << i;
    EXPECT_EQ(srv.response.missing_images, 0u);
    stamps.push_back(srv.response.stamp);
  }

  // Ctrl-C: the bag is closed and indexed, the manifest written, exit status 0.
  ASSERT_EQ(kill(pid, SIGINT), 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  std::string info;
  EXPECT_EQ(
      norm2tex::test::runCommand("rosbag info " + sigint_dir + "/norm2tex_shard0_0.bag", info), 0)
      << info;
  EXPECT_NE(info.find("/digit_left/image_raw"), std::string::npos) << info;
  const BagCounts interrupted = readBags(sigint_dir);
  for (const char* topic : {"/digit_left/image_raw", "/digit_right/image_raw"}) {
    EXPECT_EQ(interrupted.image_stamps.at(topic), stamps) << topic;
  }
  // Stopped from outside: the reason docs/datasets.md gives for it, and not complete.
  const std::string interrupted_manifest = readFile(sigint_dir + "/norm2tex_shard0.yaml");
  EXPECT_NE(interrupted_manifest.find("stop_reason: shutdown\n"), std::string::npos)
      << interrupted_manifest;
  EXPECT_NE(interrupted_manifest.find("complete: false\n"), std::string::npos)
      << interrupted_manifest;

  // The main recorder's target was 20 images = these 10 frames: it closed by itself.
  ASSERT_TRUE(
      waitFor([&] { return std::filesystem::exists(main_dir + "/norm2tex_shard0.yaml"); }, 30.0));
  const BagCounts recorded = readBags(main_dir);
  for (const std::string sensor : {"digit_left", "digit_right"}) {
    EXPECT_EQ(recorded.image_stamps.at("/" + sensor + "/image_raw"), stamps) << sensor;
    EXPECT_EQ(recorded.per_topic.at("/" + sensor + "/camera_info"), 10) << sensor;
    EXPECT_EQ(recorded.per_topic.at("/" + sensor + "/depth"), 10) << sensor;
    EXPECT_EQ(recorded.per_topic.at("/" + sensor + "/contact"), 10) << sensor;
  }
  EXPECT_EQ(recorded.material, "wood");
  const std::string manifest = readFile(main_dir + "/norm2tex_shard0.yaml");
  EXPECT_NE(manifest.find("images: 20"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("complete: true"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("stop_reason: sample_target\n"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("'wood/variant0': 20"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("'/digit_left/depth': {received: 10, written: 10}"), std::string::npos)
      << manifest;
}

TEST(DatasetRecorder, BadInputExitsNamingTheCause) {
  struct Case {
    std::string args, expected;
  } cases[] = {
      {"_output_dir:=/proc/norm2tex_cannot_write", "/proc/norm2tex_cannot_write"},
      {"_output_dir:=/tmp/norm2tex_rec_bad _samples:=-5", "~samples"},
      {"_output_dir:=/tmp/norm2tex_rec_bad _compression:=zip", "lz4, bz2, none"},
      {"", "~output_dir"},
  };
  for (const Case& c : cases) {
    std::string output;
    EXPECT_EQ(
        norm2tex::test::runNodeUntilExit(NORM2TEX_DATASET_RECORDER_EXECUTABLE, c.args, output), 1)
        << c.args << ":\n"
        << output;
    EXPECT_NE(output.find(c.expected), std::string::npos) << c.args << ":\n" << output;
  }
}

// Once the recorder has its ~samples and stops, it leaves the lock-step (announced, then not
// waited for): the frame it never answers and every later ~step go on with the renderers alone,
// each returning well within ~render_timeout (waiting for the recorder would take all of it and
// fail), and both renderers still publish every frame's image.
TEST(RecorderFinished, LeavesTheLockStepAndLaterStepsGoOnWithTheRenderers) {
  ros::NodeHandle nh;
  std::string dir;
  ASSERT_TRUE(nh.getParam("/dataset_recorder/output_dir", dir));
  int samples = 0;
  ASSERT_TRUE(nh.getParam("/dataset_recorder/samples", samples));
  ASSERT_EQ(samples, 4);  // two frames of two sensors
  double render_timeout = 0.0;
  ASSERT_TRUE(nh.getParam("/contact_sim/render_timeout", render_timeout));

  std::map<std::string, std::set<ros::Time>> images;  // stamps received, per sensor
  std::vector<ros::Subscriber> subscribers;
  for (const std::string sensor : {"digit_left", "digit_right"}) {
    subscribers.push_back(nh.subscribe<sensor_msgs::Image>(
        "/" + sensor + "/image_raw", 100, [&images, sensor](const sensor_msgs::Image::ConstPtr& m) {
          images[sensor].insert(m->header.stamp);
        }));
  }
  ros::ServiceClient step = nh.serviceClient<norm2tex::Step>("/contact_sim/step");
  ASSERT_TRUE(step.waitForExistence(ros::Duration(60.0)));
  ASSERT_TRUE(waitFor(
      [&] {
        for (const ros::Subscriber& s : subscribers) {
          if (s.getNumPublishers() == 0) return false;
        }
        return true;
      },
      30.0));
  auto bothImagesOf = [&](const ros::Time& stamp) {
    return waitFor(
        [&] { return images["digit_left"].count(stamp) && images["digit_right"].count(stamp); },
        10.0);
  };

  // Three frames: the recorder writes the first two and stops; the third it never answers.
  norm2tex::Step srv;
  srv.request.frames = 3;
  ASSERT_TRUE(step.call(srv));
  ASSERT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.missing_images, 0u);
  EXPECT_TRUE(bothImagesOf(srv.response.stamp));
  const std::uint64_t first_frames = srv.response.frame;

  // The recorder finished as planned (its node gone: the manifest is written): its samples (and
  // the frames already begun), complete.
  ASSERT_TRUE(waitFor(
      [] {
        ros::V_string nodes;
        return ros::master::getNodes(nodes) &&
               std::find(nodes.begin(), nodes.end(), "/dataset_recorder") == nodes.end();
      },
      30.0, 0.05));
  const std::string manifest = readFile(dir + "/norm2tex_shard0.yaml");
  const std::size_t images_at = manifest.find("\nimages: ");
  ASSERT_NE(images_at, std::string::npos) << manifest;
  EXPECT_GE(std::stoi(manifest.substr(images_at + 9)), 4) << manifest;
  EXPECT_NE(manifest.find("stop_reason: sample_target\n"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("complete: true\n"), std::string::npos) << manifest;

  // Later steps, one frame and several: prompt, and the renderers answer each frame.
  for (const std::uint32_t frames : {1u, 1u, 1u, 5u}) {
    srv = norm2tex::Step();
    srv.request.frames = frames;
    const ros::WallTime start = ros::WallTime::now();
    ASSERT_TRUE(step.call(srv));
    const double seconds = (ros::WallTime::now() - start).toSec();
    ASSERT_TRUE(srv.response.success) << srv.response.message;
    EXPECT_LT(seconds, render_timeout) << frames << " frame(s)";
    EXPECT_EQ(srv.response.missing_images, 0u);
    EXPECT_TRUE(bothImagesOf(srv.response.stamp)) << srv.response.stamp;
  }
  EXPECT_EQ(srv.response.frame, first_frames + 1u + 1u + 1u + 5u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "dataset_recorder_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
