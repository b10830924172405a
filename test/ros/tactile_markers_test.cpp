// rostest (tactile_markers.test): a ball held between two gels that carry markers, in lock-step.
// Its weight shears the gels down the image: /<sensor>/markers shows the dots carried that way,
// /<sensor>/shear the field that carries them, TactileContact the slip it causes; opened, all of
// it is back at rest. The recorder's bags give back the same markers and fields. Conditions are
// awaited with deadlines.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "dataset_export.hpp"
#include "norm2tex/common/npy_file.hpp"
#include "norm2tex/Reset.h"
#include "norm2tex/Step.h"
#include "norm2tex/TactileContact.h"
#include "norm2tex/TactileMarkers.h"
#include "norm2tex/render/sensor_model.hpp"
#include "tactile_bag_reader.hpp"
#include "wait_for.hpp"

namespace {

using norm2tex::TactileContact;
using norm2tex::TactileMarkers;
using norm2tex::waitFor;

const char* const kSensors[2] = {"digit_left", "digit_right"};
const char* const kSensorYaml = NORM2TEX_SOURCE_DIR "/test/fixtures/digit_markers.yaml";

cv::Mat2f shearField(const sensor_msgs::Image& msg) {
  return cv::Mat2f(static_cast<int>(msg.height), static_cast<int>(msg.width),
                   reinterpret_cast<cv::Vec2f*>(const_cast<std::uint8_t*>(msg.data.data())),
                   msg.step)
      .clone();
}

// Everything one sensor published, by stamp; and how often each stamp came.
struct SensorLog {
  std::map<ros::Time, sensor_msgs::Image::ConstPtr> image, shear;
  std::map<ros::Time, TactileMarkers::ConstPtr> markers;
  std::map<ros::Time, TactileContact::ConstPtr> contact;
  std::map<ros::Time, int> images_at, markers_at, shears_at;
};

// One for the whole run: the recorder's frames are compared with what it logged.
struct Listener {
  ros::NodeHandle nh;
  std::map<std::string, SensorLog> log;
  std::vector<ros::Subscriber> subs;
  ros::ServiceClient step = nh.serviceClient<norm2tex::Step>("/contact_sim/step");
  ros::ServiceClient reset = nh.serviceClient<norm2tex::Reset>("/contact_sim/reset");

