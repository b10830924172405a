// Every program's command line, run as a user runs it: --help (whole sentences, every option the
// synopsis names documented) and the bad command lines of the programs without a CLI test of
// their own (norm2tex_wake_bench, norm2tex_ros_bench, norm2tex_grasp_demo), which once read
// numbers with atoi or took "nan": a clear error and exit 2 at once, without a ROS master.
#include <algorithm>
#include <filesystem>
#include <regex>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "cli_runner.hpp"

namespace {

using norm2tex::test::CliRun;
using norm2tex::test::CliTest;

std::string program(const std::string& name) {
  return std::string(NORM2TEX_PROGRAMS_DIR) + "/" + name;
}

/// Runs a program with no ROS master in reach (port 1 is never one) and a time limit: a program
/// that took a bad argument and went on to wait for a master fails the test, it does not hang it.
CliRun run(const std::string& name, const std::string& arguments) {
  return norm2tex::test::runCommand("ROS_MASTER_URI=http://localhost:1 timeout 20 " + program(name),
                                    arguments);
}

/// Exit 2, the one-line error first (naming `fragment`), then the usage.
void expectUsageError(const std::string& name, const std::string& arguments,
                      const std::string& fragment) {
  const CliRun result = run(name, arguments);
  EXPECT_EQ(result.exit_code, 2) << name << " " << arguments << "\n" << result.output;
  EXPECT_EQ(result.output.rfind(name + ": error: ", 0), 0u) << result.output;
  EXPECT_NE(result.output.substr(0, result.output.find('\n')).find(fragment), std::string::npos)
      << "lacks '" << fragment << "':\n"
      << result.output;
  EXPECT_NE(result.output.find("\nusage: "), std::string::npos) << result.output;
}

const char* const kPrograms[] = {
    "norm2tex_bake",      "norm2tex_render",        "norm2tex_texgen",
    "norm2tex_calibrate", "norm2tex_match_texture", "norm2tex_gripper_sweep",
    "norm2tex_export",    "norm2tex_grasp_demo",    "norm2tex_make_demo_normal_map",
    "norm2tex_ros_bench", "norm2tex_wake_bench",    "norm2tex_launch_check",
    "nodelet_group"};

TEST(ProgramsCli, EveryHelpHasWholeSentencesAndEveryOption) {
  for (const std::string name : kPrograms) {
    for (const std::string flag : {"--help", "-h"}) {
      const CliRun help = run(name, flag);
      EXPECT_EQ(help.exit_code, 0) << name << " " << flag << "\n" << help.output;
      EXPECT_EQ(help.output.rfind("usage: ", 0), 0u) << name << "\n" << help.output;
    }
    const std::string text = run(name, "--help").output;
    // Usage, blank line, the first paragraph: whole sentences.
    const size_t start = text.find("\n\n");
    ASSERT_NE(start, std::string::npos) << name << "\n" << text;
    const size_t end = text.find("\n\n", start + 2);
    ASSERT_NE(end, std::string::npos) << name << "\n" << text;
    const std::string paragraph = text.substr(start + 2, end - start - 2);
    EXPECT_GT(paragraph.size(), 40u) << name << "\n" << text;
    EXPECT_EQ(paragraph.back(), '.') << name << ": " << paragraph;
    // Every option the usage names is in the options' list, with its description.
    const std::string usage = text.substr(0, start);
    const std::string options = text.substr(end);
    const std::regex option_name(R"(--[a-z][a-z0-9-]*)");
    std::set<std::string> named;
    for (auto it = std::sregex_iterator(usage.begin(), usage.end(), option_name);
         it != std::sregex_iterator(); ++it) {
      named.insert(it->str());
    }
    for (const std::string& option : named) {
      const std::regex listed("\n  (-[a-z] \\[ )?" + option + "[ \\]]");
      EXPECT_TRUE(std::regex_search(options, listed)) << name << ": " << option << "\n" << text;
    }
  }
}

TEST(ProgramsCli, WakeBenchRefusesWhatAtoiTook) {
  expectUsageError("norm2tex_wake_bench", "20abc", "'20abc'");  // atoi: 20 frames
  expectUsageError("norm2tex_wake_bench", "abc", "'abc'");      // atoi: 0
  expectUsageError("norm2tex_wake_bench", "99999999999", "99999999999");
  expectUsageError("norm2tex_wake_bench", "9", "at least 10");
  expectUsageError("norm2tex_wake_bench", "20 30", "unexpected argument '30'");
  expectUsageError("norm2tex_wake_bench", "--frames", "--frames");
}

TEST(ProgramsCli, RosBenchRefusesABadLineBeforeLookingForAMaster) {
  const std::string bench = "norm2tex_ros_bench";
  expectUsageError(bench, "synchronous 600x", "'600x'");  // atoi: 600, then waited for a master
  expectUsageError(bench, "real_time 1e3", "'1e3'");      // atoi: 1
  expectUsageError(bench, "real_time 60 spilt", "'spilt'");
  expectUsageError(bench, "synchronous 60 split", "real_time only");
  expectUsageError(bench, "synchronous 60 --arrivals arrivals.csv", "real_time only");
  expectUsageError(bench, "real_time 60 --arrivals", "--arrivals");
  expectUsageError(bench, "real_time 60 --arrival a.csv", "'--arrival'");
  expectUsageError(bench, "synchronus", "'synchronus'");
  expectUsageError(bench, "", "missing MODE");
  expectUsageError(bench, "hand_synchronous 5", "at least 10");
  expectUsageError(bench, "hand_real_time 60x", "'60x'");
}

class GraspDemoCli : public CliTest {};

TEST_F(GraspDemoCli, RefusesABadLineBeforeLookingForAMaster) {
  const std::string demo = "norm2tex_grasp_demo";
  const std::string out = path("grasp");
  // std::stod took these, then the demo waited 30 s for a master.
  expectUsageError(demo, out + " --height-offset nan", "finite");
  expectUsageError(demo, out + " --height-offset inf", "finite");
  // A seed below 0, which ~reset refuses.
  expectUsageError(demo, out + " --seed -1", ">= 0");
  expectUsageError(demo, out + " --seed 1.5", "'1.5'");
  expectUsageError(demo, out + " --seed", "--seed");
  expectUsageError(demo, out + " --sede 2", "'--sede'");
  expectUsageError(demo, out + " extra", "unexpected argument 'extra'");
  expectUsageError(demo, "--seed 2", "missing OUT_DIR");
  EXPECT_FALSE(std::filesystem::exists(out)) << "nothing made for a bad command line";
}

TEST(ProgramsCli, ParseErrorsOfTheOtherProgramsUseTheSameFormat) {
  expectUsageError("norm2tex_make_demo_normal_map", "-o x.png --size 256px", "'256px'");
  expectUsageError("norm2tex_gripper_sweep", "-o x.png --friction nan", "finite");
  expectUsageError("norm2tex_export", "a.bag -o out --depth", "--depth");
  expectUsageError("nodelet_group", "stray", "unexpected argument 'stray'");
  // launch_check speaks for its launch file: "NAME: reason", exit 2 with the usage.
  const CliRun launch =
      run("norm2tex_launch_check", "--launch x.launch --min-free-mb lots --output-dir /tmp");
  EXPECT_EQ(launch.exit_code, 2) << launch.output;
  EXPECT_EQ(launch.output.rfind("x.launch: ", 0), 0u) << launch.output;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
