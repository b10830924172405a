#include "tactile_bag_reader.hpp"

#include <set>
#include <tuple>

#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>

#include "conversions.hpp"
#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

/// "/digit_left/image_raw" -> ("digit_left", "image_raw").
std::pair<std::string, std::string> splitTopic(const std::string& topic) {
  const std::size_t slash = topic.rfind('/');
  if (slash == std::string::npos) return {"", topic};
  if (slash == 0) return {"", topic.substr(1)};
  const std::size_t start = topic[0] == '/' ? 1 : 0;
  return {topic.substr(start, slash - start), topic.substr(slash + 1)};
}

struct Partial {
  TactileSample sample;
  bool has_image = false, has_depth = false, has_shear = false;
};

/// The per-frame topics a sample joins.
bool isFramePart(const std::string& leaf) {
  return leaf == "image_raw" || leaf == "depth" || leaf == "contact" || leaf == "markers" ||
         leaf == "shear";
}

/// The message type this reader reads a per-frame topic as: its MD5 sum, and its name.
std::pair<std::string, std::string> typeOf(const std::string& leaf) {
  if (leaf == "contact") {
    return {ros::message_traits::MD5Sum<TactileContact>::value(),
            ros::message_traits::DataType<TactileContact>::value()};
  }
  if (leaf == "markers") {
    return {ros::message_traits::MD5Sum<TactileMarkers>::value(),
            ros::message_traits::DataType<TactileMarkers>::value()};
  }
  return {ros::message_traits::MD5Sum<sensor_msgs::Image>::value(),
          ros::message_traits::DataType<sensor_msgs::Image>::value()};
}

}  // namespace

TactileBagReader::TactileBagReader(std::vector<std::string> bag_paths)
    : paths_(std::move(bag_paths)) {
  if (paths_.empty()) throw Error("no bag given");
  for (const std::string& path : paths_) {
    try {
      rosbag::Bag bag(path, rosbag::bagmode::Read);
    } catch (const rosbag::BagException& e) {
      throw Error("'" + path + "' is not a readable bag: " + e.what());
    }
  }
}

