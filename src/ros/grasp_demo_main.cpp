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

/// Waits for the ROS master that the launch starting beside this may still be bringing up,
/// quietly (a node handle would retry with an error line per attempt), with a deadline.
void waitForMaster(double seconds) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(seconds);
  while (!ros::master::check()) {
    if (ros::WallTime::now() > deadline) {
      throw std::runtime_error("no ROS master at " + ros::master::getURI() + " within " +
                               std::to_string(static_cast<int>(seconds)) + " s");
    }
    ros::WallDuration(0.1).sleep();
  }
}

/// A synchronous gripper_sim driven one frame a call: its services and each sensor's latest
/// image and contact.
class GraspSession {
 public:
  /// Subscribes and waits (with deadlines) for the services and the renderers' topics.
  explicit GraspSession(ros::NodeHandle& nh) {
    for (const char* sensor : kSensors) {
      const std::string name = sensor;
      subs_.push_back(nh.subscribe<sensor_msgs::Image>(
          name + "/image_raw", 10, [this, name](const auto& m) { latest_.images[name] = m; }));
      subs_.push_back(nh.subscribe<norm2tex::TactileContact>(
          name + "/contact", 10, [this, name](const auto& m) { latest_.contacts[name] = m; }));
    }
    step_ = nh.serviceClient<norm2tex::Step>("contact_sim/step");
    reset_ = nh.serviceClient<norm2tex::Reset>("contact_sim/reset");
    if (!step_.waitForExistence(ros::Duration(60.0)) ||
        !reset_.waitForExistence(ros::Duration(5.0))) {
      throw std::runtime_error("no synchronous contact_sim (~step) within 60 s");
    }
    const auto connected = [&] {
      for (const ros::Subscriber& sub : subs_) {
        if (sub.getNumPublishers() == 0) return false;
      }
      return true;
    };
    if (!waitFor(connected, 30.0))
      throw std::runtime_error("the renderers' topics never connected");
  }

  void reset(std::int64_t seed, double height_offset) {
    norm2tex::Reset episode;
    episode.request.seed = seed;
    episode.request.height_offset = height_offset;
    if (!reset_.call(episode) || !episode.response.success) {
      throw std::runtime_error("~reset failed: " + episode.response.message);
    }
  }

  /// One frame with the opening changed by `delta` (0: no command). The call returns once both
  /// images of it are published, so waiting for images with its stamp never reads a stale one.
  void advance(double delta) {
    step_srv_.request.frames = 1;
    step_srv_.request.set_command = delta != 0.0;
    step_srv_.request.command.mode = norm2tex::GripperCommand::DELTA;
    step_srv_.request.command.opening = delta;
    if (!step_.call(step_srv_)) throw std::runtime_error("~step failed (no answer)");
    if (!step_srv_.response.success) throw std::runtime_error(step_srv_.response.message);
    const ros::Time stamp = step_srv_.response.stamp;
    const auto arrived = [&] {
      for (const char* sensor : kSensors) {
        const auto it = latest_.images.find(sensor);
        if (it == latest_.images.end() || it->second->header.stamp != stamp) return false;
      }
      return true;
    };
    if (!waitFor(arrived, 10.0)) {
      throw std::runtime_error("the images of the frame at " + std::to_string(stamp.toSec()) +
                               " s never arrived");
    }
  }

  const norm2tex::Step::Response& last() const { return step_srv_.response; }
  cv::Mat3b image(int sensor) const { return toMat(*latest_.images.at(kSensors[sensor])); }
  /// The left gel's normal force at the latest contact message (N), or NaN before the first.
  double leftNormalForce() const {
    const auto it = latest_.contacts.find(kSensors[0]);
    return it == latest_.contacts.end() || !it->second ? std::nan("") : it->second->normal_force;
  }

 private:
  Latest latest_;
  std::vector<ros::Subscriber> subs_;
  ros::ServiceClient step_, reset_;
  norm2tex::Step step_srv_;
};

/// The moments the demo keeps: both sensors' PNGs each, and the tiles of the labelled strip.
class GraspRecord {
 public:
  explicit GraspRecord(std::filesystem::path out) : out_(std::move(out)) {}

  void save(const GraspSession& session, const std::string& moment) {
    const norm2tex::Step::Response& frame = session.last();
    for (int i = 0; i < 2; ++i) {
      const cv::Mat3b image = session.image(i);
      cv::imwrite((out_ / (std::string(kSensors[i]) + "_" + moment + ".png")).string(), image);
      tiles_[i].push_back(image);
    }
    labels_.push_back(moment + ", opening " + std::to_string(frame.opening).substr(0, 5));
    std::printf("%-10s opening %.3f  stamp %.3f s  -> %s/digit_{left,right}_%s.png\n",
                moment.c_str(), frame.opening, frame.stamp.toSec(), out_.c_str(), moment.c_str());
  }

  /// Writes the strip; returns its path.
  std::string writeStrip() const {
    const std::string strip = (out_ / "grasp_sequence.png").string();
    cv::imwrite(strip,
                norm2tex::cli::makeContactSheet(tiles_, {"digit_left", "digit_right"}, labels_));
    return strip;
  }

 private:
  std::filesystem::path out_;
  std::vector<std::vector<cv::Mat3b>> tiles_{2};
  std::vector<std::string> labels_;
};

/// The paper's grasp: hold, squeeze 2 mm, then open slowly until the cube drops (at most 600
/// frames), saving the moments. Returns whether it dropped.
bool runGrasp(GraspSession& session, GraspRecord& record) {
  session.advance(0.0);
  record.save(session, "grasp");
  for (int i = 0; i < 10; ++i) session.advance(-0.005);  // squeeze: 2 mm narrower
  for (int i = 0; i < 20; ++i) session.advance(0.0);     // let the fingers get there
  record.save(session, "squeeze");
  bool saved_release = false;
  for (int frames = 0; !session.last().dropped && frames < 600; ++frames) {
    session.advance(session.last().opening < 0.98 ? 0.0025 : 0.0);
    if (!saved_release && session.leftNormalForce() < 2.0) {
      record.save(session, "release");
      saved_release = true;
    }
  }
  for (int i = 0; i < 10; ++i) session.advance(0.0);
  const bool dropped = session.last().dropped;
  record.save(session, dropped ? "dropped" : "open");
  return dropped;
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

  waitForMaster(30.0);
  ros::NodeHandle nh;
  GraspSession session(nh);
  session.reset(seed, height_offset);
  GraspRecord record(out);
  const bool dropped = runGrasp(session, record);
  std::printf("grasp sequence (both sensors) -> %s; the object %s\n", record.writeStrip().c_str(),
              dropped ? "dropped" : "did not drop");
  return dropped ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const norm2tex::cli::Program program = makeProgram();
  return program.main(argc, argv, [&](int argc, char** argv) { return run(program, argc, argv); });
}