  Listener() {
    for (const char* s : kSensors) {
      SensorLog* l = &log[s];
      const std::string ns = s;
      subs.push_back(nh.subscribe<sensor_msgs::Image>(ns + "/image_raw", 1000, [l](const auto& m) {
        l->image[m->header.stamp] = m;
        ++l->images_at[m->header.stamp];
      }));
      subs.push_back(nh.subscribe<sensor_msgs::Image>(ns + "/shear", 1000, [l](const auto& m) {
        l->shear[m->header.stamp] = m;
        ++l->shears_at[m->header.stamp];
      }));
      subs.push_back(nh.subscribe<TactileMarkers>(ns + "/markers", 1000, [l](const auto& m) {
        l->markers[m->header.stamp] = m;
        ++l->markers_at[m->header.stamp];
      }));
      subs.push_back(nh.subscribe<TactileContact>(
          ns + "/contact", 1000, [l](const auto& m) { l->contact[m->header.stamp] = m; }));
    }
  }
  bool ready() {
    return step.waitForExistence(ros::Duration(60.0)) &&
           waitFor(
               [&] {
                 for (const ros::Subscriber& sub : subs) {
                   if (sub.getNumPublishers() == 0) return false;
                 }
                 return true;
               },
               60.0);
  }
  ros::Time stepFrames(std::uint32_t frames, double opening = -1.0) {
    norm2tex::Step srv;
    srv.request.frames = frames;
    if (opening >= 0.0) {
      srv.request.set_command = true;
      srv.request.command.mode = norm2tex::GripperCommand::ABSOLUTE;
      srv.request.command.opening = opening;
    }
    EXPECT_TRUE(step.call(srv));
    EXPECT_TRUE(srv.response.success) << srv.response.message;
    EXPECT_EQ(srv.response.missing_images, 0u);
    return srv.response.stamp;
  }
  // Both sensors' image, markers, shear and contact of `stamp` arrive.
  bool everythingOf(const ros::Time& stamp) {
    return waitFor(
        [&] {
          for (const char* s : kSensors) {
            SensorLog& l = log[s];
            if (!l.image.count(stamp) || !l.markers.count(stamp) || !l.shear.count(stamp) ||
                !l.contact.count(stamp)) {
              return false;
            }
          }
          return true;
        },
        10.0);
  }
};

Listener* the_listener = nullptr;  // made in main, after ros::init

Listener& listener() { return *the_listener; }

TEST(SynchronousMarkers, AHeldBallsWeightCarriesTheMarkersDownTheImageAndOpeningReleasesThem) {
  Listener& l = listener();
  ASSERT_TRUE(l.ready());
  const norm2tex::SensorModel model = norm2tex::loadSensorModel(kSensorYaml);
  ASSERT_TRUE(model.markers.enabled);
  norm2tex::Reset episode;
  episode.request.seed = 1;
  episode.request.height_offset = 0.0;
  ASSERT_TRUE(l.reset.call(episode));
  ASSERT_TRUE(episode.response.success) << episode.response.message;
  const ros::Time held = l.stepFrames(5);
  ASSERT_TRUE(l.everythingOf(held));

  for (const char* sensor : kSensors) {
    SCOPED_TRACE(sensor);
    SensorLog& log = l.log[sensor];
    const sensor_msgs::Image& image = *log.image[held];
    const TactileMarkers& markers = *log.markers[held];
    const sensor_msgs::Image& shear = *log.shear[held];
    const TactileContact& contact = *log.contact[held];
    // The image's stamp and frame on all three.
    EXPECT_EQ(markers.header.stamp, image.header.stamp);
    EXPECT_EQ(markers.header.frame_id, image.header.frame_id);
    EXPECT_EQ(shear.header.stamp, image.header.stamp);
    EXPECT_EQ(shear.header.frame_id, image.header.frame_id);
    EXPECT_EQ(image.header.frame_id, std::string(sensor) + "_gel");

    // The grid as configured, each dot where its displacement puts it.
    ASSERT_EQ(markers.rows, static_cast<std::uint32_t>(model.markers.rows));
    ASSERT_EQ(markers.cols, static_cast<std::uint32_t>(model.markers.cols));
    const std::size_t count = markers.rows * markers.cols;
    ASSERT_EQ(markers.rest_px.size(), count);
    ASSERT_EQ(markers.current_px.size(), count);
    ASSERT_EQ(markers.displacement_mm.size(), count);
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    double largest = 0.0;
    for (std::size_t i = 0; i < count; ++i) {
      const double dx = markers.displacement_mm[i].x, dy = markers.displacement_mm[i].y;
      EXPECT_NEAR(markers.current_px[i].x - markers.rest_px[i].x, dx / model.mm_per_pixel, 1e-3);
      EXPECT_NEAR(markers.current_px[i].y - markers.rest_px[i].y, dy / model.mm_per_pixel, 1e-3);
      sum += Eigen::Vector2d(dx, dy);
      largest = std::max(largest, std::hypot(dx, dy));
    }
    std::printf("%s held: markers moved %.4f mm at most, on average (%.5f, %.5f) mm; slip %.3f "
                "(contact %.3f), twist %.2e N m, shear force (%.3f, %.3f) N\n",
                sensor, largest, sum.x() / count, sum.y() / count, markers.slip_fraction,
                contact.slip_fraction, contact.twist_moment, contact.shear_force.x,
                contact.shear_force.y);
    // The ball hangs in the gels: it pulls them down the image (+y), not sideways.
    EXPECT_GT(contact.shear_force.y, 0.05);
    EXPECT_GT(largest, 0.01);  // mm: a fifth of a pixel
    EXPECT_GT(sum.y(), 0.0);
    EXPECT_LT(std::abs(sum.x()), 0.3 * sum.y());

    // The field: 32FC2, the image's size, metres; where a dot sits it moved the dot.
    ASSERT_EQ(shear.encoding, "32FC2");
    ASSERT_EQ(shear.height, image.height);
    ASSERT_EQ(shear.width, image.width);
    ASSERT_EQ(shear.data.size(), static_cast<std::size_t>(shear.step) * shear.height);
    const cv::Mat2f field = shearField(shear);
    double field_largest = 0.0;
    for (int r = 0; r < field.rows; ++r) {
      for (int c = 0; c < field.cols; ++c) {
        field_largest =
            std::max(field_largest, std::hypot<double>(field(r, c)[0], field(r, c)[1]));
      }
    }
    EXPECT_GT(field_largest, 1e-5);  // m
    EXPECT_GE(field_largest, largest * 1e-3);
    for (std::size_t i = 0; i < count; ++i) {
      const int c = static_cast<int>(std::lround(markers.rest_px[i].x));
      const int r = static_cast<int>(std::lround(markers.rest_px[i].y));
      if (r < 0 || c < 0 || r >= field.rows || c >= field.cols) continue;
      EXPECT_NEAR(field(r, c)[1], markers.displacement_mm[i].y * 1e-3, 0.1 * field_largest);
      EXPECT_NEAR(field(r, c)[0], markers.displacement_mm[i].x * 1e-3, 0.1 * field_largest);
    }

    // Cattaneo-Mindlin: a ball under a tangential force below friction's limit slips in a thin
    // annulus at the rim. The renderer solves it on coarser cells, which slip a little more.
    EXPECT_TRUE(contact.in_contact);
    EXPECT_GT(contact.slip_fraction, 0.0);
    EXPECT_LT(contact.slip_fraction, 0.5);
    EXPECT_GT(markers.slip_fraction, 0.0);
    EXPECT_GE(markers.slip_fraction, contact.slip_fraction - 0.02);
    EXPECT_LE(markers.slip_fraction, contact.slip_fraction + 0.15);
    // A ball held by one contact point, its weight through the grip: no twist to speak of.
    EXPECT_LT(std::abs(contact.twist_moment), 1e-4);
  }

  // Opened: the ball falls, the gels come back to rest and stick where nothing touches.
  const ros::Time open = l.stepFrames(60, 1.0);
  ASSERT_TRUE(l.everythingOf(open));
  for (const char* sensor : kSensors) {
    SCOPED_TRACE(sensor);
    SensorLog& log = l.log[sensor];
    const TactileMarkers& markers = *log.markers[open];
    EXPECT_FALSE(log.contact[open]->in_contact);
    EXPECT_EQ(log.contact[open]->slip_fraction, 0.0);
    EXPECT_EQ(markers.slip_fraction, 0.0);
    for (std::size_t i = 0; i < markers.rest_px.size(); ++i) {
      EXPECT_EQ(markers.current_px[i].x, markers.rest_px[i].x);
      EXPECT_EQ(markers.current_px[i].y, markers.rest_px[i].y);
    }
    EXPECT_EQ(cv::countNonZero(shearField(*log.shear[open]).reshape(1)), 0);
  }

  // Lock-step: one image, one markers and one shear per sensor and frame, never two.
  for (const char* sensor : kSensors) {
    SensorLog& log = l.log[sensor];
    for (const auto& [stamp, n] : log.images_at) {
      EXPECT_EQ(n, 1) << sensor << " images at " << stamp;
      EXPECT_EQ(log.markers_at[stamp], 1) << sensor << " markers at " << stamp;
      EXPECT_EQ(log.shears_at[stamp], 1) << sensor << " shear at " << stamp;
    }
  }
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(SynchronousMarkers, TheRecordersBagsGiveBackTheMarkersAndTheShear) {
  Listener& l = listener();
  ASSERT_TRUE(l.ready());
  std::string dir;
  ASSERT_TRUE(l.nh.getParam("/dataset_recorder/output_dir", dir));
  const std::string manifest = dir + "/norm2tex_shard0.yaml";
  // The recorder stops at 10 images (5 frames of two sensors); frames until then.
  for (int i = 0; i < 20 && !std::filesystem::exists(manifest); ++i) {
    l.stepFrames(1);
    waitFor([&] { return std::filesystem::exists(manifest); }, 0.5);
  }
  ASSERT_TRUE(waitFor([&] { return std::filesystem::exists(manifest); }, 30.0));
  ASSERT_TRUE(waitFor([&] { return readFile(manifest).find("bags:") != std::string::npos; }, 10.0));
  const std::string text = readFile(manifest);
  EXPECT_NE(text.find("complete: true"), std::string::npos) << text;
  // As many markers and fields as images written per sensor (frames in flight when the target
  // was reached are finished, so at least 5).
  for (const char* sensor : kSensors) {
    std::map<std::string, int> written;
    for (const char* leaf : {"image_raw", "markers", "shear"}) {
      const std::string key = "'/" + std::string(sensor) + "/" + leaf + "': {received: ";
      const std::size_t at = text.find(key);
      ASSERT_NE(at, std::string::npos) << key << " in " << text;
      const std::size_t w = text.find("written: ", at);
      written[leaf] = std::stoi(text.substr(w + 9));
    }
    EXPECT_GE(written["image_raw"], 5) << sensor;
    EXPECT_EQ(written["markers"], written["image_raw"]) << sensor;
    EXPECT_EQ(written["shear"], written["image_raw"]) << sensor;
  }

  std::vector<std::string> bags;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() == ".bag") bags.push_back(entry.path().string());
  }
  ASSERT_FALSE(bags.empty());
  norm2tex::TactileBagReader reader(bags);
  int compared = 0;
  std::map<std::pair<std::string, std::uint64_t>, cv::Mat2f> recorded_shear;
  reader.forEachSample([&](const norm2tex::TactileSample& s) {
    recorded_shear[{s.sensor, s.stamp.toNSec()}] = s.shear_m.clone();
    SCOPED_TRACE(s.sensor + " at " + std::to_string(s.stamp.toSec()));
    ASSERT_TRUE(s.has_markers);
    ASSERT_FALSE(s.shear_m.empty());
    EXPECT_EQ(s.markers.header.stamp, s.stamp);
    SensorLog& log = l.log[s.sensor];
    if (!log.markers.count(s.stamp)) return;  // a frame before the test listened
    const TactileMarkers& live = *log.markers[s.stamp];
    ASSERT_EQ(s.markers.rest_px.size(), live.rest_px.size());
    for (std::size_t i = 0; i < live.rest_px.size(); ++i) {
      EXPECT_EQ(s.markers.current_px[i].x, live.current_px[i].x);
      EXPECT_EQ(s.markers.current_px[i].y, live.current_px[i].y);
      EXPECT_EQ(s.markers.displacement_mm[i].y, live.displacement_mm[i].y);
    }
    EXPECT_EQ(s.markers.slip_fraction, live.slip_fraction);
    EXPECT_EQ(cv::norm(s.shear_m.reshape(1), shearField(*log.shear[s.stamp]).reshape(1),
                       cv::NORM_INF),
              0.0);
    ++compared;
  });
  EXPECT_GE(compared, 6);
  EXPECT_TRUE(reader.warnings().empty());

