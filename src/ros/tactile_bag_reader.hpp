#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <ros/time.h>

#include "norm2tex/EpisodeInfo.h"
#include "norm2tex/TactileContact.h"
#include "norm2tex/TactileMarkers.h"

namespace norm2tex {

/// One tactile frame of one sensor as recorded: the image with what was recorded beside it.
struct TactileSample {
  std::string sensor;  ///< e.g. "digit_left" (the topic's namespace)
  ros::Time stamp;     ///< the frame's stamp (header), shared by its image, depth and contact
  cv::Mat3b image;     ///< image_raw, BGR
  cv::Mat1f depth_m;   ///< depth (gel indentation, metres); empty when not recorded
  bool has_contact = false;
  TactileContact contact;  ///< valid when has_contact
  bool has_markers = false;
  TactileMarkers markers;  ///< valid when has_markers (sensors with markers)
  cv::Mat2f shear_m;       ///< shear (lateral displacement, metres); empty when not recorded
  /// The episode the frame belongs to: the latest EpisodeInfo stamped at or before the frame
  /// (episode 0, all fields empty, when the bag holds none before it).
  EpisodeInfo episode;
  std::string bag;  ///< the bag file the image came from
};

/// Reads the tactile frames of dataset_recorder bags, streaming (bags of many GB are fine): for
/// each <sensor>/image_raw it joins that frame's <sensor>/depth, contact, markers and shear (by
/// header stamp, those the bags have) and the episode label. Bags of one recording (split parts)
/// are read in the given order as one stream, so a frame cut by a split is still joined.
class TactileBagReader {
 public:
  /// Opens every bag now; throws Error naming a file that is missing or not a readable bag.
  explicit TactileBagReader(std::vector<std::string> bag_paths);

  /// Calls `visit` for every frame, in stamp order within a sensor; returns how many. A frame is
  /// handed over once its image and every per-frame topic its sensor has in these bags
  /// (depth, contact, markers, shear) are read, or at the end with what there is. Throws Error
  /// for an image message that cannot be decoded (naming the bag and stamp).
  std::uint64_t forEachSample(const std::function<void(const TactileSample&)>& visit);

  /// Each sensor's no-contact background (the renderer's latched <sensor>/background), once
  /// forEachSample has started (it reads them before any frame); sensors without one are absent.
  const std::map<std::string, cv::Mat3b>& backgrounds() const { return backgrounds_; }

  /// What forEachSample could not read and left out, one sentence each: per-frame topics
  /// recorded with another version of their message (a TactileContact of a bag recorded before
  /// it had twist_moment and slip_fraction: its frames come without contact labels).
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  std::vector<std::string> paths_;
  std::map<std::string, cv::Mat3b> backgrounds_;
  std::vector<std::string> warnings_;
};

}  // namespace norm2tex
