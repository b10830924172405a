// norm2tex_ros_bench: end-to-end speed of a running gripper_sim.launch, both sensors delivered
// to this subscriber.
//   norm2tex_ros_bench synchronous [FRAMES]   frames/s of ~step (one call per frame, the policy
//                                             loop; and one call for all frames)
//   norm2tex_ros_bench hand_synchronous [FRAMES]
//                                             the same policy loop against a running
//                                             hand_sim.launch, every sensor of its hand
//                                             delivered (frames/s and images/s)
//   norm2tex_ros_bench hand_real_time [FRAMES]
//                                             every sensor of a real-time hand_sim.launch:
//                                             frames missed and stamp-to-image latency
//   norm2tex_ros_bench real_time [FRAMES] [split]
//                                             latency from a frame's stamp to its images'
//                                             arrival here (wall-clock stamps), p50 / p99 / max;
//                                             "split": also when its physics was done, and the
//                                             first and second image
//   norm2tex_ros_bench real_time FRAMES [split] --arrivals FILE
//                                             also writes each frame's image arrivals as CSV
//                                             (stamp_ns,first_ns,second_ns,first_frame_id), for
//                                             scripts/latency_trace
#include <algorithm>
#include <atomic>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include <ros/ros.h>
#include <sensor_msgs/Image.h>

#include "cli_arguments.hpp"
#include "norm2tex/HandStep.h"
#include "norm2tex/SimFrame.h"
#include "norm2tex/Step.h"
#include "wait_for.hpp"

namespace {

namespace po = norm2tex::cli::po;
using norm2tex::waitFor;
using norm2tex::cli::UsageError;

struct Arrivals {
  std::map<ros::Time, int> count;               // images per stamp (both sensors)
  std::map<ros::Time, ros::WallTime> first;     // when the stamp's first image arrived
  std::map<ros::Time, ros::WallTime> last;      // when the stamp's last image arrived
  std::map<ros::Time, ros::WallTime> frame;     // when its SimFrame arrived (physics done)
  std::map<ros::Time, std::string> first_from;  // the gel frame of the stamp's first image
  int total = 0;
};

int fail(const char* why) {
  std::fprintf(stderr, "norm2tex_ros_bench: error: %s\n", why);
  return 1;
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * (v.size() - 1) + 0.5))];
}

norm2tex::cli::Program makeProgram() {
  norm2tex::cli::Program program(
      "norm2tex_ros_bench",
      "norm2tex_ros_bench synchronous [FRAMES]\n"
      "       norm2tex_ros_bench hand_synchronous [FRAMES]\n"
      "       norm2tex_ros_bench hand_real_time [FRAMES]\n"
      "       norm2tex_ros_bench real_time [FRAMES] [split] [--arrivals FILE]",
      "Measures the end-to-end speed of a running gripper_sim.launch (hand_sim.launch for\n"
      "hand_synchronous), every sensor's images delivered to this subscriber. synchronous: the\n"
      "frames/s of ~step, one call per frame (the policy loop) and one call for all frames.\n"
      "hand_synchronous: the same policy loop against hand_sim, frames/s and images/s.\n"
      "hand_real_time: every sensor of a real-time hand_sim.launch, the frames it missed and\n"
      "the latency from a frame's stamp to its image.\n"
      "real_time: the latency from a frame's stamp to its images' arrival here (wall-clock\n"
      "stamps), p50 / p99 / max; with split, also when its physics was done, and the first and\n"
      "second image. FRAMES: at least 10 (default 600).");
  program.positional("MODE", 1, po::value<std::string>());
  program.positional("FRAMES", 1, po::value<int>());
  program.positional("SPLIT", 1, po::value<std::string>());
  program.add()  //
      ("arrivals", po::value<std::string>()->value_name("FILE"),
       "real_time: also write each frame's image arrivals as CSV "
       "(stamp_ns,first_ns,second_ns,first_frame_id), for scripts/latency_trace.");
  return program;
}

}  // namespace

