#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <rosbag/bag.h>
#include <topic_tools/shape_shifter.h>

#include "norm2tex/EpisodeInfo.h"
#include "norm2tex/FrameRendered.h"
#include "norm2tex/SimFrame.h"

namespace norm2tex {

/// Why a recording ended: the manifest's `stop_reason` (docs/datasets.md lists these; the docs
/// check compares that list with this one). Only the first two make a complete dataset.
namespace stop_reason {
constexpr const char* kLastFrame = "last_frame";        ///< the source's last frame is written
constexpr const char* kSampleTarget = "sample_target";  ///< ~samples images are written
/// Stopped from outside before done: Ctrl-C or SIGTERM (the node), the nodelet unloaded or its
/// manager stopped, roslaunch ending, the master gone.
constexpr const char* kShutdown = "shutdown";
constexpr const char* kError = "error";         ///< a write failed (the manifest says which)
constexpr const char* kDiskFull = "disk_full";  ///< less than ~min_free_mb free on the output disk
}  // namespace stop_reason

/// Validated private parameters of dataset_recorder (docs/ros.md, "dataset_recorder").
struct DatasetRecorderParams {
  std::string output_dir;           ///< ~output_dir: created if missing; must be writable
  std::string prefix = "norm2tex";  ///< ~prefix: bags are <prefix>_shard<k>_<n>.bag
  int shard = 0;                    ///< ~shard: recorded in the file names and the manifest
  std::vector<std::string> sensors = {"digit_left", "digit_right"};  ///< ~sensors
  std::vector<std::string> topics;  ///< ~topics: extra topics (default: TF, joints, clock, episode)
  std::string compression = "lz4";  ///< ~compression: lz4 | bz2 | none
  int samples = 0;                  ///< ~samples: tactile images to record, then exit; 0 = no limit
  double split_mb = 0.0;            ///< ~split_mb: start a new bag past this size; 0 = one bag
  /// ~min_free_mb: recording ends (stop_reason disk_full, an error in the manifest) when the
  /// output file system has less free space than this, so the bag's index and the manifest
  /// still fit: the bag stays valid. 0 = write until a write fails.
  double min_free_mb = 64.0;
  /// ~answer_as: the name it answers synchronous frames under (list it in contact_sim's
  /// ~renderers); "" = never answer.
  std::string answer_as = "recorder";
  std::string frame_topic = "contact_sim/frame";      ///< ~frame_topic: the SimFrame source
  std::string answer_topic = "contact_sim/rendered";  ///< ~answer_topic: where answers go
  /// ~record_shear: also record each sensor's shear (the gel's lateral displacement, 32FC2),
  /// which makes the renderers compute it for every frame.
  bool record_shear = false;
};

DatasetRecorderParams readDatasetRecorderParams(const ros::NodeHandle& private_nh);

/// Writes every message of the sensors' image_raw, camera_info, depth and contact topics (and
/// markers for sensors that have them, shear with ~record_shear) and the extra topics into
/// rosbags, counting what it received and wrote per topic and the images per episode label.
/// In synchronous mode it answers each SimFrame (as sensor "recorder" on
/// contact_sim/rendered) once every sensor's image of that frame is written, so contact_sim can
/// wait for it: received = written. Closes (indexes) the bag and writes <prefix>_shard<k>.yaml,
/// the manifest, on close(): at the sample target, on SIGINT/SIGTERM, or on a write error.
class DatasetRecorder {
 public:
  /// Throws Error for bad parameters or an output directory that cannot be written.
  DatasetRecorder(ros::NodeHandle nh, ros::NodeHandle private_nh);
  ~DatasetRecorder();

  /// True once the sample target or the source's last frame is written, or a write failed (the
  /// node then exits).
  bool done() const { return done_; }
  /// Closes the current bag and writes the manifest; idempotent. Stopped before it was done
  /// (sample target, last frame, a write error), the manifest's stop_reason is `shutdown`.
  void close();
  /// Non-empty when writing failed (e.g. a full disk): why.
  const std::string& error() const { return error_; }

 private:
  /// Counts a received message on `topic` and writes it with `write_message(bag time)`; false
  /// (and done, with the error) when the write failed, or when recording is over.
  bool write(const std::string& topic, const std::function<void(const ros::Time&)>& write_message);
  /// Extra topics (TF, clock, joints, labels), as they come.
  void onMessage(const std::string& topic, const ros::MessageEvent<topic_tools::ShapeShifter>& e);
  /// Subscribes ~topics and the episodes (after construction, see the constructor).
  void subscribeExtraTopics();
  /// The sensors' per-frame topics: written, then counted towards their frame (`stamp`).
  void onFramePart(const std::string& topic, const ros::Time& stamp,
                   const std::function<void(const ros::Time&)>& write_message);
  void onFrame(const SimFrame::ConstPtr& frame);
  void onEpisode(const EpisodeInfo::ConstPtr& info);
  void openNextBag();
  void answerFramesWritten();
  /// Publishes the "ready" answer once the topics of every frame are connected.
  void announceReady();
  /// "material/variant" of the episode an image stamped `stamp` belongs to.
  std::string labelAt(const ros::Time& stamp) const;
  bool frameComplete(const ros::Time& stamp) const;
  /// How many per-frame messages make a frame: every sensor's required topics, and the markers
  /// of the sensors whose renderer publishes them.
  int partsPerFrame() const;
  /// The markers topics that are advertised (asked of the master) but not yet connected.
  std::string unconnectedMarkers() const;

  DatasetRecorderParams params_;
  std::unique_ptr<rosbag::Bag> bag_;
  std::vector<std::string> bag_paths_;
  std::map<std::string, std::uint64_t> received_, written_;
  /// Per frame stamp: messages written of the sensors' image_raw, camera_info, depth, contact
  /// (and shear, markers); a frame is complete at partsPerFrame(), and then moves to completed_.
  std::map<ros::Time, int> parts_at_;
  std::set<ros::Time> completed_;  ///< the latest 10000 complete frames
  ros::Time last_image_stamp_;
  bool target_reached_ = false;
  std::map<ros::Time, std::uint64_t> waiting_;  ///< synchronous frames to answer, by stamp
  /// Stamps of the images written, labelled at close(): an image may arrive before the
  /// EpisodeInfo that labels it (different topics), so labels are joined by stamp at the end.
  std::vector<ros::Time> image_stamps_;
  EpisodeInfo episode_;  ///< the latest episode
  /// Episodes by start stamp: an image belongs to the latest episode started at or before it
  /// (topics arrive on separate connections, so arrival order is not enough).
  std::map<ros::Time, std::string> label_from_;
  std::set<std::uint32_t> shards_;
  ros::Time last_frame_stamp_;  ///< the source's last frame, once announced
  std::string stop_reason_;
  std::uint64_t images_ = 0;
  bool done_ = false, closed_ = false;
  int writes_since_space_check_ = 0;  ///< ~min_free_mb is checked every few writes
  std::string error_;
  ros::WallTime started_, last_progress_;

  ros::NodeHandle nh_;
  std::vector<ros::Subscriber> extra_subs_;  ///< ~topics
  std::vector<ros::Subscriber> part_subs_;   ///< the sensors' per-frame topics
  /// The sensors' markers: per frame too, but only for sensors whose model has markers (their
  /// renderer advertises the topic).
  std::vector<ros::Subscriber> marker_subs_;
  bool extras_subscribed_ = false;
  ros::Subscriber frame_sub_, episode_sub_;
  ros::Publisher answer_pub_;
  ros::WallTimer ready_timer_;
  ros::WallTime connected_since_;
};

}  // namespace norm2tex