  // Exported: a CSV of the markers per frame, named in labels.csv with the contact's slip.
  const std::string out = dir + "_export";
  norm2tex::ExportOptions options;
  options.out_dir = out;
  options.force = true;
  const norm2tex::ExportSummary summary = norm2tex::exportDataset(bags, options);
  EXPECT_GE(summary.frames, 10u);
  EXPECT_EQ(summary.frames_with_markers, summary.frames);
  std::ifstream labels(out + "/labels.csv");
  std::string header, row;
  ASSERT_TRUE(std::getline(labels, header));
  EXPECT_NE(header.find(",bag,twist_moment,slip_fraction,markers,shear"), std::string::npos)
      << header;
  ASSERT_TRUE(std::getline(labels, row));
  std::vector<std::string> cells;
  for (std::stringstream fields(row); cells.size() < 64;) {
    std::string cell;
    if (!std::getline(fields, cell, ',')) break;
    cells.push_back(cell);
  }
  ASSERT_EQ(cells.size(), 24u) << row;  // no quoted field in these rows
  // The shear field as a NumPy array: its header, then the recorded field's values.
  const std::string& shear_npy = cells[23];
  ASSERT_EQ(shear_npy.rfind("shear/", 0), 0u) << row;
  const cv::Mat2f& field = recorded_shear.at({cells[5], std::stoull(cells[6])});
  std::ifstream npy(out + "/" + shear_npy, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(npy)), std::istreambuf_iterator<char>());
  const std::string npy_header = norm2tex::npyHeader(field.rows, field.cols, 2);
  ASSERT_EQ(bytes.size(), npy_header.size() + field.total() * sizeof(cv::Vec2f));
  EXPECT_EQ(bytes.substr(0, npy_header.size()), npy_header);
  EXPECT_EQ(std::memcmp(bytes.data() + npy_header.size(), field.ptr(), field.total() * 8), 0);
  EXPECT_EQ(summary.frames_with_shear, summary.frames);
  const std::string markers_csv = cells[22];
  ASSERT_EQ(markers_csv.rfind("markers/", 0), 0u) << row;
  std::ifstream markers(out + "/" + markers_csv);
  std::string line;
  int lines = 0;
  while (std::getline(markers, line)) ++lines;
  EXPECT_EQ(lines, 1 + 9 * 7);
  std::filesystem::remove_all(out);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "tactile_markers_test");
  ros::NodeHandle nh;
  Listener listener;
  the_listener = &listener;
  return RUN_ALL_TESTS();
}