/// hand_synchronous: the policy loop (one ~step, then every sensor's image of it) against
/// hand_sim, however many sensors its hand has.
int benchHandSynchronous(ros::NodeHandle& nh, int frames) {
  std::vector<std::string> sensors;
  if (!waitFor([&] { return nh.getParam("hand_sim/sensors", sensors); }, 60, 0.05)) {
    return fail("no hand_sim/sensors parameter within 60 s (is hand_sim.launch running?)");
  }
  std::map<ros::Time, size_t> count;
  std::vector<ros::Subscriber> subs;
  for (const std::string& sensor : sensors) {
    subs.push_back(nh.subscribe<sensor_msgs::Image>(
        sensor + "/image_raw", 2 * frames + 200,
        [&](const sensor_msgs::Image::ConstPtr& m) { ++count[m->header.stamp]; }, {},
        ros::TransportHints().tcpNoDelay()));
  }
  ros::ServiceClient step = nh.serviceClient<norm2tex::HandStep>("hand_sim/step", true);
  if (!step.waitForExistence(ros::Duration(60.0))) return fail("no hand_sim/step within 60 s");
  norm2tex::HandStep srv;
  srv.request.frames = 1;
  for (int i = 0; i < 20; ++i) step.call(srv);  // warm up
  waitFor([&] { return count[srv.response.stamp] == sensors.size(); }, 10);
  const ros::WallTime start = ros::WallTime::now();
  for (int i = 0; i < frames; ++i) {
    if (!step.call(srv) || !srv.response.success)
      return fail(("~step failed: " + srv.response.message).c_str());
    const ros::Time stamp = srv.response.stamp;
    if (!waitFor([&] { return count[stamp] == sensors.size(); }, 10)) {
      return fail("a step's images did not all arrive within 10 s");
    }
  }
  const double loop = (ros::WallTime::now() - start).toSec();
  std::printf(
      "hand_synchronous, %d frames, %zu sensors delivered: policy loop (step 1 + wait) "
      "%.0f frames/s (%.2f ms/frame), %.0f images/s\n",
      frames, sensors.size(), frames / loop, 1e3 * loop / frames, frames * sensors.size() / loop);
  return 0;
}

/// hand_real_time: every sensor of a hand_sim.launch running in real time, over FRAMES frames
/// of the clock: the frames each sensor missed (gaps in its stamps, which sit on the frame grid),
/// and the latency from a frame's stamp (wall clock) to its image's arrival here.
int benchHandRealTime(ros::NodeHandle& nh, int frames) {
  std::vector<std::string> sensors;
  if (!waitFor([&] { return nh.getParam("hand_sim/sensors", sensors); }, 60, 0.05)) {
    return fail("no hand_sim/sensors parameter within 60 s (is hand_sim.launch running?)");
  }
  double rate = 60.0;
  nh.getParam("hand_sim/frame_rate", rate);
  std::map<std::string, std::vector<ros::Time>> stamps;
  std::vector<double> latency_ms;
  latency_ms.reserve(static_cast<size_t>(frames) * sensors.size() + 1000);
  std::vector<ros::Subscriber> subs;
  for (const std::string& sensor : sensors) {
    subs.push_back(nh.subscribe<sensor_msgs::Image>(
        sensor + "/image_raw", 2 * frames + 200,
        [&, sensor](const sensor_msgs::Image::ConstPtr& m) {
          stamps[sensor].push_back(m->header.stamp);
          const ros::WallTime now = ros::WallTime::now();
          latency_ms.push_back(1e3 * (now.toSec() - m->header.stamp.toSec()));
        },
        {}, ros::TransportHints().tcpNoDelay()));
  }
  const auto all_have = [&](size_t n) {
    for (const std::string& sensor : sensors) {
      if (stamps[sensor].size() < n) return false;
    }
    return true;
  };
  // Counted from when every sensor publishes (the renderers' first frames wait for textures).
  if (!waitFor([&] { return all_have(1); }, 120))
    return fail("not every sensor published within 120 s");
  // (Callbacks run only inside waitFor: nothing arrives while this starts the count.)
  const size_t skip = latency_ms.size();
  for (auto& [sensor, s] : stamps) s.clear();
  const double seconds = frames / rate;
  if (!waitFor([&] { return all_have(static_cast<size_t>(frames)); }, 2.0 * seconds + 30.0)) {
    return fail("the sensors did not publish FRAMES images within twice their time");
  }
  const double period = 1.0 / rate;
  int lost = 0;
  for (const std::string& sensor : sensors) {
    const std::vector<ros::Time>& s = stamps[sensor];
    int missing = 0;
    for (size_t i = 1; i < static_cast<size_t>(frames); ++i) {
      missing += static_cast<int>(std::lround((s[i] - s[i - 1]).toSec() / period)) - 1;
    }
    lost += missing;
    std::printf("  %s: %d images over %.1f s of frames, %d frames missed\n", sensor.c_str(), frames,
                (s[frames - 1] - s[0]).toSec(), missing);
  }
  std::vector<double> measured(latency_ms.begin() + static_cast<long>(skip), latency_ms.end());
  std::printf(
      "hand_real_time, %d frames at %.0f Hz, %zu sensors: %d frames missed in all; "
      "latency stamp -> image p50 %.2f ms, p99 %.2f ms, max %.2f ms\n",
      frames, rate, sensors.size(), lost, percentile(measured, 0.5), percentile(measured, 0.99),
      *std::max_element(measured.begin(), measured.end()));
  return lost == 0 ? 0 : 1;
}

