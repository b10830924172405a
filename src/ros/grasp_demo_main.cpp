// norm2tex_grasp_demo: drives a synchronous gripper_sim.launch through the paper's grasp
// (grasp, squeeze, open slowly until the cube drops) and saves both DIGITs' images at several
// moments, plus a labelled strip of them. The main job runs it headless.
// Its options: norm2tex_grasp_demo --help.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <cv_bridge/cv_bridge.h>
#include <ros/master.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/image_encodings.h>
#include <opencv2/imgcodecs.hpp>

#include "cli_arguments.hpp"
#include "contact_sheet.hpp"
#include "norm2tex/Reset.h"
#include "norm2tex/Step.h"
#include "norm2tex/TactileContact.h"
#include "wait_for.hpp"

namespace {

namespace po = norm2tex::cli::po;
using norm2tex::waitFor;

const char* const kSensors[2] = {"digit_left", "digit_right"};

struct Latest {
  std::map<std::string, sensor_msgs::Image::ConstPtr> images;
  std::map<std::string, norm2tex::TactileContact::ConstPtr> contacts;
};

cv::Mat3b toMat(const sensor_msgs::Image& msg) {
  return cv_bridge::toCvCopy(msg, sensor_msgs::image_encodings::BGR8)->image;
}

norm2tex::cli::Program makeProgram() {
  norm2tex::cli::Program program(
      "norm2tex_grasp_demo", "norm2tex_grasp_demo OUT_DIR [--seed S] [--height-offset M]",
      "Runs the paper's grasp on a synchronous gripper_sim.launch (started separately): grasp,\n"
      "squeeze, open slowly until the cube drops. It saves both DIGITs' images at several\n"
      "moments, and a labelled strip of them, in OUT_DIR. It exits 0 when the cube dropped.");
  program.positional("OUT_DIR", 1, po::value<std::string>());
  program.add()  //
      ("seed", po::value<std::int64_t>()->value_name("S"),
       "The episode's seed, >= 0 (default 1).")  //
      ("height-offset", po::value<double>()->value_name("M"),
       "Metres, the object's centre above the gels' centres, within the scene's range (default "
       "0.008).");
  return program;
}

int run(const norm2tex::cli::Program& program, int argc, char** argv) {
  // ros::init first: it takes its own arguments (name:=value remappings) off the command line.
  ros::init(argc, argv, "norm2tex_grasp_demo", ros::init_options::AnonymousName);
  const po::variables_map args = program.parse(argc, argv);
  if (!args.count("OUT_DIR")) throw norm2tex::cli::UsageError("missing OUT_DIR");
  const std::filesystem::path out = args["OUT_DIR"].as<std::string>();
  const std::int64_t seed = norm2tex::cli::valueOr<std::int64_t>(args, "seed", 1);
  if (seed < 0) {
    throw norm2tex::cli::UsageError("--seed must be >= 0, got " + std::to_string(seed));
  }
  const double height_offset = norm2tex::cli::valueOr(args, "height-offset", 0.008);
  std::error_code error;
  std::filesystem::create_directories(out, error);
  if (error) {
    throw std::runtime_error("cannot create " + out.string() + ": " + error.message());
  }

  // The launch that starts the master may still be coming up: wait for it quietly (a node handle
  // would retry with an error line per attempt), with a deadline.
  const ros::WallTime master_deadline = ros::WallTime::now() + ros::WallDuration(30.0);
  while (!ros::master::check()) {
    if (ros::WallTime::now() > master_deadline) {
      throw std::runtime_error("no ROS master at " + ros::master::getURI() + " within 30 s");
    }
    ros::WallDuration(0.1).sleep();
  }
  ros::NodeHandle nh;
  Latest latest;
  std::vector<ros::Subscriber> subs;
  for (const char* sensor : kSensors) {
    const std::string name = sensor;
    subs.push_back(nh.subscribe<sensor_msgs::Image>(
        name + "/image_raw", 10, [&latest, name](const auto& m) { latest.images[name] = m; }));
    subs.push_back(nh.subscribe<norm2tex::TactileContact>(
        name + "/contact", 10, [&latest, name](const auto& m) { latest.contacts[name] = m; }));
  }
  ros::ServiceClient step = nh.serviceClient<norm2tex::Step>("contact_sim/step");
  ros::ServiceClient reset = nh.serviceClient<norm2tex::Reset>("contact_sim/reset");
  if (!step.waitForExistence(ros::Duration(60.0)) || !reset.waitForExistence(ros::Duration(5.0))) {
    throw std::runtime_error("no synchronous contact_sim (~step) within 60 s");
  }
  if (!waitFor(
          [&] {
            for (const ros::Subscriber& sub : subs) {
              if (sub.getNumPublishers() == 0) return false;
            }
            return true;
          },
          30.0)) {
    throw std::runtime_error("the renderers' topics never connected");
  }

  norm2tex::Reset episode;
  episode.request.seed = seed;
  episode.request.height_offset = height_offset;
  if (!reset.call(episode) || !episode.response.success) {
    throw std::runtime_error("~reset failed: " + episode.response.message);
  }

  // One frame per call: the call returns once both images of it are published, so waiting
  // for images with its stamp never reads a stale one.
  norm2tex::Step srv;
  auto advance = [&](double delta) {
    srv.request.frames = 1;
    srv.request.set_command = delta != 0.0;
    srv.request.command.mode = norm2tex::GripperCommand::DELTA;
    srv.request.command.opening = delta;
    if (!step.call(srv)) throw std::runtime_error("~step failed (no answer)");
    if (!srv.response.success) throw std::runtime_error(srv.response.message);
    const ros::Time stamp = srv.response.stamp;
    if (!waitFor(
            [&] {
              for (const char* sensor : kSensors) {
                const auto it = latest.images.find(sensor);
                if (it == latest.images.end() || it->second->header.stamp != stamp) return false;
              }
              return true;
            },
            10.0)) {
      throw std::runtime_error("the images of the frame at " + std::to_string(stamp.toSec()) +
                               " s never arrived");
    }
  };

  std::vector<std::vector<cv::Mat3b>> tiles(2);
  std::vector<std::string> labels;
  auto save = [&](const std::string& moment) {
    for (int i = 0; i < 2; ++i) {
      const cv::Mat3b image = toMat(*latest.images[kSensors[i]]);
      const std::string path = (out / (std::string(kSensors[i]) + "_" + moment + ".png")).string();
      cv::imwrite(path, image);
      tiles[i].push_back(image);
    }
    labels.push_back(moment + ", opening " + std::to_string(srv.response.opening).substr(0, 5));
    std::printf("%-10s opening %.3f  stamp %.3f s  -> %s/digit_{left,right}_%s.png\n",
                moment.c_str(), srv.response.opening, srv.response.stamp.toSec(), out.c_str(),
                moment.c_str());
  };

  advance(0.0);
  save("grasp");
  for (int i = 0; i < 10; ++i) advance(-0.005);  // squeeze: 2 mm narrower
  for (int i = 0; i < 20; ++i) advance(0.0);     // let the fingers get there
  save("squeeze");
  int frames = 0;
  bool saved_release = false;
  while (!srv.response.dropped && frames < 600) {
    advance(srv.response.opening < 0.98 ? 0.0025 : 0.0);
    ++frames;
    const auto& contact = latest.contacts[kSensors[0]];
    if (!saved_release && contact && contact->normal_force < 2.0) {
      save("release");
      saved_release = true;
    }
  }
  for (int i = 0; i < 10; ++i) advance(0.0);
  save(srv.response.dropped ? "dropped" : "open");
  const std::string strip = (out / "grasp_sequence.png").string();
  cv::imwrite(strip, norm2tex::cli::makeContactSheet(tiles, {"digit_left", "digit_right"}, labels));
  std::printf("grasp sequence (both sensors) -> %s; the object %s\n", strip.c_str(),
              srv.response.dropped ? "dropped" : "did not drop");
  return srv.response.dropped ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const norm2tex::cli::Program program = makeProgram();
  return program.main(argc, argv, [&](int argc, char** argv) { return run(program, argc, argv); });
}
