// rostests of the tactile renderers inside the whole simulated gripper (gripper_sim.launch):
// real time (tactile_renderer.test), lock-step synchronous mode (tactile_renderer_sync.test) and
// bad input (tactile_renderer_bad_input.test). Conditions are awaited with deadlines.
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "norm2tex/GripperCommand.h"
#include "norm2tex/Reset.h"
#include "norm2tex/Step.h"
#include "norm2tex/TactileContact.h"
#include "norm2tex/TactileMarkers.h"
#include "norm2tex/render/digit_shader_response.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "run_node.hpp"
#include "wait_for.hpp"

namespace {

// The sensor the sync rostests launch (tactile_renderer_sync.test).
const char* const kSensorYaml = NORM2TEX_SOURCE_DIR "/config/digit.yaml";
// The second sensor, launched with sensor:= (gelsight_mini.test).
const char* const kMiniYaml = NORM2TEX_SOURCE_DIR "/config/gelsight_mini.yaml";

using norm2tex::waitFor;

cv::Mat view(const sensor_msgs::Image& msg) {
  const int type = msg.encoding == "bgr8" ? CV_8UC3 : msg.encoding == "mono8" ? CV_8UC1 : CV_32FC1;
  return cv::Mat(static_cast<int>(msg.height), static_cast<int>(msg.width), type,
                 const_cast<std::uint8_t*>(msg.data.data()), msg.step);
}

// Everything one sensor published, by stamp.
struct SensorLog {
  std::vector<sensor_msgs::Image::ConstPtr> images;
  std::map<ros::Time, sensor_msgs::Image::ConstPtr> image, depth, mask;
  std::map<ros::Time, sensor_msgs::CameraInfo::ConstPtr> info;
  norm2tex::TactileContact::ConstPtr contact;
};

struct Listener {
  ros::NodeHandle nh;
  tf2_ros::Buffer buffer{ros::Duration(60.0)};
  tf2_ros::TransformListener tf{buffer, nh};
  std::map<std::string, SensorLog> log;
  std::vector<ros::Subscriber> subs;