/// synchronous: the policy loop (one ~step, then both images of it) against contact_sim, then
/// one ~step of every frame.
int benchSynchronous(ros::NodeHandle& nh, Arrivals& arrivals, int frames) {
  ros::ServiceClient step = nh.serviceClient<norm2tex::Step>("contact_sim/step", true);
  if (!step.waitForExistence(ros::Duration(60.0))) return fail("no contact_sim/step within 60 s");
  norm2tex::Step srv;
  srv.request.frames = 1;
  for (int i = 0; i < 20; ++i) step.call(srv);  // warm up
  waitFor([&] { return arrivals.count[srv.response.stamp] == 2; }, 10);
  // The policy loop: step one frame, wait for both of its images.
  ros::WallTime start = ros::WallTime::now();
  for (int i = 0; i < frames; ++i) {
    if (!step.call(srv) || !srv.response.success)
      return fail(("~step failed: " + srv.response.message).c_str());
    const ros::Time stamp = srv.response.stamp;
    if (!waitFor([&] { return arrivals.count[stamp] == 2; }, 10))
      return fail("a step's two images did not arrive within 10 s");
  }
  const double loop = (ros::WallTime::now() - start).toSec();
  // One call for all frames, then wait for the last images.
  const int before = arrivals.total;
  start = ros::WallTime::now();
  srv.request.frames = frames;
  // The call blocks until every frame is answered: made from another thread, so that this one
  // takes the images as they arrive, as a subscriber of its own would. (Held back until the
  // call returned, all of them piled up here: 1200 fresh 230 kB buffers, ~30 page faults
  // each, on the cores the renderers need.)
  std::atomic<bool> called{false}, step_ok{false};
  std::thread caller([&] {
    step_ok = step.call(srv) && srv.response.success;
    called = true;
  });
  // Until the call returned and every image is here, or none has come for 2 s (a subscriber
  // that fell more than the publisher's queue behind lost some: reported below).
  int seen = arrivals.total;
  ros::WallTime last_arrival = ros::WallTime::now();
  waitFor(
      [&] {
        const ros::WallTime now = ros::WallTime::now();
        if (arrivals.total != seen) {
          seen = arrivals.total;
          last_arrival = now;
        }
        return called &&
               (arrivals.total - before == 2 * frames || (now - last_arrival).toSec() > 2.0);
      },
      120);
  caller.join();
  if (!step_ok) return fail("~step failed");
  const double batch = (last_arrival - start).toSec();
  std::printf(
      "synchronous, %d frames, both sensors delivered: policy loop (step 1 + wait) "
      "%.0f frames/s (%.2f ms/frame); one ~step of %d frames %.0f frames/s "
      "(%.2f ms/frame); %d images lost\n",
      frames, frames / loop, 1e3 * loop / frames, frames, frames / batch, 1e3 * batch / frames,
      2 * frames - (arrivals.total - before));
  return 0;
}

