// norm2tex_grasp_demo: drives a synchronous gripper_sim.launch through the paper's grasp
// (grasp, squeeze, open slowly until the cube drops) and saves both DIGITs' images at several
// moments, plus a labelled strip of them. The main job runs it headless.
//
//   norm2tex_grasp_demo OUT_DIR [--seed S] [--height-offset M]
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <cv_bridge/cv_bridge.h>
#include <ros/master.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/image_encodings.h>
#include <opencv2/imgcodecs.hpp>

#include "contact_sheet.hpp"
#include "norm2tex/Reset.h"
#include "norm2tex/Step.h"
#include "norm2tex/TactileContact.h"
#include "wait_for.hpp"

namespace {

using norm2tex::waitFor;

const char* const kSensors[2] = {"digit_left", "digit_right"};

struct Latest {
  std::map<std::string, sensor_msgs::Image::ConstPtr> images;
  std::map<std::string, norm2tex::TactileContact::ConstPtr> contacts;
};

cv::Mat3b toMat(const sensor_msgs::Image& msg) {
  return cv_bridge::toCvCopy(msg, sensor_msgs::image_encodings::BGR8)->image;
}

}  // namespace

int main(int argc, char** argv) {
  const char* const usage =
      "usage: norm2tex_grasp_demo OUT_DIR [--seed S] [--height-offset M]\n"
      "  Runs the grasp on a synchronous gripper_sim.launch (started separately) and saves both\n"
      "  DIGITs' images at several moments, and a labelled strip of them, in OUT_DIR.\n";
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "-h") == 0 || std::strcmp(argv[i], "--help") == 0) {
      std::fputs(usage, stdout);
      return 0;
    }
  }
  ros::init(argc, argv, "norm2tex_grasp_demo", ros::init_options::AnonymousName);
  if (argc < 2 || argc % 2 != 0) {
    std::fputs(usage, stderr);
    return 2;
  }
  const std::filesystem::path out = argv[1];
  std::int64_t seed = 1;
  double height_offset = 0.008;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    try {
      size_t used = 0;
      if (flag == "--seed") {
        seed = std::stoll(argv[i + 1], &used);
      } else if (flag == "--height-offset") {
        height_offset = std::stod(argv[i + 1], &used);
      } else {
        std::fprintf(stderr, "norm2tex_grasp_demo: unknown option %s\n%s", flag.c_str(), usage);
        return 2;
      }
      if (argv[i + 1][used] != '\0') throw std::invalid_argument("trailing characters");
    } catch (const std::exception&) {
      std::fprintf(stderr, "norm2tex_grasp_demo: %s %s is not a number\n%s", flag.c_str(),
                   argv[i + 1], usage);
      return 2;
    }
  }
  std::error_code error;
  std::filesystem::create_directories(out, error);
  if (error) {
    std::fprintf(stderr, "norm2tex_grasp_demo: cannot create %s: %s\n", out.c_str(),
                 error.message().c_str());
    return 1;
  }

  // The launch that starts the master may still be coming up: wait for it quietly (a node handle
  // would retry with an error line per attempt), with a deadline.
  const ros::WallTime master_deadline = ros::WallTime::now() + ros::WallDuration(30.0);
  while (!ros::master::check()) {
    if (ros::WallTime::now() > master_deadline) {
      std::fprintf(stderr, "norm2tex_grasp_demo: no ROS master at %s within 30 s\n",
                   ros::master::getURI().c_str());
      return 1;
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
    std::fprintf(stderr, "norm2tex_grasp_demo: no synchronous contact_sim (~step) within 60 s\n");
    return 1;
  }
  if (!waitFor(
          [&] {
            for (const ros::Subscriber& sub : subs) {
              if (sub.getNumPublishers() == 0) return false;
            }
            return true;
          },
          30.0)) {
    std::fprintf(stderr, "norm2tex_grasp_demo: the renderers' topics never connected\n");
    return 1;
  }

  norm2tex::Reset episode;
  episode.request.seed = seed;
  episode.request.height_offset = height_offset;
  if (!reset.call(episode) || !episode.response.success) {
    std::fprintf(stderr, "norm2tex_grasp_demo: ~reset failed: %s\n",
                 episode.response.message.c_str());
    return 1;
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

  try {
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
  } catch (const std::exception& e) {
    std::fprintf(stderr, "norm2tex_grasp_demo: %s\n", e.what());
    return 1;
  }
  const std::string strip = (out / "grasp_sequence.png").string();
  cv::imwrite(strip, norm2tex::cli::makeContactSheet(tiles, {"digit_left", "digit_right"}, labels));
  std::printf("grasp sequence (both sensors) -> %s; the object %s\n", strip.c_str(),
              srv.response.dropped ? "dropped" : "did not drop");
  return srv.response.dropped ? 0 : 1;
}
