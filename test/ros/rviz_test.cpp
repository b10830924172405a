// rostest (test/ros/rviz.test): rviz loads rviz/norm2tex.rviz cleanly against the running
// gripper_sim.launch. rviz runs on a virtual X screen for a fixed time:
//   xvfb-run -a -s "-screen 0 1280x800x24" timeout -s INT -k 10 12 rviz -d CONFIG __name:=...
// and the test checks that
//   - rviz started and stayed up until `timeout` stopped it: exit status 124 (what timeout
//     returns when the time ran out; rviz itself exits cleanly on the SIGINT, and xvfb-run
//     passes the status through). A crash gives 128+signal, a rviz that ignores SIGINT is
//     killed 10 s later (137), a rviz that exits early gives its own status;
//   - no line of its output carries a ROS "[ERROR]" or "[ WARN]" tag: an unknown display class
//     (plugin that does not load) is reported as "[ERROR] ... PluginlibFactory ...". Nothing
//     is filtered: a normal run prints only [ INFO] lines plus three untagged lines,
//       QStandardPaths: XDG_RUNTIME_DIR not set, defaulting to '/tmp/runtime-root'
//       [rospack] Error: no such package media_export
//       [librospack]: error while executing command
//     (Qt without a session, and rviz asking rospack for media_export plugins: harmless);
//   - the config's displays really run: while rviz is up, its node subscribes to both tactile
//     images and both marker topics (polled from the master's system state with a deadline).
//     rviz prints nothing for a YAML syntax error (its displays are then simply missing) or a
//     wrong topic (only a status in the GUI): this is what catches them. A missing config file
//     fails before rviz starts;
//   - the config's fixed frame exists in TF and connects to the gel frames (rviz only shows a
//     status in the GUI for a wrong fixed frame).
// NORM2TEX_RVIZ_CONFIG overrides the config path (to prove the test fails on a broken copy).
// Waits on conditions with deadlines; the only fixed time is rviz's 12 s run.
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <future>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <ros/master.h>
#include <ros/package.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include "wait_for.hpp"

namespace {

const char* const kRvizNode = "norm2tex_rviz_loads";
constexpr int kRvizSeconds = 12;
constexpr int kTimedOut = 124;  // timeout(1)'s exit status when the time ran out

// Conditions here ask the master: poll every 50 ms.
bool waitFor(const std::function<bool()>& done, double seconds) {
  return norm2tex::waitFor(done, seconds, 0.05);
}

std::string configPath() {
  const char* env = std::getenv("NORM2TEX_RVIZ_CONFIG");
  if (env && *env) return env;
  return ros::package::getPath("norm2tex") + "/rviz/norm2tex.rviz";
}

std::string shellQuote(const std::string& s) {
  std::string quoted = "'";
  for (char c : s) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

struct CommandResult {
  int status = -1;  // exit status of the command, -1: did not exit normally
  std::string output;
};

// Runs a shell command, returns its exit status and everything it printed (stdout + stderr).
CommandResult runCommand(const std::string& command) {
  CommandResult run;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return run;
  char buffer[4096];
  while (fgets(buffer, sizeof buffer, pipe)) run.output += buffer;
  const int status = pclose(pipe);
  run.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

// Topics `node` subscribes to, from the master's system state; empty if the master can't say.
std::set<std::string> subscriptionsOf(const std::string& node) {
  std::set<std::string> topics;
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  if (!ros::master::execute("getSystemState", args, result, payload, false)) return topics;
  if (payload.getType() != XmlRpc::XmlRpcValue::TypeArray || payload.size() < 2) return topics;
  XmlRpc::XmlRpcValue& subscribers = payload[1];  // [[topic, [node, ...]], ...]
  for (int i = 0; i < subscribers.size(); ++i) {
    XmlRpc::XmlRpcValue& nodes = subscribers[i][1];
    for (int j = 0; j < nodes.size(); ++j) {
      if (static_cast<std::string>(nodes[j]) == node) {
        topics.insert(static_cast<std::string>(subscribers[i][0]));
      }
    }
  }
  return topics;
}

// The lines of `output` with a ROS error or warning tag.
std::vector<std::string> errorAndWarningLines(const std::string& output) {
  std::vector<std::string> lines;
  std::istringstream in(output);
  for (std::string line; std::getline(in, line);) {
    if (line.find("[ERROR]") != std::string::npos || line.find("[ WARN]") != std::string::npos ||
        line.find("[FATAL]") != std::string::npos) {
      lines.push_back(line);
    }
  }
  return lines;
}

TEST(Rviz, LoadsTheConfigWithoutErrorsAndSubscribesToTheSimulation) {
  const std::string config = configPath();
  std::string text;
  {
    std::ifstream file(config);
    ASSERT_TRUE(file.good()) << "no rviz config " << config;
    std::stringstream content;
    content << file.rdbuf();
    text = content.str();
  }
  std::smatch fixed;
  ASSERT_TRUE(std::regex_search(text, fixed, std::regex(R"(Fixed Frame:\s*(\S+))")))
      << config << " has no Fixed Frame";
  const std::string fixed_frame = fixed[1];

  // The simulation is up: tactile images flow and TF knows the fixed frame and both gels.
  ros::NodeHandle nh;
  bool image = false;
  ros::Subscriber sub = nh.subscribe<sensor_msgs::Image>(
      "/digit_left/image_raw", 1, [&](const sensor_msgs::Image::ConstPtr&) { image = true; });
  ASSERT_TRUE(waitFor([&] { return image; }, 60.0)) << "no image on /digit_left/image_raw";
  sub.shutdown();
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer, nh);
  EXPECT_TRUE(waitFor(
      [&] {
        return buffer.canTransform(fixed_frame, "digit_left_gel", ros::Time(0)) &&
               buffer.canTransform(fixed_frame, "digit_right_gel", ros::Time(0));
      },
      10.0))
      << "fixed frame '" << fixed_frame << "' of " << config << " does not reach the gel frames";

  // rviz on a virtual screen for kRvizSeconds; its output is read on another thread while this
  // one watches the master.
  const std::string command = "xvfb-run -a -s '-screen 0 1280x800x24' timeout -s INT -k 10 " +
                              std::to_string(kRvizSeconds) + " rviz -d " + shellQuote(config) +
                              " __name:=" + kRvizNode;
  std::future<CommandResult> rviz = std::async(std::launch::async, runCommand, command);

  const std::set<std::string> expected = {"/digit_left/image_raw", "/digit_right/image_raw",
                                          "/contact_sim/markers", "/contact_sim/object_marker"};
  std::set<std::string> subscribed;
  const bool all_subscribed = waitFor(
      [&] {
        for (const std::string& topic : subscriptionsOf(std::string("/") + kRvizNode)) {
          subscribed.insert(topic);
        }
        for (const std::string& topic : expected) {
          if (!subscribed.count(topic)) return false;
        }
        return true;
      },
      kRvizSeconds - 1.0);

  const CommandResult run = rviz.get();
  SCOPED_TRACE("command: " + command + "\nrviz output:\n" + run.output);
  EXPECT_NE(run.output.find("rviz version"), std::string::npos) << "rviz did not start";
  EXPECT_EQ(run.status, kTimedOut) << "rviz did not stay up until timeout stopped it";
  for (const std::string& line : errorAndWarningLines(run.output)) {
    ADD_FAILURE() << "rviz: " << line;
  }
  EXPECT_TRUE(all_subscribed);
  for (const std::string& topic : expected) {
    EXPECT_TRUE(subscribed.count(topic)) << "rviz never subscribed to " << topic;
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rviz_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
