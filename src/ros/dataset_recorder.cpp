#include "dataset_recorder.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <limits>

#include <ros/master.h>
#include <rosbag/exceptions.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include "norm2tex/TactileContact.h"
#include "norm2tex/TactileMarkers.h"

#include "lock_step.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/memory_reuse.hpp"
#include "norm2tex/common/output_directory.hpp"
#include "params.hpp"

namespace norm2tex {
namespace {

using ros_params::badParameter;
using ros_params::readParam;
using ros_params::text;

template <typename M>
struct MessageTag {
  using type = M;
};

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

}  // namespace

DatasetRecorderParams readDatasetRecorderParams(const ros::NodeHandle& pnh) {
  DatasetRecorderParams p;
  if (!pnh.getParam("output_dir", p.output_dir) || p.output_dir.empty()) {
    badParameter("output_dir", "''", "a directory to write the bags into");
  }
  readParam<std::string>(pnh, "prefix", p.prefix, p.prefix);
  readParam(pnh, "shard", p.shard, p.shard);
  if (p.shard < 0) badParameter("shard", text(p.shard), ">= 0");
  readParam(pnh, "sensors", p.sensors, p.sensors);
  p.topics = {"/tf", "/tf_static", "/joint_states", "/clock", "episode"};
  for (const std::string& sensor : p.sensors) p.topics.push_back(sensor + "/background");
  readParam(pnh, "topics", p.topics, p.topics);
  readParam<std::string>(pnh, "compression", p.compression, p.compression);
  if (p.compression != "lz4" && p.compression != "bz2" && p.compression != "none") {
    badParameter("compression", "'" + p.compression + "'", "lz4, bz2, none");
  }
  readParam(pnh, "samples", p.samples, p.samples);
  if (p.samples < 0) badParameter("samples", text(p.samples), ">= 0 (0: no limit)");
  readParam<std::string>(pnh, "answer_as", p.answer_as, p.answer_as);
  readParam<std::string>(pnh, "frame_topic", p.frame_topic, p.frame_topic);
  readParam<std::string>(pnh, "answer_topic", p.answer_topic, p.answer_topic);
  readParam(pnh, "split_mb", p.split_mb, p.split_mb);
  if (!(p.split_mb >= 0.0)) badParameter("split_mb", text(p.split_mb), ">= 0 MB (0: one bag)");
  readParam(pnh, "min_free_mb", p.min_free_mb, p.min_free_mb);
  if (!(p.min_free_mb >= 0.0)) {
    badParameter("min_free_mb", text(p.min_free_mb), ">= 0 MB (0: write until a write fails)");
  }
  readParam(pnh, "record_shear", p.record_shear, p.record_shear);
  return p;
}

DatasetRecorder::DatasetRecorder(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : params_(readDatasetRecorderParams(private_nh)), nh_(nh) {
  keepFreedMemoryForReuse();  // frames, bags and textures reuse memory, not fault it in
  // An unwritable or full directory fails now, naming it, not at the first frame.
  checkOutputDirectory(params_.output_dir, params_.min_free_mb);
  openNextBag();

  answer_pub_ = nh_.advertise<FrameRendered>(params_.answer_topic, 100, /*latch=*/true);
  std::vector<std::string> topics = params_.topics;
  // The per-frame topics typed: in a nodelet manager they arrive without a copy, and their
  // stamps are read without deserialising them again.
  auto subscribePart = [&](const std::string& topic, auto tag,
                           std::vector<ros::Subscriber>& subs) {
    using Message = typename decltype(tag)::type;
    const std::string resolved = nh_.resolveName(topic);
    topics.push_back(topic);
    subs.push_back(nh_.subscribe<Message>(
        topic, 1000, [this, resolved](const ros::MessageEvent<Message const>& e) {
          onFramePart(resolved, e.getConstMessage()->header.stamp,
                      [&](const ros::Time& when) {
                        bag_->write(resolved, when, e.getConstMessage(), e.getConnectionHeaderPtr());
                      });
        }));
  };
  for (const std::string& sensor : params_.sensors) {
    subscribePart(sensor + "/image_raw", MessageTag<sensor_msgs::Image>(), part_subs_);
    subscribePart(sensor + "/camera_info", MessageTag<sensor_msgs::CameraInfo>(), part_subs_);
    subscribePart(sensor + "/depth", MessageTag<sensor_msgs::Image>(), part_subs_);
    subscribePart(sensor + "/contact", MessageTag<TactileContact>(), part_subs_);
    if (params_.record_shear) {
      subscribePart(sensor + "/shear", MessageTag<sensor_msgs::Image>(), part_subs_);
    }
    subscribePart(sensor + "/markers", MessageTag<TactileMarkers>(), marker_subs_);
  }
  frame_sub_ = nh_.subscribe(params_.frame_topic, 100, &DatasetRecorder::onFrame, this);
  started_ = last_progress_ = ros::WallTime::now();
  // The extra topics and the episodes are subscribed from this timer, once the constructor (a
  // nodelet's onInit) has returned: nodelet 1.10 (Debian 11) loses a latched message (the
  // renderers' background, /tf_static) that reaches a subscriber while onInit still runs, and
  // that subscriber never fires again (nodelet_core issue 108). Then, in synchronous mode, the
  // same timer announces "ready" once everything is connected.
  ready_timer_ = nh_.createWallTimer(ros::WallDuration(0.02), [this](const ros::WallTimerEvent&) {
    if (!extras_subscribed_) subscribeExtraTopics();
    if (params_.answer_as.empty()) {
      ready_timer_.stop();
      return;
    }
    announceReady();
  });
  // ~samples 0 is no limit of the recorder's own: the frame source's plan decides (probe_sim
  // ends with its last frame), so say that rather than "target 0".
  const std::string until = params_.samples > 0
                                ? "stops at " + text(params_.samples) + " images"
                                : std::string("until the frame source's last frame");
  ROS_INFO("dataset_recorder: %zu topics -> %s (%s), %s", topics.size(),
           bag_paths_.back().c_str(), params_.compression.c_str(), until.c_str());
}

DatasetRecorder::~DatasetRecorder() { close(); }

void DatasetRecorder::subscribeExtraTopics() {
  // Deep queues: in real time a slow disk must not drop frames unnoticed (drops are counted
  // as received - written at the end).
  for (const std::string& topic : params_.topics) {
    const std::string resolved = nh_.resolveName(topic);
    extra_subs_.push_back(nh_.subscribe<topic_tools::ShapeShifter>(
        topic, 1000, [this, resolved](const ros::MessageEvent<topic_tools::ShapeShifter>& e) {
          onMessage(resolved, e);
        }));
  }
  episode_sub_ = nh_.subscribe("episode", 10, &DatasetRecorder::onEpisode, this);
  extras_subscribed_ = true;
}

void DatasetRecorder::announceReady() {
  // "Ready" only once the per-frame topics and the frames are connected: a synchronous source
  // starts at that answer, and a message published before a connection exists is lost.
  std::string unconnected;
  for (const ros::Subscriber& sub : part_subs_) {
    if (sub.getNumPublishers() == 0) unconnected += " " + sub.getTopic();
  }
  if (frame_sub_.getNumPublishers() == 0) unconnected += " " + frame_sub_.getTopic();
  // Markers only of the sensors that have them: their renderers advertise the topic before
  // their image, so once the images are connected the master knows.
  if (unconnected.empty()) unconnected = unconnectedMarkers();
  const ros::WallTime now = ros::WallTime::now();
  if (!unconnected.empty()) {
    ROS_INFO_THROTTLE(5.0, "dataset_recorder: waiting for publishers of%s", unconnected.c_str());
    return;
  }
  // Extra topics (TF, clock, joints) may legitimately have no publisher: a short grace period.
  if (connected_since_.isZero()) connected_since_ = now;
  std::string optional;
  for (const ros::Subscriber& sub : extra_subs_) {
    if (sub.getNumPublishers() == 0) optional += " " + sub.getTopic();
  }
  if (!optional.empty() && (now - connected_since_).toSec() < 1.0) return;
  if (!optional.empty()) {
    ROS_INFO("dataset_recorder: no publisher (yet) of%s; recording without waiting for them",
             optional.c_str());
  }
  ready_timer_.stop();
  FrameRendered ready;
  ready.sensor = params_.answer_as;
  ready.reason = lock_step::kReady;
  answer_pub_.publish(ready);
}

std::string DatasetRecorder::unconnectedMarkers() const {
  std::string unconnected;
  std::vector<ros::master::TopicInfo> advertised;
  bool asked = false;
  for (const ros::Subscriber& sub : marker_subs_) {
    if (sub.getNumPublishers() > 0) continue;
    if (!asked && !ros::master::getTopics(advertised)) return " (the master's topics)";
    asked = true;
    for (const ros::master::TopicInfo& topic : advertised) {
      if (topic.name == sub.getTopic()) unconnected += " " + sub.getTopic();
    }
  }
  return unconnected;
}

int DatasetRecorder::partsPerFrame() const {
  int parts = static_cast<int>(part_subs_.size());
  for (const ros::Subscriber& sub : marker_subs_) parts += sub.getNumPublishers() > 0;
  return parts;
}

void DatasetRecorder::openNextBag() {
  if (bag_) bag_->close();
  const std::string path = params_.output_dir + "/" + params_.prefix + "_shard" +
                           std::to_string(params_.shard) + "_" + std::to_string(bag_paths_.size()) +
                           ".bag";
  bag_ = std::make_unique<rosbag::Bag>();
  try {
    bag_->open(path, rosbag::bagmode::Write);
  } catch (const rosbag::BagException& e) {
    throw Error("bag '" + path + "' cannot be opened: " + e.what());
  }
  bag_->setCompression(params_.compression == "lz4"   ? rosbag::compression::LZ4
                       : params_.compression == "bz2" ? rosbag::compression::BZ2
                                                      : rosbag::compression::Uncompressed);
  bag_paths_.push_back(path);
}

void DatasetRecorder::onEpisode(const EpisodeInfo::ConstPtr& info) {
  episode_ = *info;
  label_from_[info->header.stamp] = info->material + "/variant" + std::to_string(info->variant);
  shards_.insert(info->shard);
}

std::string DatasetRecorder::labelAt(const ros::Time& stamp) const {
  auto it = label_from_.upper_bound(stamp);
  if (it == label_from_.begin()) return "unlabelled";
  return std::prev(it)->second;
}

bool DatasetRecorder::write(const std::string& topic,
                            const std::function<void(const ros::Time&)>& write_message) {
  ++received_[topic];
  if (done_) return false;
  // A full disk would leave a bag without its index (unreadable until `rosbag reindex`): stop
  // while the index and the manifest still fit. Checked every 8 writes (~2 frames, ~1 MB).
  if (params_.min_free_mb > 0.0 && ++writes_since_space_check_ >= 8) {
    writes_since_space_check_ = 0;
    const double free_mb = freeMegabytes(params_.output_dir);
    if (free_mb < params_.min_free_mb && error_.empty()) {
      error_ = "the disk of '" + params_.output_dir + "' is nearly full: " + text(free_mb) +
               " MB free, under ~min_free_mb = " + text(params_.min_free_mb) +
               " MB; recording stopped, the bag is closed with the frames written so far";
      ROS_ERROR("dataset_recorder: %s", error_.c_str());
      stop_reason_ = stop_reason::kDiskFull;
      done_ = true;
      return false;
    }
  }
  ros::Time when = ros::Time::now();
  if (when < ros::TIME_MIN) when = ros::TIME_MIN;  // bags cannot hold time 0
  try {
    write_message(when);
  } catch (const rosbag::BagException& ex) {
    error_ = std::string("writing ") + topic + " to " + bag_paths_.back() + " failed: " + ex.what();
    ROS_ERROR("dataset_recorder: %s; closing the bag", error_.c_str());
    stop_reason_ = stop_reason::kError;
    done_ = true;
    return false;
  }
  ++written_[topic];
  return true;
}

void DatasetRecorder::onMessage(const std::string& topic,
                                const ros::MessageEvent<topic_tools::ShapeShifter>& e) {
  if (!write(topic, [&](const ros::Time& when) {
        bag_->write(topic, when, e.getConstMessage(), e.getConnectionHeaderPtr());
      })) {
    return;
  }
  if (params_.split_mb > 0.0 && bag_->getSize() > params_.split_mb * 1e6) openNextBag();
}

void DatasetRecorder::onFramePart(const std::string& topic, const ros::Time& stamp,
                                  const std::function<void(const ros::Time&)>& write_message) {
  if (!write(topic, write_message)) return;
  // A part of a frame already complete (a markers topic that connected while its frame was
  // under way) is written but counts for nothing: it must not open the frame again.
  if (!completed_.count(stamp) && ++parts_at_[stamp] >= partsPerFrame()) {
    parts_at_.erase(stamp);
    completed_.insert(stamp);
    // Remembered for a while: the frame's SimFrame may arrive after its last part.
    if (completed_.size() > 10000) completed_.erase(completed_.begin());
  }
  if (endsWith(topic, "/image_raw")) {
    ++images_;
    image_stamps_.push_back(stamp);
    last_image_stamp_ = std::max(last_image_stamp_, stamp);
    if (params_.samples > 0 && images_ >= static_cast<std::uint64_t>(params_.samples)) {
      target_reached_ = true;
      if (stop_reason_.empty()) stop_reason_ = stop_reason::kSampleTarget;
    }
    const ros::WallTime now = ros::WallTime::now();
    if ((now - last_progress_).toSec() >= 1.0) {
      last_progress_ = now;
      const double rate = images_ / std::max(1e-9, (now - started_).toSec());
      ROS_INFO("dataset_recorder: %lu images (%s) at %.0f/s%s", static_cast<unsigned long>(images_),
               params_.samples > 0 ? (text(params_.samples) + " wanted").c_str() : "no limit", rate,
               params_.samples > 0
                   ? (", ETA " + text(static_cast<int>((params_.samples - images_) / rate)) + " s")
                         .c_str()
                   : "");
    }
  }
  answerFramesWritten();
  // At the target, finish the frames already begun (every topic of the last frame), then stop.
  if (target_reached_) {
    bool open_frames = false;
    for (const auto& [t, parts] : parts_at_) {
      if (t <= last_image_stamp_) open_frames = true;  // parts_at_ holds incomplete frames only
    }
    if (!open_frames) done_ = true;
  }
  if (params_.split_mb > 0.0 && bag_->getSize() > params_.split_mb * 1e6) openNextBag();
}

void DatasetRecorder::onFrame(const SimFrame::ConstPtr& frame) {
  if (frame->last) last_frame_stamp_ = frame->header.stamp;
  if (frame->acknowledge && !params_.answer_as.empty()) {
    waiting_[frame->header.stamp] = frame->frame;
  }
  answerFramesWritten();
}

bool DatasetRecorder::frameComplete(const ros::Time& stamp) const {
  return completed_.count(stamp) > 0;
}

void DatasetRecorder::answerFramesWritten() {
  // A synchronous frame is answered once every sensor's image, camera_info, depth and contact of
  // it (and shear, markers) are in the bag.
  for (auto it = waiting_.begin(); it != waiting_.end();) {
    if (!frameComplete(it->first)) {
      ++it;
      continue;
    }
    FrameRendered answer;
    answer.header.stamp = it->first;
    answer.sensor = params_.answer_as;
    answer.frame = it->second;
    answer.published = true;
    answer_pub_.publish(answer);
    it = waiting_.erase(it);
  }
  // The source's last frame written: stop (the answer above let the source finish).
  if (!last_frame_stamp_.isZero() && frameComplete(last_frame_stamp_) && !done_) {
    if (stop_reason_.empty()) stop_reason_ = stop_reason::kLastFrame;
    done_ = true;
  }
}

void DatasetRecorder::close() {
  if (closed_) return;
  closed_ = true;
  // Finished (or stopped): leave the lock-step, so that the frame source stops waiting for
  // answers this recorder will not give. First, so it is on its way while the bag is indexed.
  if (!params_.answer_as.empty() && answer_pub_ && ros::ok()) {
    FrameRendered leaving;
    leaving.sensor = params_.answer_as;
    leaving.reason = lock_step::kLeaving;
    answer_pub_.publish(leaving);
  }
  if (stop_reason_.empty()) stop_reason_ = stop_reason::kShutdown;
  try {
    if (bag_) bag_->close();  // writes the index: `rosbag info` reads it
  } catch (const rosbag::BagException& e) {
    // The disk filled up under min_free_mb (or it is 0): the chunks are there, the index not.
    const std::string why = std::string("closing ") + bag_paths_.back() + " failed: " + e.what() +
                            "; `rosbag reindex` recovers the frames written";
    error_ = error_.empty() ? why : error_ + "; " + why;
    ROS_ERROR("dataset_recorder: %s", why.c_str());
  }
  const std::string path = params_.output_dir + "/" + params_.prefix + "_shard" +
                           std::to_string(params_.shard) + ".yaml";
  std::ofstream manifest(path);
  manifest << "# norm2tex dataset manifest (dataset_recorder)\n"
           << "package_version: " << NORM2TEX_VERSION << "\n"
           << "shard: " << params_.shard << "\n"
           << "compression: " << params_.compression << "\n"
           << "images: " << images_ << "\n"
           << "samples_wanted: " << params_.samples << "\n"
           << "stop_reason: " << stop_reason_ << "\n"
           << "complete: "
           << (error_.empty() && (stop_reason_ == stop_reason::kLastFrame ||
                                  stop_reason_ == stop_reason::kSampleTarget)
                   ? "true"
                   : "false")
           << "\n";
  manifest << "shards_seen: [";
  for (auto it = shards_.begin(); it != shards_.end(); ++it) {
    manifest << (it == shards_.begin() ? "" : ", ") << *it;
  }
  manifest << "]\n";
  if (!error_.empty()) manifest << "error: \"" << error_ << "\"\n";
  manifest << "bags:\n";
  for (const std::string& bag : bag_paths_) {
    manifest << "  - " << std::filesystem::path(bag).filename().string() << "\n";
  }
  manifest << "last_episode: {episode: " << episode_.episode << ", object: '" << episode_.object
           << "', material: '" << episode_.material << "', variant: " << episode_.variant
           << ", beta: " << episode_.beta << ", seed: " << episode_.seed << ", scenario: '"
           << episode_.scenario << "'}\n"
           << "images_per_label:\n";
  std::map<std::string, std::uint64_t> images_per_label;
  for (const ros::Time& stamp : image_stamps_) ++images_per_label[labelAt(stamp)];
  for (const auto& [label, count] : images_per_label) {
    manifest << "  '" << label << "': " << count << "\n";
  }
  manifest << "topics:  # received / written\n";
  for (const auto& [topic, count] : received_) {
    manifest << "  '" << topic << "': {received: " << count << ", written: " << written_[topic]
             << "}\n";
  }
  ROS_INFO("dataset_recorder: %lu images in %zu bag(s); manifest %s",
           static_cast<unsigned long>(images_), bag_paths_.size(), path.c_str());
}

}  // namespace norm2tex