  explicit Listener(const std::vector<std::string>& sensors) {
    for (const std::string& s : sensors) {
      SensorLog* l = &log[s];
      subs.push_back(nh.subscribe<sensor_msgs::Image>(s + "/image_raw", 1000, [l](const auto& m) {
        l->images.push_back(m);
        l->image[m->header.stamp] = m;
      }));
      subs.push_back(nh.subscribe<sensor_msgs::Image>(
          s + "/depth", 1000, [l](const auto& m) { l->depth[m->header.stamp] = m; }));
      subs.push_back(nh.subscribe<sensor_msgs::Image>(
          s + "/contact_mask", 1000, [l](const auto& m) { l->mask[m->header.stamp] = m; }));
      subs.push_back(nh.subscribe<sensor_msgs::CameraInfo>(
          s + "/camera_info", 1000, [l](const auto& m) { l->info[m->header.stamp] = m; }));
      subs.push_back(nh.subscribe<norm2tex::TactileContact>(
          s + "/contact", 10, [l](const auto& m) { l->contact = m; }));
    }
  }
  // Every sensor's image_raw, depth and camera_info have a publisher.
  bool connected(int per_sensor_publishers) {
    return waitFor(
        [&] {
          for (const ros::Subscriber& sub : subs) {
            const std::string topic = sub.getTopic();
            const bool needed = topic.find("/image_raw") != std::string::npos ||
                                topic.find("/depth") != std::string::npos ||
                                topic.find("/camera_info") != std::string::npos;
            if (needed && static_cast<int>(sub.getNumPublishers()) < per_sensor_publishers) {
              return false;
            }
          }
          return true;
        },
        60.0);
  }
};

// ---------------------------------------------------------------------------------------------
// Real time (sphere scene, masks on).

TEST(RealTimeRendering, ImagesComeAtTheFrameRateWithMatchingInfoDepthAndTf) {
  Listener l({"digit_left", "digit_right"});
  ASSERT_TRUE(l.connected(1));
  ASSERT_TRUE(waitFor(
      [&] {
        return l.log["digit_left"].images.size() >= 5 && l.log["digit_right"].images.size() >= 5;
      },
      30.0));
  const std::size_t before = l.log["digit_left"].images.size();
  const std::size_t before_right = l.log["digit_right"].images.size();
  const ros::WallTime start = ros::WallTime::now();
  waitFor([] { return false; }, 3.0);  // count what arrives in 3 s of wall time
  const double seconds = (ros::WallTime::now() - start).toSec();
  const double rate = (l.log["digit_left"].images.size() - before) / seconds;
  const double rate_right = (l.log["digit_right"].images.size() - before_right) / seconds;
  EXPECT_NEAR(rate, 60.0, 6.0);
  EXPECT_NEAR(rate_right, 60.0, 6.0);

  for (const std::string sensor : {"digit_left", "digit_right"}) {
    SensorLog& s = l.log[sensor];
    ASSERT_GE(s.images.size(), 10u) << sensor;
    const sensor_msgs::Image& image = *s.images[s.images.size() - 10];
    EXPECT_EQ(image.encoding, "bgr8");
    EXPECT_EQ(image.height, 320u);
    EXPECT_EQ(image.width, 240u);
    EXPECT_EQ(image.header.frame_id, sensor + "_gel");
    const ros::Time stamp = image.header.stamp;
    ASSERT_TRUE(s.info.count(stamp) && s.depth.count(stamp) && s.mask.count(stamp)) << sensor;
    EXPECT_EQ(s.depth[stamp]->encoding, "32FC1");
    EXPECT_EQ(s.info[stamp]->header.frame_id, sensor + "_gel");
    EXPECT_EQ(s.info[stamp]->width, 240u);
    EXPECT_TRUE(l.buffer.canTransform(sensor + "_gel", "object", stamp)) << sensor;
  }
}

TEST(RealTimeRendering, ContactShowsGrowsWithTheSqueezeAndEndsWhenDropped) {
  Listener l({"digit_left", "digit_right"});
  ros::Publisher command = l.nh.advertise<norm2tex::GripperCommand>("/gripper/command", 10);
  ASSERT_TRUE(l.connected(1));
  ASSERT_TRUE(waitFor([&] { return command.getNumSubscribers() > 0; }, 20.0));
  auto latest = [&](const std::string& sensor) {
    SensorLog& s = l.log[sensor];
    // The newest image whose depth and mask arrived too.
    for (auto it = s.images.rbegin(); it != s.images.rend(); ++it) {
      const ros::Time t = (*it)->header.stamp;
      if (s.depth.count(t) && s.mask.count(t)) return t;
    }
    return ros::Time(0);
  };
  auto measure = [&](const std::string& sensor, ros::Time t, double& area, double& deepest) {
    SensorLog& s = l.log[sensor];
    area = cv::countNonZero(view(*s.mask[t]));
    cv::minMaxLoc(view(*s.depth[t]), nullptr, &deepest);
  };
  ASSERT_TRUE(waitFor(
      [&] { return latest("digit_left") > ros::Time(0) && latest("digit_right") > ros::Time(0); },
      30.0));
  std::map<std::string, ros::Time> held;
  double area[2], depth[2];
  for (int i = 0; i < 2; ++i) {
    const std::string sensor = i ? "digit_right" : "digit_left";
    held[sensor] = latest(sensor);
    measure(sensor, held[sensor], area[i], depth[i]);
    EXPECT_GT(area[i], 500) << sensor;
    EXPECT_GT(depth[i], 0.2e-3) << sensor;
  }

  norm2tex::GripperCommand squeeze;
  squeeze.mode = norm2tex::GripperCommand::DELTA;
  squeeze.opening = -0.02;  // 0.8 mm narrower
  command.publish(squeeze);
  const ros::Time after = latest("digit_left") + ros::Duration(0.5);  // fingers move 20 mm/s
  ASSERT_TRUE(
      waitFor([&] { return latest("digit_left") > after && latest("digit_right") > after; }, 20.0));
  for (int i = 0; i < 2; ++i) {
    const std::string sensor = i ? "digit_right" : "digit_left";
    double squeezed_area = 0, squeezed_depth = 0;
    measure(sensor, latest(sensor), squeezed_area, squeezed_depth);
    EXPECT_GT(squeezed_area, 1.2 * area[i]) << sensor;
    EXPECT_GT(squeezed_depth, depth[i] + 0.2e-3) << sensor;
  }

  norm2tex::GripperCommand open;
  open.mode = norm2tex::GripperCommand::ABSOLUTE;
  open.opening = 1.0;
  command.publish(open);
  ASSERT_TRUE(waitFor(
      [&] {
        const auto& c0 = l.log["digit_left"].contact;
        const auto& c1 = l.log["digit_right"].contact;
        return c0 && c1 && !c0->in_contact && !c1->in_contact;
      },
      20.0));
  const ros::Time gone = l.log["digit_left"].contact->header.stamp;
  ASSERT_TRUE(
      waitFor([&] { return latest("digit_left") > gone && latest("digit_right") > gone; }, 20.0));
  for (int i = 0; i < 2; ++i) {
    const std::string sensor = i ? "digit_right" : "digit_left";
    const ros::Time t = latest(sensor);
    double dropped_area = 0, dropped_depth = 0;
    measure(sensor, t, dropped_area, dropped_depth);
    EXPECT_EQ(dropped_area, 0) << sensor;
    EXPECT_EQ(dropped_depth, 0.0) << sensor;
    // While held, the image differed from the no-contact image inside the contact.
    SensorLog& s = l.log[sensor];
    cv::Mat diff;
    cv::absdiff(view(*s.image[held[sensor]]), view(*s.image[t]), diff);
    const cv::Scalar inside = cv::mean(diff, view(*s.mask[held[sensor]]));
    EXPECT_GT((inside[0] + inside[1] + inside[2]) / 3.0, 5.0) << sensor;
  }
}

// ---------------------------------------------------------------------------------------------
// gripper_sim.launch sensor:=config/gelsight_mini.yaml (gelsight_mini.test): lock-step, noise off.

TEST(GelSightMiniRendering, BothFingersPublishTheMinisLandscapeFramesAndCameraInfo) {
  const norm2tex::SensorModel mini = norm2tex::loadSensorModel(kMiniYaml);
  Listener l({"digit_left", "digit_right"});
  std::map<std::string, sensor_msgs::Image::ConstPtr> backgrounds;
  std::map<std::string, std::map<ros::Time, norm2tex::TactileMarkers::ConstPtr>> markers;
  std::vector<ros::Subscriber> extra;
  for (const std::string sensor : {"digit_left", "digit_right"}) {
    extra.push_back(l.nh.subscribe<sensor_msgs::Image>(
        sensor + "/background", 1,
        [&backgrounds, sensor](const auto& m) { backgrounds[sensor] = m; }));
    extra.push_back(l.nh.subscribe<norm2tex::TactileMarkers>(
        sensor + "/markers", 100,
        [&markers, sensor](const auto& m) { markers[sensor][m->header.stamp] = m; }));
  }
  ros::ServiceClient step = l.nh.serviceClient<norm2tex::Step>("/contact_sim/step");
  ros::ServiceClient reset = l.nh.serviceClient<norm2tex::Reset>("/contact_sim/reset");
  ASSERT_TRUE(step.waitForExistence(ros::Duration(60.0)));
  ASSERT_TRUE(l.connected(1));
  norm2tex::Reset episode;
  episode.request.seed = 2;
  episode.request.height_offset = 0.010;  // the cube's lower edge crosses the gels
  ASSERT_TRUE(reset.call(episode));
  norm2tex::Step srv;
  srv.request.frames = 1;
  ASSERT_TRUE(step.call(srv));
  EXPECT_EQ(srv.response.missing_images, 0u);
  const ros::Time t = srv.response.stamp;
  ASSERT_TRUE(waitFor(
      [&] {
        for (const std::string sensor : {"digit_left", "digit_right"}) {
          SensorLog& s = l.log[sensor];
          if (!s.image.count(t) || !s.mask.count(t) || !s.depth.count(t) || !s.info.count(t) ||
              !backgrounds.count(sensor) || !markers[sensor].count(t)) {
            return false;
          }
        }
        return true;
      },
      20.0));
  for (const std::string sensor : {"digit_left", "digit_right"}) {
    SCOPED_TRACE(sensor);
    SensorLog& s = l.log[sensor];
    const sensor_msgs::Image& image = *s.image[t];
    EXPECT_EQ(image.encoding, "bgr8");
    EXPECT_EQ(image.height, 240u);  // landscape, not the DIGIT's 320 x 240 portrait
    EXPECT_EQ(image.width, 320u);
    EXPECT_EQ(s.depth[t]->height, 240u);
    EXPECT_EQ(s.depth[t]->width, 320u);
    EXPECT_EQ(s.mask[t]->width, 320u);
    EXPECT_EQ(backgrounds[sensor]->width, 320u);
    const sensor_msgs::CameraInfo& info = *s.info[t];
    EXPECT_EQ(info.height, 240u);
    EXPECT_EQ(info.width, 320u);
    EXPECT_DOUBLE_EQ(info.K[0], mini.fx);
    EXPECT_DOUBLE_EQ(info.K[2], mini.cx);
    EXPECT_DOUBLE_EQ(info.K[4], mini.fy);
    EXPECT_DOUBLE_EQ(info.K[5], mini.cy);
    // Its gel carries the 7 x 9 dots: their message comes with every frame.
    const norm2tex::TactileMarkers& dots = *markers[sensor][t];
    EXPECT_EQ(dots.rows, 7u);
    EXPECT_EQ(dots.cols, 9u);
    EXPECT_EQ(dots.rest_px.size(), 63u);
    // The held cube shows: the frame differs from the no-contact frame inside the contact.
    const cv::Mat mask = view(*s.mask[t]);
    ASSERT_GT(cv::countNonZero(mask), 1000);
    cv::Mat diff;
    cv::absdiff(view(image), view(*backgrounds[sensor]), diff);
    const cv::Scalar inside = cv::mean(diff, mask);
    EXPECT_GT((inside[0] + inside[1] + inside[2]) / 3.0, 2.0);
  }
}

// ---------------------------------------------------------------------------------------------
// Synchronous: digit_left (wood), digit_right (wood), digit_left_rock (rock) and
// digit_left_plain (wood at beta 0) and digit_left_bare (no texture), all on digit_left_gel
// except digit_right; noise off.

struct SyncFixture {
  Listener l{
      {"digit_left", "digit_right", "digit_left_rock", "digit_left_plain", "digit_left_bare"}};
  ros::ServiceClient step = l.nh.serviceClient<norm2tex::Step>("/contact_sim/step");
  ros::ServiceClient reset = l.nh.serviceClient<norm2tex::Reset>("/contact_sim/reset");
  bool ready() { return step.waitForExistence(ros::Duration(60.0)) && l.connected(1); }
  ros::Time stepOnce(std::uint32_t frames = 1) {
    norm2tex::Step srv;
    srv.request.frames = frames;
    EXPECT_TRUE(step.call(srv));
    EXPECT_EQ(srv.response.missing_images, 0u);
    return srv.response.stamp;
  }
  // All five renderers' images of `stamp` (published before ~step returned) arrive.
  bool imagesOf(ros::Time stamp) {
    return waitFor(
        [&] {
          for (auto& [name, s] : l.log) {
            if (!s.image.count(stamp) || !s.mask.count(stamp)) return false;
          }
          return true;
        },
        10.0);
  }
};

TEST(SynchronousRendering, EveryStepGivesExactlyOneImagePerSensorWithOneStamp) {
  SyncFixture f;
  ASSERT_TRUE(f.ready());
  // A slow subscriber (5 ms per image) with room for every frame loses none.
  int slow_count = 0;
  ros::Subscriber slow =
      f.l.nh.subscribe<sensor_msgs::Image>("digit_right/image_raw", 100, [&](const auto&) {
        ros::WallDuration(0.005).sleep();  // simulates a slow consumer
        ++slow_count;
      });
  ASSERT_TRUE(waitFor([&] { return slow.getNumPublishers() > 0; }, 20.0));
  const std::size_t left0 = f.l.log["digit_left"].images.size();
  const std::size_t right0 = f.l.log["digit_right"].images.size();
  std::vector<ros::Time> stamps;
  for (std::uint32_t frames : {1u, 1u, 5u, 1u, 20u, 2u}) stamps.push_back(f.stepOnce(frames));
  const std::size_t expected = 1 + 1 + 5 + 1 + 20 + 2;
  ASSERT_TRUE(f.imagesOf(stamps.back()));
  ASSERT_TRUE(waitFor([&] { return slow_count >= static_cast<int>(expected); }, 20.0));
  waitFor([] { return false; }, 0.3);  // any extra image would show up now
  const auto& left = f.l.log["digit_left"].images;
  const auto& right = f.l.log["digit_right"].images;
  ASSERT_EQ(left.size() - left0, expected);
  ASSERT_EQ(right.size() - right0, expected);
  EXPECT_EQ(slow_count, static_cast<int>(expected));
  for (std::size_t i = left0; i < left.size(); ++i) {
    EXPECT_EQ(left[i]->header.stamp, right[i - left0 + right0]->header.stamp);
    if (i > left0) {
      EXPECT_EQ((left[i]->header.stamp - left[i - 1]->header.stamp).toNSec(), 16666667);
    }
  }
  // Each call's stamp is its last frame's.
  EXPECT_EQ(left.back()->header.stamp, stamps.back());
}

TEST(SynchronousRendering, MaterialChangesTextureNotContactAndBetaZeroIsTextureless) {
  SyncFixture f;
  ASSERT_TRUE(f.ready());
  norm2tex::Reset episode;
  episode.request.seed = 2;
  episode.request.height_offset = 0.010;  // the cube's lower edge crosses the gel
  ASSERT_TRUE(f.reset.call(episode));
  const ros::Time t = f.stepOnce();
  ASSERT_TRUE(f.imagesOf(t));
  auto image = [&](const std::string& s) { return view(*f.l.log[s].image[t]); };
  auto mask = [&](const std::string& s) { return view(*f.l.log[s].mask[t]); };
  // Same geometry: identical contact masks.
  EXPECT_EQ(cv::norm(mask("digit_left"), mask("digit_left_rock"), cv::NORM_INF), 0.0);
  const int touching = cv::countNonZero(mask("digit_left"));
  EXPECT_GT(touching, 5000);
  EXPECT_LT(touching, 320 * 240 - 5000);
  // Other material: other pixels inside the contact ...
  cv::Mat diff;
  cv::absdiff(image("digit_left"), image("digit_left_rock"), diff);
  const cv::Scalar inside = cv::mean(diff, mask("digit_left"));
  EXPECT_GT((inside[0] + inside[1] + inside[2]) / 3.0, 1.0);
  // ... and the very same pixels far from it (beyond the gel's skirt).
  // Beyond the gel's skirt (3 sigma of its smoothing pyramid) and the shading's reach (its
  // rim-shadow blur), in pixels of the shipped sensor.
  const norm2tex::SensorModel sensor = norm2tex::loadSensorModel(kSensorYaml);
  double variance_mm2 = 0.0;
  for (const double sigma : sensor.gel.pyramid_sigmas_mm) variance_mm2 += sigma * sigma;
  const int far_px =
      static_cast<int>(std::ceil(3.0 * std::sqrt(variance_mm2) / sensor.mm_per_pixel)) +
      norm2tex::shadingReachPixels(sensor.mm_per_pixel, sensor.shading.shadow_sigma_mm) + 8;
  cv::Mat near;
  cv::dilate(mask("digit_left"), near, cv::Mat(), cv::Point(-1, -1), far_px);
  cv::Mat far;
  cv::bitwise_not(near, far);
  if (cv::countNonZero(far) >= 1000) {
    EXPECT_EQ(cv::mean(diff, far)[0], 0.0);
  } else {
    // At the shipped scale (0.0532 mm/px, a 13 x 17 mm view) the held cube's contact, skirt and
    // rim-shadow reach can cover the whole frame: then the material must show much less
    // outside the contact than inside it.
    cv::Mat outside;
    cv::bitwise_not(mask("digit_left"), outside);
    ASSERT_GT(cv::countNonZero(outside), 500);
    const cv::Scalar out = cv::mean(diff, outside);
    EXPECT_LT((out[0] + out[1] + out[2]) / 3.0, 0.5 * (inside[0] + inside[1] + inside[2]) / 3.0);
  }
  // beta 0 renders exactly what no texture renders; with texture the contact differs.
  EXPECT_EQ(cv::norm(image("digit_left_plain"), image("digit_left_bare"), cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(image("digit_left"), image("digit_left_bare"), cv::NORM_INF), 2.0);
}

TEST(SynchronousRendering, AOneMillimetreSlideShiftsTheTextureByOneMillimetre) {
  SyncFixture f;
  ASSERT_TRUE(f.ready());
  // The cube 1 mm higher = 1 mm towards the image top: 1 / mm_per_pixel pixels of the shipped
  // sensor (18.8 at its 0.0532 mm/px).
  const double pixels_per_mm = 1.0 / norm2tex::loadSensorModel(kSensorYaml).mm_per_pixel;
  std::vector<cv::Mat> reliefs;
  for (double offset : {0.000, 0.001}) {
    norm2tex::Reset episode;
    episode.request.seed = 3;
    episode.request.height_offset = offset;
    ASSERT_TRUE(f.reset.call(episode));
    const ros::Time t = f.stepOnce();
    ASSERT_TRUE(f.imagesOf(t));
    cv::Mat textured, bare, relief;
    // Rock: random grains, so the correlation has one peak (wood's grain runs along the slide).
    cv::cvtColor(view(*f.l.log["digit_left_rock"].image[t]), textured, cv::COLOR_BGR2GRAY);
    cv::cvtColor(view(*f.l.log["digit_left_bare"].image[t]), bare, cv::COLOR_BGR2GRAY);
    // The texture alone: the textured frame minus the same frame without texture.
    cv::subtract(textured, bare, relief, cv::noArray(), CV_32F);
    reliefs.push_back(relief);
  }
  // Where the first relief's centre crop lies in the second: normalised cross-correlation over
  // shifts of up to 30 rows and 10 columns, the peak refined by a parabola. (Phase correlation
  // whitens the spectrum, so with texture only a few grey levels deep, as the calibrated
  // shading draws it like a real DIGIT, the 1-level rounding pattern outweighs the grains.)
  const cv::Rect crop(40, 80, 160, 140);
  const int reach_x = 10, reach_y = 30;
  cv::Mat scores;
  cv::matchTemplate(reliefs[1](cv::Rect(crop.x - reach_x, crop.y - reach_y,
                                        crop.width + 2 * reach_x, crop.height + 2 * reach_y)),
                    reliefs[0](crop), scores, cv::TM_CCOEFF_NORMED);
  cv::Point peak;
  double best = 0.0;
  cv::minMaxLoc(scores, nullptr, &best, nullptr, &peak);
  EXPECT_GT(best, 0.5) << "the texture is found again";
  const auto refine = [&](int at, int size, const std::function<float(int)>& score) {
    if (at <= 0 || at >= size - 1) return static_cast<double>(at);
    const double left = score(at - 1), centre = score(at), right = score(at + 1);
    const double curvature = left - 2.0 * centre + right;
    return at + (curvature < 0.0 ? 0.5 * (left - right) / curvature : 0.0);
  };
  const cv::Point2d shift(
      refine(peak.x, scores.cols, [&](int x) { return scores.at<float>(peak.y, x); }) - reach_x,
      refine(peak.y, scores.rows, [&](int y) { return scores.at<float>(y, peak.x); }) - reach_y);
  EXPECT_NEAR(shift.y, -pixels_per_mm, 0.5);
  EXPECT_NEAR(shift.x, 0.0, 0.5);
}

// ---------------------------------------------------------------------------------------------
// Synchronous with contact_sim and both renderers as nodelets in one manager.

TEST(SynchronousNodelets, EveryStepGivesExactlyOneImagePerSensorWithOneStamp) {
  Listener l({"digit_left", "digit_right"});
  ros::ServiceClient step = l.nh.serviceClient<norm2tex::Step>("/contact_sim/step");
  ASSERT_TRUE(step.waitForExistence(ros::Duration(60.0)));
  ASSERT_TRUE(l.connected(1));
  std::vector<ros::Time> stamps;
  for (std::uint32_t frames : {1u, 3u, 1u, 10u}) {
    norm2tex::Step srv;
    srv.request.frames = frames;
    ASSERT_TRUE(step.call(srv));
    EXPECT_EQ(srv.response.missing_images, 0u);
    stamps.push_back(srv.response.stamp);
  }
  ASSERT_TRUE(waitFor(
      [&] {
        return l.log["digit_left"].image.count(stamps.back()) &&
               l.log["digit_right"].image.count(stamps.back());
      },
      10.0));
  waitFor([] { return false; }, 0.3);  // any extra image would show up now
  for (const char* sensor : {"digit_left", "digit_right"}) {
    const auto& images = l.log[sensor].images;
    ASSERT_EQ(images.size(), 15u) << sensor;
    for (std::size_t i = 1; i < images.size(); ++i) {
      EXPECT_EQ((images[i]->header.stamp - images[i - 1]->header.stamp).toNSec(), 16666667);
    }
    EXPECT_EQ(images.back()->header.stamp, stamps.back());
  }
}

// ---------------------------------------------------------------------------------------------
// Bad input.

int runRenderer(const std::string& args, std::string& output) {
  return norm2tex::test::runNodeUntilExit(NORM2TEX_TACTILE_RENDERER_EXECUTABLE, args, output);
}

TEST(BadRendererInput, StartUpErrorsExitNonZeroNamingTheCause) {
  struct Case {
    std::string args, expected;
  } cases[] = {
      {"_mesh:=/nonexistent/object.stl", "/nonexistent/object.stl"},
      {"_material:=unobtainium", "unobtainium"},
      {"_material:='' _normal_map:=/nonexistent/normal.png", "/nonexistent/normal.png"},
      {"_background:=/nonexistent/bg.png", "/nonexistent/bg.png"},
      {"_tf_timeout:=-1", "~tf_timeout"},
      {"_queue_size:=0", "~queue_size"},
      {"_opencv_threads:=0", "~opencv_threads"},
      {"_cpu:=-2", "~cpu"},
      {"_cpu:=100000", "~cpu"},  // more CPUs than any machine: named, not a silent no-op
      {"_rehearse_ms:=-1", "~rehearse_ms"},
      {"_rehearse_ms:=1000", "~rehearse_ms"},
      // Of the wrong type: roscpp's param() would take the default without a word.
      {"_rehearse_ms:=.nan", "~rehearse_ms = .nan is not valid; valid: a number"},
      {"_variant:=first", "~variant = first is not valid; valid: an integer"},
      // The shipped materials have variants 0-23: 24 was drawn silently.
      {"_material:=wood _variant:=24", "~variant = 24 is not valid; valid: [0, 23] (wood's variant_count 24)"},
      {"_publish_mask:=3", "~publish_mask = 3 is not valid; valid: true or false"},
  };
  for (const Case& c : cases) {
    std::string output;
    EXPECT_EQ(runRenderer(c.args, output), 1) << c.args << ":\n" << output;
    EXPECT_NE(output.find(c.expected), std::string::npos) << c.args << ":\n" << output;
  }
}

TEST(BadRendererInput, NodeletGroupStartUpErrorsExitNonZeroNamingTheCause) {
  // nodelet_group reads its list from ~nodelets (a YAML list: set here, not on the command
  // line); a nodelet that fails to start ends the group with its own FATAL.
  ros::param::set("/group_bad_renderer/material", std::string("unobtainium"));
  auto entry = [](const std::string& name, const std::string& type) {
    XmlRpc::XmlRpcValue value;
    value["name"] = name;
    if (!type.empty()) value["type"] = type;
    return value;
  };
  XmlRpc::XmlRpcValue no_type, unknown_type, failing, empty;
  no_type[0] = entry("group_a", "");
  unknown_type[0] = entry("group_b", "norm2tex/NoSuchNodelet");
  failing[0] = entry("group_bad_renderer", "norm2tex/TactileRendererNodelet");
  empty.setSize(0);
  struct Case {
    std::string node;
    const XmlRpc::XmlRpcValue* nodelets;  // null: no ~nodelets at all
    std::string expected;
  } cases[] = {
      {"group_without_list", nullptr, "~nodelets must be a non-empty list"},
      {"group_with_empty_list", &empty, "~nodelets must be a non-empty list"},
      {"group_without_type", &no_type, "~nodelets[0] is not {name: NAME, type: PACKAGE/Type}"},
      {"group_unknown_type", &unknown_type, "norm2tex/NoSuchNodelet"},
      {"group_failing_nodelet", &failing, "unobtainium"},
  };
  for (const Case& c : cases) {
    if (c.nodelets != nullptr) ros::param::set("/" + c.node + "/nodelets", *c.nodelets);
    std::string output;
    const int status = norm2tex::test::runCommand(
        std::string(NORM2TEX_NODELET_GROUP_EXECUTABLE) + " __name:=" + c.node, output);
    EXPECT_EQ(status, 1) << c.node << ":\n" << output;
    EXPECT_NE(output.find(c.expected), std::string::npos) << c.node << ":\n" << output;
  }
}

TEST(BadRendererInput, APoseThatNeverArrivesIsCountedNotFaked) {
  // digit_ghost renders a frame that has no TF: every frame is reported missing, no image is
  // published for it, and the renderer stays up.
  Listener l({"digit_ghost"});
  ros::ServiceClient step = l.nh.serviceClient<norm2tex::Step>("/contact_sim/step");
  ASSERT_TRUE(step.waitForExistence(ros::Duration(60.0)));
  for (int i = 0; i < 3; ++i) {
    norm2tex::Step srv;
    srv.request.frames = 2;
    ASSERT_TRUE(step.call(srv));
    EXPECT_EQ(srv.response.missing_images, 2u);
  }
  waitFor([] { return false; }, 0.3);
  EXPECT_TRUE(l.log["digit_ghost"].images.empty());
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "tactile_renderer_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