/// real_time: from a frame's stamp (wall clock) to its images' arrival, p50 / p99 / max; with
/// `split` also to its SimFrame; with `arrivals_file` each frame's arrivals as CSV.
int benchRealTime(Arrivals& arrivals, int frames, bool split, const std::string& arrivals_file) {
  // Real time: stamps are wall time (use_sim_time false).
  waitFor([&] { return arrivals.total >= 2 * 60; }, 30);
  arrivals = Arrivals{};
  // Woken by each image (as a subscriber spinning its queue is), not by a 0.5 ms poll: 2000
  // wake-ups a second of its own would compete with the renderers it measures.
  waitFor([&] { return static_cast<int>(arrivals.count.size()) >= frames + 2; }, frames / 30.0 + 30,
          /*poll_seconds=*/0.1);
  std::vector<double> latency_ms, physics_ms, first_ms, second_ms;
  int incomplete = 0;
  // The oldest frame may have had its first image before counting started, the newest its
  // second still on the way when counting stopped: neither is a frame with one image.
  const ros::Time oldest = arrivals.count.begin()->first;
  const ros::Time newest = arrivals.count.rbegin()->first;
  for (const auto& [stamp, n] : arrivals.count) {
    if (n != 2) {
      if (stamp != oldest && stamp != newest) ++incomplete;
      continue;
    }
    latency_ms.push_back(1e3 * (arrivals.last[stamp].toSec() - stamp.toSec()));
    first_ms.push_back(1e3 * (arrivals.first[stamp].toSec() - stamp.toSec()));
    second_ms.push_back(1e3 * (arrivals.last[stamp] - arrivals.first[stamp]).toSec());
    const auto f = arrivals.frame.find(stamp);
    if (f != arrivals.frame.end()) physics_ms.push_back(1e3 * (f->second.toSec() - stamp.toSec()));
  }
  if (latency_ms.size() < 10) return fail("fewer than 10 frames with both images");
  if (!arrivals_file.empty()) {
    std::ofstream out(arrivals_file);
    out << "stamp_ns,first_ns,second_ns,first_frame_id\n";
    for (const auto& [stamp, n] : arrivals.count) {
      if (n != 2) continue;
      out << stamp.toNSec() << ',' << arrivals.first[stamp].toNSec() << ','
          << arrivals.last[stamp].toNSec() << ',' << arrivals.first_from[stamp] << '\n';
    }
    if (!out.flush()) return fail(("cannot write " + arrivals_file).c_str());
  }
  std::printf(
      "real time, %zu frames: stamp -> both images here: p50 %.2f ms, p99 %.2f ms, "
      "max %.2f ms; %d frames with one image\n",
      latency_ms.size(), percentile(latency_ms, 0.5), percentile(latency_ms, 0.99),
      percentile(latency_ms, 1.0), incomplete);
  if (split) {
    if (physics_ms.size() < 10) return fail("fewer than 10 frames with their SimFrame here");
    std::printf("  stamp -> SimFrame here (physics done) p50 %.2f ms, p99 %.2f ms\n",
                percentile(physics_ms, 0.5), percentile(physics_ms, 0.99));
  }
  std::printf(
      "  stamp -> first image p50 %.2f ms, p99 %.2f ms; first -> second image p50 %.2f ms, "
      "p99 %.2f ms\n",
      percentile(first_ms, 0.5), percentile(first_ms, 0.99), percentile(second_ms, 0.5),
      percentile(second_ms, 0.99));
  return 0;
}

