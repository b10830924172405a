// The paper's probe collection end to end, with real masters, nodes and bags:
// record_dataset.launch (probe_sim + tactile_renderer + dataset_recorder) runs to completion by
// itself, and the bags are read back. Every frame is a contact with its labels; a seed
// reproduces its images bit for bit (nodelets or nodes); another seed probes elsewhere; two
// shards are disjoint and together give the unsharded dataset; the export round-trips.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "../core/test_helpers.hpp"
#include "conversions.hpp"
#include "dataset_export.hpp"
#include "norm2tex/common/error.hpp"
#include "run_node.hpp"
#include "tactile_bag_reader.hpp"

namespace norm2tex {
namespace {
namespace fs = std::filesystem;

/// A TCP port nobody listens on now, for this run's own master: from scripts/free_port, below
/// the kernel's ephemeral range (roslaunch's own server takes an ephemeral port before the
/// master binds its port, and could be handed the same one).
int freePort() {
  std::string output;
  EXPECT_EQ(test::runCommand(std::string(NORM2TEX_SOURCE_DIR) + "/scripts/free_port", output), 0)
      << output;
  return std::stoi(output);
}

const fs::path& scratch() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("norm2tex_probe_test_" + std::to_string(getpid()));
    fs::remove_all(d);
    fs::create_directories(d / "ros_home");
    return d;
  }();
  return dir;
}

std::string readFile(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// Runs record_dataset.launch on its own master until it exits by itself; returns the output
/// directory. 40 frames: wood and fabric, 2 variants each, presses of 5 frames.
fs::path record(const std::string& name, const std::string& extra_args) {
  const fs::path out = scratch() / name;
  const int port = freePort();
  std::ostringstream command;
  command << "ROS_HOME=" << (scratch() / "ros_home") << " ROS_MASTER_URI=http://localhost:" << port
          << " timeout 300 roslaunch -p " << port
          << " norm2tex record_dataset.launch material:=wood,fabric variants:=2 samples:=20"
          << " slides:=4 out:=" << out << " " << extra_args;
  std::string output;
  const int status = test::runCommand(command.str(), output);
  EXPECT_EQ(status, 0) << output;
  return out;
}

std::vector<std::string> bagsIn(const fs::path& dir) {
  std::vector<std::string> bags;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() == ".bag") bags.push_back(entry.path().string());
  }
  std::sort(bags.begin(), bags.end());
  return bags;
}

struct Frame {
  TactileSample sample;
  int slide = 0;  ///< position within its press
};

/// Every frame of a recording, by stamp.
std::map<ros::Time, Frame> framesOf(const fs::path& dir) {
  std::map<ros::Time, Frame> frames;
  TactileBagReader reader(bagsIn(dir));
  std::map<std::uint32_t, int> seen_in_episode;
  reader.forEachSample([&](const TactileSample& s) {
    Frame f{s, seen_in_episode[s.episode.episode]++};
    frames.emplace(s.stamp, f);
  });
  return frames;
}

using PressKey = std::tuple<std::string, std::uint32_t, std::uint64_t, int>;  // material, variant, press, slide
PressKey keyOf(const Frame& f) {
  return {f.sample.episode.material, f.sample.episode.variant, f.sample.episode.press, f.slide};
}

double maxOf(const cv::Mat& m) {
  double lo = 0, hi = 0;
  cv::minMaxLoc(m, &lo, &hi);
  return hi;
}

class ProbeDataset : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    seed3_ = new fs::path(record("seed3", "seed:=3"));
    frames3_ = new std::map<ros::Time, Frame>(framesOf(*seed3_));
  }
  static void TearDownTestSuite() {
    delete seed3_;
    delete frames3_;
    fs::remove_all(scratch());
  }
  static fs::path* seed3_;
  static std::map<ros::Time, Frame>* frames3_;
};
fs::path* ProbeDataset::seed3_ = nullptr;
std::map<ros::Time, Frame>* ProbeDataset::frames3_ = nullptr;

