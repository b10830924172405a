// The launch files through roslaunch itself, on masters of their own: a mistake the launch can
// see before any node starts (an output directory that cannot be written, a missing file) ends
// roslaunch at once with a non-zero status and the reason; a finished recording ends quietly.
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "run_node.hpp"

namespace {
namespace fs = std::filesystem;

const fs::path& scratch() {
  static const fs::path dir = [] {
    const fs::path d =
        fs::temp_directory_path() / ("norm2tex_launch_test_" + std::to_string(getpid()));
    fs::remove_all(d);
    fs::create_directories(d / "ros_home");
    return d;
  }();
  return dir;
}

int freePort() {
  std::string output;
  EXPECT_EQ(
      norm2tex::test::runCommand(std::string(NORM2TEX_SOURCE_DIR) + "/scripts/free_port", output),
      0)
      << output;
  return std::stoi(output);
}

/// "Ends by itself": well under the 60 s the launch used to wait (probe_sim's ~ready_timeout)
/// and the 120 s cap below, with room for a loaded machine. Idle, these launches end in about
/// 1.3 s (roslaunch's own start-up); a deadline, not a speed requirement.
constexpr double kEndsBySelfSeconds = 30.0;

struct LaunchRun {
  int status = -1;
  double seconds = 0.0;
  std::string output;
};

/// Runs `roslaunch norm2tex <args>` on a master of its own until it exits (a hard cap of 120 s
/// stops a launch that would hang, which the assertions on `seconds` then report).
LaunchRun launch(const std::string& args) {
  const int port = freePort();
  std::ostringstream command;
  command << "ROS_HOME=" << (scratch() / "ros_home") << " ROS_MASTER_URI=http://localhost:" << port
          << " timeout -s INT -k 10 120 roslaunch -p " << port << " norm2tex " << args;
  LaunchRun run;
  const auto start = std::chrono::steady_clock::now();
  run.status = norm2tex::test::runCommand(command.str(), run.output);
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

/// The output has `line` as a line of its own (the reason is not buried in another message).
bool hasLine(const std::string& output, const std::string& line) {
  std::istringstream in(output);
  for (std::string l; std::getline(in, l);) {
    if (l == line) return true;
  }
  return false;
}

TEST(LaunchFailure, AnOutputDirectoryThatCannotBeWrittenEndsTheLaunchAtOnceWithTheReason) {
  const fs::path file = scratch() / "a_file";
  std::ofstream(file) << "not a directory\n";
  struct Case {
    std::string out, reason;
  } cases[] = {
      {(file / "out").string(), "record_dataset.launch: output directory '" +
                                    (file / "out").string() +
                                    "' cannot be written: Not a directory"},
      {"/proc/norm2tex_cannot_write",
       "record_dataset.launch: output directory "
       "'/proc/norm2tex_cannot_write' cannot be written"},
  };
  for (const Case& c : cases) {
    const LaunchRun run = launch("record_dataset.launch samples:=10 out:=" + c.out);
    EXPECT_NE(run.status, 0) << run.output;
    EXPECT_LT(run.seconds, kEndsBySelfSeconds) << run.output;
    EXPECT_NE(run.output.find(c.reason), std::string::npos) << run.output;
    // No node was started: nothing to tear down, no banner.
    EXPECT_EQ(run.output.find("REQUIRED process"), std::string::npos) << run.output;
  }
}

TEST(LaunchFailure, AMissingFileEndsTheLaunchAtOnceWithTheReason) {
  const std::string missing = (scratch() / "no_such_mesh.obj").string();
  const LaunchRun run = launch("gripper_sim.launch mesh:=" + missing + " scale:=0.001");
  EXPECT_NE(run.status, 0) << run.output;
  EXPECT_LT(run.seconds, kEndsBySelfSeconds) << run.output;
  EXPECT_TRUE(hasLine(run.output, "gripper_sim.launch: mesh file '" + missing + "' does not exist"))
      << run.output;
  const std::string no_map = (scratch() / "no_such_normals.png").string();
  const LaunchRun map_run = launch("gripper_sim.launch material:=none normal_map:=" + no_map);
  EXPECT_NE(map_run.status, 0) << map_run.output;
  EXPECT_TRUE(hasLine(map_run.output,
                      "gripper_sim.launch: normal_map file '" + no_map + "' does not exist"))
      << map_run.output;
}

TEST(LaunchFailure, ABadHandEndsHandSimLaunchWithTheReason) {
  // A missing hand yaml (norm2tex_launch_check) or one without sensors (scripts/hand_nodelets)
  // stops roslaunch while it reads the file; what only the simulation finds (a sensor on a link
  // the URDF lacks, a malformed URDF) ends it through the required manager, with hand_sim's
  // FATAL naming it.
  const std::string robots = std::string(NORM2TEX_SOURCE_DIR) + "/test/fixtures/robots/wsg50";
  const std::string missing = (scratch() / "no_such_hand.yaml").string();
  const LaunchRun run = launch("hand_sim.launch hand:=" + missing);
  EXPECT_NE(run.status, 0) << run.output;
  EXPECT_LT(run.seconds, kEndsBySelfSeconds) << run.output;
  EXPECT_NE(run.output.find("hand_sim.launch: hand file '" + missing + "' does not exist"),
            std::string::npos)
      << run.output;
  const fs::path no_sensors = scratch() / "no_sensors.yaml";
  std::ofstream(no_sensors) << "hand: {urdf: " << robots << "/wsg50_digit.urdf}\n";
  const LaunchRun sensors_run = launch("hand_sim.launch hand:=" + no_sensors.string());
  EXPECT_NE(sensors_run.status, 0) << sensors_run.output;
  EXPECT_NE(sensors_run.output.find("hand_nodelets: hand yaml '" + no_sensors.string() +
                                    "': sensors is required"),
            std::string::npos)
      << sensors_run.output;

  const fs::path link = scratch() / "bad_link.yaml";
  std::ofstream(link) << "hand: {urdf: " << robots
                      << "/wsg50_digit.urdf, package_paths: {wsg50: " << robots
                      << "}}\nsensors: [{name: digit_left, link: finger_left_tipp}]\n";
  const LaunchRun link_run = launch("hand_sim.launch mode:=synchronous hand:=" + link.string());
  EXPECT_LT(link_run.seconds, kEndsBySelfSeconds) << link_run.output;
  EXPECT_NE(link_run.output.find("sensor 'digit_left': link 'finger_left_tipp' is not in the hand"),
            std::string::npos)
      << link_run.output;
  EXPECT_NE(link_run.output.find("REQUIRED process [norm2tex_manager"), std::string::npos)
      << link_run.output;

  const fs::path urdf = scratch() / "broken.urdf";
  std::ofstream(urdf) << "<robot name=\"r\">\n<link name=\"a\">\n</robot>\n";
  const fs::path broken = scratch() / "broken_urdf.yaml";
  std::ofstream(broken) << "hand: {urdf: " << urdf.string() << "}\nsensors: [{name: d, link: a}]\n";
  const LaunchRun urdf_run = launch("hand_sim.launch nodelets:=false hand:=" + broken.string());
  EXPECT_LT(urdf_run.seconds, kEndsBySelfSeconds) << urdf_run.output;
  EXPECT_NE(urdf_run.output.find(urdf.string() + ":"), std::string::npos) << urdf_run.output;
  EXPECT_NE(urdf_run.output.find("not well-formed XML"), std::string::npos) << urdf_run.output;
  EXPECT_NE(urdf_run.output.find("REQUIRED process [hand_sim"), std::string::npos)
      << urdf_run.output;
}

TEST(LaunchFailure, ANodeletThatFailsAtStartUpEndsTheLaunchWithoutWaitingForTheOthers) {
  // A mistake only the recorder sees (its compression), loaded after probe_sim, which waits
  // for its renderers: the manager used to sit out probe_sim's ~ready_timeout (60 s) first.
  // roslaunch's own status stays 0 here (a required node died; roslaunch 1.15 does not pass
  // statuses on), so the reason is what the output must carry.
  const LaunchRun run = launch("record_dataset.launch samples:=10 compression:=zip out:=" +
                               (scratch() / "zip").string());
  EXPECT_LT(run.seconds, kEndsBySelfSeconds) << run.output;
  EXPECT_NE(run.output.find("~compression = 'zip' is not valid; valid: lz4, bz2, none"),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("REQUIRED process [norm2tex_manager"), std::string::npos) << run.output;
}

TEST(LaunchEnd, AFinishedRecordingEndsTheLaunchQuietly) {
  const fs::path out = scratch() / "recording";
  const LaunchRun run =
      launch("record_dataset.launch material:=wood variants:=1 samples:=10 out:=" + out.string());
  EXPECT_EQ(run.status, 0) << run.output;
  std::ifstream manifest(out / "norm2tex_shard0.yaml");
  std::stringstream text;
  text << manifest.rdbuf();
  EXPECT_NE(text.str().find("complete: true"), std::string::npos) << text.str();
  // A clean end is no failure: no red "REQUIRED process [...] has died!" banner.
  EXPECT_EQ(run.output.find("REQUIRED process"), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("has died"), std::string::npos) << run.output;
  // The recorder says when it stops, not "target 0 images".
  EXPECT_EQ(run.output.find("target 0 images"), std::string::npos) << run.output;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  const int result = RUN_ALL_TESTS();
  fs::remove_all(scratch());
  return result;
}