std::uint64_t TactileBagReader::forEachSample(
    const std::function<void(const TactileSample&)>& visit) {
  // Which per-frame topics each sensor has, over all bags: a frame waits for exactly those.
  // And every background first (a small latched topic, read through the bag index): the
  // recorder may store it after the first frames of its sensor, which must not be handed over
  // without it.
  std::map<std::string, std::set<std::string>> leaves;
  for (const std::string& path : paths_) {
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    std::vector<std::string> background_topics;
    {
      rosbag::View view(bag);
      for (const rosbag::ConnectionInfo* c : view.getConnections()) {
        const auto [sensor, leaf] = splitTopic(c->topic);
        if (leaf == "background") background_topics.push_back(c->topic);
        if (!isFramePart(leaf)) continue;
        // Another version of the message (a bag recorded before a field was added) cannot be
        // decoded as this one: its frames come without it rather than never.
        const auto [md5, type] = typeOf(leaf);
        if (c->md5sum != md5) {
          warnings_.push_back("'" + path + "': " + c->topic +
                              " was recorded as another version of " + type + " (MD5 " +
                              c->md5sum + ", this reader's " + md5 +
                              "); its frames are read without it");
          continue;
        }
        leaves[sensor].insert(leaf);
      }
    }
    if (background_topics.empty()) continue;
    rosbag::View view(bag, rosbag::TopicQuery(background_topics));
    for (const rosbag::MessageInstance& m : view) {
      if (auto image = m.instantiate<sensor_msgs::Image>()) {
        backgrounds_[splitTopic(m.getTopic()).first] = ros_conversions::fromImageMsg(*image);
      }
    }
  }
  // Every episode label first (a small topic, read through the bag index): an episode message
  // may be stored after frames of its episode (a pipelined source runs the clock ahead), so
  // labels are joined by stamp, not by the order in the bag.
  std::map<ros::Time, EpisodeInfo> episodes;
  for (const std::string& path : paths_) {
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{"/episode", "episode"}));
    for (const rosbag::MessageInstance& m : view) {
      if (auto info = m.instantiate<EpisodeInfo>()) episodes[info->header.stamp] = *info;
    }
  }
  std::map<std::pair<std::string, ros::Time>, Partial> pending;
  std::uint64_t count = 0;
  auto episodeAt = [&](const ros::Time& stamp) {
    auto it = episodes.upper_bound(stamp);
    return it == episodes.begin() ? EpisodeInfo() : std::prev(it)->second;
  };
  auto complete = [&](const Partial& p) {
    const std::set<std::string>& has = leaves[p.sample.sensor];
    return p.has_image && (p.has_depth || !has.count("depth")) &&
           (p.sample.has_contact || !has.count("contact")) &&
           (p.sample.has_markers || !has.count("markers")) &&
           (p.has_shear || !has.count("shear"));
  };
  // Complete frames are handed over in stamp order: a pipelined source's frames may complete
  // out of order by a few; hold them until the bag's time has passed their stamp.
  std::map<std::pair<ros::Time, std::string>, TactileSample> ready;
  auto emitReady = [&](const ros::Time* before) {
    while (!ready.empty() && (!before || ready.begin()->first.first < *before)) {
      TactileSample& sample = ready.begin()->second;
      sample.episode = episodeAt(sample.stamp);
      visit(sample);
      ++count;
      ready.erase(ready.begin());
    }
  };
  for (const std::string& path : paths_) {
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    rosbag::View view(bag);
    for (const rosbag::MessageInstance& m : view) {
      const ros::Time bag_time = m.getTime();
      emitReady(&bag_time);
      const auto [sensor, leaf] = splitTopic(m.getTopic());
      if (leaf == "episode" || leaf == "background") continue;  // read above
      if (!isFramePart(leaf)) continue;
      ros::Time stamp;
      TactileContact::ConstPtr contact;
      TactileMarkers::ConstPtr markers;
      sensor_msgs::Image::ConstPtr image;
      if (leaf == "contact") {
        contact = m.instantiate<TactileContact>();
        if (!contact) continue;
        stamp = contact->header.stamp;
      } else if (leaf == "markers") {
        markers = m.instantiate<TactileMarkers>();
        if (!markers) continue;
        stamp = markers->header.stamp;
      } else {
        image = m.instantiate<sensor_msgs::Image>();
        if (!image) continue;
        stamp = image->header.stamp;
      }
      auto it = pending.try_emplace({sensor, stamp}).first;
      Partial& p = it->second;
      p.sample.sensor = sensor;
      p.sample.stamp = stamp;
      try {
        if (leaf == "image_raw") {
          p.sample.image = ros_conversions::fromImageMsg(*image);
          if (p.sample.image.type() != CV_8UC3) throw Error("image_raw is not a colour image");
          p.sample.bag = path;
          p.has_image = true;
        } else if (leaf == "depth") {
          p.sample.depth_m = ros_conversions::fromImageMsg(*image);
          p.has_depth = true;
        } else if (leaf == "shear") {
          const cv::Mat shear = ros_conversions::fromImageMsg(*image);
          if (shear.type() != CV_32FC2) throw Error("shear is not a 32FC2 image");
          p.sample.shear_m = shear;
          p.has_shear = true;
        } else if (leaf == "markers") {
          p.sample.markers = *markers;
          p.sample.has_markers = true;
        } else {
          p.sample.contact = *contact;
          p.sample.has_contact = true;
        }
      } catch (const Error& e) {
        throw Error("bag '" + path + "', " + m.getTopic() + " at " + std::to_string(stamp.toSec()) +
                    " s: " + e.what());
      }
      if (complete(p)) {
        ready.emplace(std::make_pair(stamp, sensor), std::move(p.sample));
        pending.erase(it);
      }
    }
  }
  // What never completed (a recording cut short): handed over with what there is.
  for (auto& [key, p] : pending) {
    if (p.has_image) ready.emplace(std::make_pair(key.second, key.first), std::move(p.sample));
  }
  emitReady(nullptr);
  return count;
}

}  // namespace norm2tex