TEST_F(ProbeDataset, EveryFrameIsALabelledContactAndNothingIsLost) {
  const std::string manifest = readFile(*seed3_ / "norm2tex_shard0.yaml");
  EXPECT_NE(manifest.find("images: 40"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("stop_reason: last_frame"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("complete: true"), std::string::npos) << manifest;
  // Per label, joined by stamp (an image may arrive before the EpisodeInfo that labels it).
  for (const char* label : {"wood/variant0", "wood/variant1", "fabric/variant0", "fabric/variant1"}) {
    EXPECT_NE(manifest.find("'" + std::string(label) + "': 10\n"), std::string::npos)
        << label << "\n" << manifest;
  }
  EXPECT_EQ(manifest.find("unlabelled"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("'/digit_left/image_raw': {received: 40, written: 40}"),
            std::string::npos)
      << manifest;
  std::string info;
  EXPECT_EQ(test::runCommand("rosbag info " + bagsIn(*seed3_).front(), info), 0) << info;

  ASSERT_EQ(frames3_->size(), 40u);
  std::map<std::pair<std::string, std::uint32_t>, int> per_label;
  std::set<std::uint32_t> episodes;
  for (const auto& [stamp, f] : *frames3_) {
    const TactileSample& s = f.sample;
    EXPECT_EQ(s.sensor, "digit_left");
    EXPECT_EQ(s.image.rows, 320);
    EXPECT_EQ(s.image.cols, 240);
    ASSERT_TRUE(s.has_contact) << stamp;
    EXPECT_TRUE(s.contact.in_contact) << stamp;
    // The rendered gel is indented as deep as the press (the gel model keeps the peak).
    ASSERT_FALSE(s.depth_m.empty());
    EXPECT_GT(maxOf(s.depth_m), 0.5 * s.episode.press_depth) << stamp;
    EXPECT_NEAR(s.contact.max_indentation, s.episode.press_depth, 2e-6) << stamp;
    EXPECT_GE(s.episode.press_depth, 0.0003);
    EXPECT_LE(s.episode.press_depth, 0.0012);
    EXPECT_EQ(s.episode.scenario, "probe");
    EXPECT_EQ(s.episode.object, "cube");
    EXPECT_EQ(s.episode.num_shards, 1u);
    ++per_label[{s.episode.material, s.episode.variant}];
    episodes.insert(s.episode.episode);
    EXPECT_LT(f.slide, 5);
  }
  // 20 images per material over 2 variants; presses of 5 frames.
  for (const auto& label : {std::make_pair(std::string("wood"), 0u), {"wood", 1u}, {"fabric", 0u},
                            {"fabric", 1u}}) {
    EXPECT_EQ(per_label[label], 10) << label.first << "/" << label.second;
  }
  EXPECT_EQ(episodes.size(), 8u);
}

TEST_F(ProbeDataset, ASeedReproducesItsImagesAndAnotherSeedProbesElsewhere) {
  // The same seed as nodes instead of nodelets: identical images, bit for bit.
  const std::map<ros::Time, Frame> again = framesOf(record("seed3_nodes", "seed:=3 manager:=false"));
  ASSERT_EQ(again.size(), frames3_->size());
  for (const auto& [stamp, f] : *frames3_) {
    const auto it = again.find(stamp);
    ASSERT_NE(it, again.end()) << stamp;
    EXPECT_EQ(cv::norm(it->second.sample.image, f.sample.image, cv::NORM_INF), 0.0) << stamp;
    EXPECT_EQ(keyOf(it->second), keyOf(f));
  }
  // Seed 4: other points, other depths.
  const std::map<ros::Time, Frame> other = framesOf(record("seed4", "seed:=4"));
  ASSERT_EQ(other.size(), frames3_->size());
  int same_depth = 0;
  for (const auto& [stamp, f] : *frames3_) {
    if (other.at(stamp).sample.episode.press_depth == f.sample.episode.press_depth) ++same_depth;
  }
  EXPECT_EQ(same_depth, 0);
}

TEST_F(ProbeDataset, TwoShardsAreDisjointAndTogetherTheWholeDataset) {
  std::map<PressKey, const Frame*> whole;
  for (const auto& [stamp, f] : *frames3_) whole[keyOf(f)] = &f;
  std::map<PressKey, int> covered;
  std::vector<std::map<ros::Time, Frame>> shards;
  for (int k = 0; k < 2; ++k) {
    const fs::path dir = record("shard" + std::to_string(k),
                                "seed:=3 num_shards:=2 shard:=" + std::to_string(k));
    const std::string manifest = readFile(dir / ("norm2tex_shard" + std::to_string(k) + ".yaml"));
    EXPECT_NE(manifest.find("complete: true"), std::string::npos) << manifest;
    shards.push_back(framesOf(dir));
    for (const auto& [stamp, f] : shards.back()) {
      EXPECT_EQ(f.sample.episode.shard, static_cast<std::uint32_t>(k));
      EXPECT_EQ(f.sample.episode.num_shards, 2u);
      ++covered[keyOf(f)];
      // The same press and slide as in the unsharded run: the same noise-free depth image.
      const auto it = whole.find(keyOf(f));
      ASSERT_NE(it, whole.end());
      EXPECT_EQ(cv::norm(f.sample.depth_m, it->second->sample.depth_m, cv::NORM_INF), 0.0);
    }
  }
  EXPECT_EQ(shards[0].size() + shards[1].size(), 40u);
  EXPECT_EQ(covered.size(), whole.size());
  for (const auto& [key, n] : covered) EXPECT_EQ(n, 1);
}

TEST_F(ProbeDataset, SplitBagsAreEachValidAndTogetherHoldEveryFrame) {
  // About 0.5 MB a frame: 40 frames split at 4 MB give several bags.
  const fs::path dir = record("split", "seed:=3 split_mb:=4");
  const std::vector<std::string> bags = bagsIn(dir);
  EXPECT_GE(bags.size(), 4u);
  for (const std::string& bag : bags) {
    std::string info;
    EXPECT_EQ(test::runCommand("rosbag info " + bag, info), 0) << info;
  }
  const std::string manifest = readFile(dir / "norm2tex_shard0.yaml");
  for (const std::string& bag : bags) {
    EXPECT_NE(manifest.find(fs::path(bag).filename().string()), std::string::npos) << manifest;
  }
  // Read as one recording: the same 40 frames, bit for bit, a frame cut by a split joined.
  const std::map<ros::Time, Frame> frames = framesOf(dir);
  ASSERT_EQ(frames.size(), frames3_->size());
  for (const auto& [stamp, f] : *frames3_) {
    const Frame& split = frames.at(stamp);
    EXPECT_EQ(cv::norm(split.sample.image, f.sample.image, cv::NORM_INF), 0.0) << stamp;
    EXPECT_EQ(cv::norm(split.sample.depth_m, f.sample.depth_m, cv::NORM_INF), 0.0) << stamp;
    EXPECT_TRUE(split.sample.has_contact);
    EXPECT_EQ(keyOf(split), keyOf(f));
  }
}

TEST_F(ProbeDataset, AFullDiskEndsRecordingWithAClearErrorAndAValidBag) {
  // A 24 MB file system (tmpfs) holds ~40 frames of 0.5 MB; the recorder stops with 8 MB left.
  const fs::path mount_point = scratch() / "small_disk";
  fs::create_directories(mount_point);
  std::string output;
  if (test::runCommand("mount -t tmpfs -o size=24m norm2tex_test " + mount_point.string(),
                       output) != 0) {
    GTEST_SKIP() << "SKIPPED: cannot mount a small tmpfs here (needs root): " << output;
  }
  struct Unmount {
    fs::path at;
    ~Unmount() {
      std::string ignored;
      test::runCommand("umount " + at.string(), ignored);
    }
  } unmount{mount_point};
  const fs::path dir = record("small_disk/out", "seed:=3 samples:=200 min_free_mb:=8");
  const std::string manifest = readFile(dir / "norm2tex_shard0.yaml");
  EXPECT_NE(manifest.find("stop_reason: disk_full"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("complete: false"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("is nearly full"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find(dir.string()), std::string::npos) << "the error names the directory";
  // The bag is closed and indexed: rosbag reads it, and the reader finds the frames written.
  const std::vector<std::string> bags = bagsIn(dir);
  ASSERT_EQ(bags.size(), 1u);
  std::string info;
  EXPECT_EQ(test::runCommand("rosbag info " + bags[0], info), 0) << info;
  const std::size_t images_at = manifest.find("images: ");
  ASSERT_NE(images_at, std::string::npos);
  const int images = std::stoi(manifest.substr(images_at + 8));
  EXPECT_GE(images, 10);
  EXPECT_LT(images, 80);  // it stopped long before the 4 x 200 frames asked for
  const std::map<ros::Time, Frame> frames = framesOf(dir);
  // Every image written is read back; the last frame may lack parts written after the stop.
  EXPECT_GE(static_cast<int>(frames.size()), images - 1);
  EXPECT_LE(static_cast<int>(frames.size()), images);
  for (const auto& [stamp, f] : frames) EXPECT_FALSE(f.sample.image.empty()) << stamp;
}

TEST_F(ProbeDataset, ExportRoundTripsFramesLabelsAndBackgroundSubtraction) {
  ExportOptions options;
  options.out_dir = (scratch() / "export").string();
  const ExportSummary summary = exportDataset(bagsIn(*seed3_), options);
  EXPECT_EQ(summary.frames, 40u);
  EXPECT_EQ(summary.frames_per_material.at("wood"), 20u);
  EXPECT_EQ(summary.frames_per_material.at("fabric"), 20u);
  std::ifstream labels(options.out_dir + "/labels.csv");
  std::string line;
  std::getline(labels, line);
  EXPECT_EQ(line.rfind("raw,diff,depth,material,variant,sensor,stamp,", 0), 0u) << line;
  int rows = 0;
  double untouched_sum = 0, touched_sum = 0;
  long untouched_n = 0, touched_n = 0;
  while (std::getline(labels, line)) {
    ++rows;
    std::vector<std::string> fields;
    std::stringstream row(line);
    for (std::string field; std::getline(row, field, ',');) fields.push_back(field);
    ASSERT_GE(fields.size(), 8u);
    const cv::Mat3b raw = cv::imread(options.out_dir + "/" + fields[0], cv::IMREAD_COLOR);
    const cv::Mat diff = cv::imread(options.out_dir + "/" + fields[1], cv::IMREAD_COLOR);
    const cv::Mat depth_um = cv::imread(options.out_dir + "/" + fields[2], cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(raw.empty() || diff.empty() || depth_um.empty()) << line;
    ASSERT_EQ(depth_um.type(), CV_16UC1);
    // The PNG is the recorded frame, bit for bit.
    const Frame& f = frames3_->at(ros::Time().fromNSec(std::stoull(fields[6])));
    EXPECT_EQ(cv::norm(raw, f.sample.image, cv::NORM_INF), 0.0);
    EXPECT_EQ(fields[3], f.sample.episode.material);
    EXPECT_EQ(std::stoul(fields[4]), f.sample.episode.variant);
    cv::Mat signed_diff;
    diff.convertTo(signed_diff, CV_32FC3, 1.0, -128.0);
    for (int r = 0; r < diff.rows; ++r) {
      for (int c = 0; c < diff.cols; ++c) {
        const cv::Vec3f d = signed_diff.at<cv::Vec3f>(r, c);
        const double magnitude = (std::abs(d[0]) + std::abs(d[1]) + std::abs(d[2])) / 3.0;
        if (depth_um.at<std::uint16_t>(r, c) == 0 && f.sample.depth_m(r, c) == 0.0f) {
          untouched_sum += magnitude;
          ++untouched_n;
        } else if (depth_um.at<std::uint16_t>(r, c) > 200) {
          touched_sum += magnitude;
          ++touched_n;
        }
      }
    }
  }
  EXPECT_EQ(rows, 40);
  ASSERT_GT(untouched_n, 0);
  ASSERT_GT(touched_n, 0);
  // Where nothing touches the difference is the sensor noise only (sigma 2 grey levels: mean
  // |noise| 1.6), where the gel is pressed 0.2 mm or more it is many times that.
  EXPECT_LT(untouched_sum / untouched_n, 2.5);
  EXPECT_GT(touched_sum / touched_n, 4.0 * untouched_sum / untouched_n);

  // Not over an export without --force; a file that is not a bag is named.
  test::expectError([&] { exportDataset(bagsIn(*seed3_), options); }, {"not empty", "--force"});
  const fs::path fake = scratch() / "fake.bag";
  std::ofstream(fake) << "not a bag";
  ExportOptions elsewhere;
  elsewhere.out_dir = (scratch() / "export2").string();
  test::expectError([&] { exportDataset({fake.string()}, elsewhere); }, {"fake.bag", "not a readable bag"});
}

// A background stored after its sensor's first frames (the recorder writes the latched
// background when it arrives, which can be after the renderer's first images): every frame is
// handed over with its sensor's background already read, and the export subtracts it.
TEST(TactileBagReader, ABackgroundStoredAfterTheFirstFramesIsReadBeforeThem) {
  const fs::path dir = scratch() / "late_background";
  fs::create_directories(dir);
  const std::string bag_path = (dir / "late.bag").string();
  const cv::Mat3b background(320, 240, cv::Vec3b(90, 100, 110));
  {
    rosbag::Bag bag(bag_path, rosbag::bagmode::Write);
    std_msgs::Header header;
    header.frame_id = "digit_left_gel";
    for (int i = 0; i < 3; ++i) {
      header.stamp = ros::Time(1.0 + i / 60.0);
      const cv::Mat3b frame(320, 240, cv::Vec3b(100 + i, 100, 100));
      bag.write("/digit_left/image_raw", header.stamp, *ros_conversions::toImageMsg(header, frame));
    }
    header.stamp = ros::Time(2.0);  // after every frame, in the bag's time and order
    bag.write("/digit_left/background", header.stamp,
              *ros_conversions::toImageMsg(header, background));
  }
  TactileBagReader reader({bag_path});
  int visited = 0;
  reader.forEachSample([&](const TactileSample& sample) {
    ++visited;
    const auto it = reader.backgrounds().find(sample.sensor);
    ASSERT_NE(it, reader.backgrounds().end()) << "frame " << visited << " before its background";
    EXPECT_EQ(cv::norm(it->second, background, cv::NORM_INF), 0.0);
  });
  EXPECT_EQ(visited, 3);
}

}  // namespace
}  // namespace norm2tex