int run(const norm2tex::cli::Program& program, int argc, char** argv) {
  // ros::init first: it takes its own arguments (name:=value remappings) off the command line.
  ros::init(argc, argv, "norm2tex_ros_bench", ros::init_options::AnonymousName);
  const po::variables_map args = program.parse(argc, argv);
  const std::string mode = norm2tex::cli::valueOr<std::string>(args, "MODE", "");
  if (mode != "synchronous" && mode != "real_time" && mode != "hand_synchronous" &&
      mode != "hand_real_time") {
    throw UsageError(
        mode.empty() ? "missing MODE (synchronous, hand_synchronous, hand_real_time or real_time)"
                     : "unknown MODE '" + mode +
                           "'; valid: synchronous, hand_synchronous, hand_real_time, real_time");
  }
  const int frames = norm2tex::cli::valueOr(args, "FRAMES", 600);
  if (frames < 10) throw UsageError("FRAMES must be at least 10, got " + std::to_string(frames));
  const std::string split_word = norm2tex::cli::valueOr<std::string>(args, "SPLIT", "");
  if (!split_word.empty() && split_word != "split") {
    throw UsageError("unexpected argument '" + split_word + "' (only 'split' may follow FRAMES)");
  }
  const bool split = !split_word.empty();
  const std::string arrivals_file = norm2tex::cli::valueOr<std::string>(args, "arrivals", "");
  if ((split || args.count("arrivals")) && mode != "real_time") {
    throw UsageError(std::string(split ? "split" : "--arrivals") + " is for real_time only");
  }
  if (args.count("arrivals") && arrivals_file.empty()) throw UsageError("--arrivals: empty FILE");
  ros::NodeHandle nh;
  if (mode == "hand_synchronous") return benchHandSynchronous(nh, frames);
  if (mode == "hand_real_time") return benchHandRealTime(nh, frames);
  Arrivals arrivals;
  auto on_image = [&](const sensor_msgs::Image::ConstPtr& m) {
    ++arrivals.total;
    const ros::WallTime now = ros::WallTime::now();
    if (++arrivals.count[m->header.stamp] == 1) {
      arrivals.first[m->header.stamp] = now;
      if (!arrivals_file.empty()) arrivals.first_from[m->header.stamp] = m->header.frame_id;
    }
    arrivals.last[m->header.stamp] = now;
  };
  // Room for every image of a run: a benchmark that drops images at its own queue would
  // measure itself.
  const int queue = 2 * frames + 200;
  const ros::TransportHints hints = ros::TransportHints().tcpNoDelay();
  ros::Subscriber left =
      nh.subscribe<sensor_msgs::Image>("digit_left/image_raw", queue, on_image, {}, hints);
  ros::Subscriber right =
      nh.subscribe<sensor_msgs::Image>("digit_right/image_raw", queue, on_image, {}, hints);
  // Real time with "split": when each frame's physics was done (its SimFrame here), to split the
  // latency. Off by default: receiving it takes this machine's CPU while the frame renders.
  ros::Subscriber frames_sub;
  if (mode == "real_time" && split) {
    frames_sub = nh.subscribe<norm2tex::SimFrame>(
        "contact_sim/frame", queue,
        [&](const norm2tex::SimFrame::ConstPtr& f) {
          arrivals.frame[f->header.stamp] = ros::WallTime::now();
        },
        {}, hints);
  }
  if (!waitFor([&] { return left.getNumPublishers() > 0 && right.getNumPublishers() > 0; }, 60)) {
    std::fprintf(stderr, "norm2tex_ros_bench: no image publishers within 60 s\n");
    return 1;
  }

  if (mode == "synchronous") return benchSynchronous(nh, arrivals, frames);
  return benchRealTime(arrivals, frames, split, arrivals_file);
}

int main(int argc, char** argv) {
  const norm2tex::cli::Program program = makeProgram();
  return program.main(argc, argv, [&](int argc, char** argv) { return run(program, argc, argv); });
}
