// ProbeScenario, without ROS: every probe frame puts the drawn surface point where the paper's
// collection presses it (gel centre, press depth, gel against the normal), the image sees a
// contact as deep as the press, points are uniform by area, seeds reproduce and differ, and
// unreachable presses are refused.
#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "norm2tex/mesh/object_mesh.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/contact_patch.hpp"
#include "norm2tex/sim/probe_scenario.hpp"
#include "norm2tex/sim/probe_schedule.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

// The press geometry and what the sensor sees of it, for a flat-faced and a curved object.
void expectPressesAsSpecified(const std::string& object, double depth_tolerance_m) {
  const SensorModel sensor = makeDigitSensorModel();
  const ObjectMesh mesh = loadObjectMesh(object);
  const ProbeConfig config;
  ProbeScenario scenario(mesh.mesh, config, sensor, 11);
  ContactPatchMeter meter(sensor);
  for (std::uint64_t p = 0; p < 40; ++p) {
    const std::vector<ProbeFrame> frames = scenario.press(p);
    ASSERT_EQ(static_cast<int>(frames.size()), scenario.framesPerPress());
    const ProbeFrame& press = frames.front();
    EXPECT_GE(press.press_depth_m, config.press_depth_min_m);
    EXPECT_LE(press.press_depth_m, config.press_depth_max_m);
    // The point sits at the gel centre, press_depth below its surface; the normal points into
    // the gel.
    const Eigen::Vector3d point = press.object_in_gel * press.surface_point;
    EXPECT_NEAR((point - Eigen::Vector3d(0, 0, -press.press_depth_m)).norm(), 0.0, 1e-9);
    EXPECT_NEAR((press.object_in_gel.linear() * press.surface_normal + Eigen::Vector3d::UnitZ())
                    .norm(),
                0.0, 1e-9);
    Eigen::Vector2d previous = Eigen::Vector2d::Zero();
    for (const ProbeFrame& f : frames) {
      // Slides move along the gel only, each by at most the configured step.
      EXPECT_LE((f.slide_m - previous).norm(), config.slide_step_max_m + 1e-12);
      previous = f.slide_m;
      const Eigen::Vector3d moved = f.object_in_gel * press.surface_point;
      EXPECT_NEAR(moved.z(), -press.press_depth_m, 1e-9);
      EXPECT_NEAR((moved.head<2>() - f.slide_m).norm(), 0.0, 1e-9);
      // Every frame is a contact the image shows, as deep as the press.
      const ContactPatch patch = meter.measure(mesh.mesh, f.object_in_gel);
      EXPECT_GT(patch.pixels, 0) << object << " press " << p << " slide " << f.slide;
      EXPECT_NEAR(patch.max_indentation_m, press.press_depth_m, depth_tolerance_m)
          << object << " press " << p << " slide " << f.slide;
    }
  }
}

TEST(ProbeScenarioTest, CubePressesSitAtTheGelCentreAtTheirDepth) {
  expectPressesAsSpecified("box:30x30x30", 1e-6);
}

TEST(ProbeScenarioTest, SpherePressesSitAtTheGelCentreAtTheirDepth) {
  // A 20 mm ball's tessellation and the pixel grid lose a few microns at the pole.
  expectPressesAsSpecified("sphere:20", 10e-6);
}

TEST(ProbeScenarioTest, PointsAreUniformByArea) {
  // A 30 x 30 x 10 mm box: the two large faces hold 1800 of its 3000 mm^2.
  const ObjectMesh mesh = loadObjectMesh("box:30x30x10");
  ProbeConfig config;
  config.slides_per_press = 0;
  ProbeScenario scenario(mesh.mesh, config, makeDigitSensorModel(), 3);
  const int n = 3000;
  int on_large_faces = 0;
  for (int p = 0; p < n; ++p) {
    if (std::abs(scenario.press(p).front().surface_normal.z()) > 0.99) ++on_large_faces;
  }
  // Binomial: sigma = sqrt(0.6 * 0.4 / 3000) = 0.009; 4 sigma.
  EXPECT_NEAR(on_large_faces / static_cast<double>(n), 0.6, 0.036);
}

TEST(ProbeScenarioTest, SameSeedReproducesAndOtherSeedsDiffer) {
  const ObjectMesh mesh = loadObjectMesh("sphere:20");
  const ProbeConfig config;
  const SensorModel sensor = makeDigitSensorModel();
  ProbeScenario a(mesh.mesh, config, sensor, 5), b(mesh.mesh, config, sensor, 5),
      c(mesh.mesh, config, sensor, 6);
  std::set<std::pair<double, double>> points;
  for (std::uint64_t p = 0; p < 20; ++p) {
    const auto fa = a.press(p), fb = b.press(p), fc = c.press(p);
    for (std::size_t i = 0; i < fa.size(); ++i) {
      EXPECT_TRUE(fa[i].object_in_gel.isApprox(fb[i].object_in_gel, 0.0)) << p << "/" << i;
    }
    EXPECT_GT((fa.front().surface_point - fc.front().surface_point).norm(), 1e-6);
    points.insert({fa.front().surface_point.x(), fa.front().surface_point.y()});
    points.insert({fc.front().surface_point.x(), fc.front().surface_point.y()});
  }
  EXPECT_EQ(points.size(), 40u);  // no press repeats another, within or across seeds
  // A press drawn out of order (another shard's) is the same press.
  EXPECT_TRUE(a.press(17).back().object_in_gel.isApprox(b.press(17).back().object_in_gel, 0.0));
}

TEST(ProbeScenarioTest, InwardWoundMeshesHaveNoReachablePoint) {
  // A box wound inwards: every "outward" normal points into the object, so any press would push
  // the opposite faces through the gel.
  ObjectMesh box = loadObjectMesh("box:30x30x30");
  std::vector<Eigen::Vector3i> flipped = box.mesh.triangles();
  for (Eigen::Vector3i& t : flipped) std::swap(t[1], t[2]);
  const TexturedMesh inward(box.mesh.vertices(), flipped, box.mesh.uvs());
  ProbeScenario scenario(inward, ProbeConfig(), makeDigitSensorModel(), 1);
  test::expectError([&] { scenario.press(0); }, {"no reachable surface point", "press 0"});
}

TEST(ProbeScenarioTest, BadConfigsAreRejected) {
  const ObjectMesh mesh = loadObjectMesh("box:30x30x30");
  ProbeConfig config;
  config.press_depth_min_m = 0.002;
  config.press_depth_max_m = 0.001;
  test::expectError([&] { ProbeScenario(mesh.mesh, config, makeDigitSensorModel(), 0); }, {"press_depth_max_m"});
  config = ProbeConfig();
  config.slides_per_press = -1;
  test::expectError([&] { ProbeScenario(mesh.mesh, config, makeDigitSensorModel(), 0); }, {"slides_per_press", "[0, 1000]"});
  config = ProbeConfig();
  config.slide_step_max_m = NAN;
  test::expectError([&] { ProbeScenario(mesh.mesh, config, makeDigitSensorModel(), 0); }, {"slide_step_max_m"});
}

TEST(ProbeScheduleTest, SamplesSpreadOverVariantsAndShardsPartitionThePresses) {
  const std::vector<std::pair<std::string, int>> materials = {{"wood", 24}, {"fabric", 7}};
  const ProbeSchedule whole(materials, 6000, 5, 42);
  ASSERT_EQ(whole.blocks().size(), 31u);
  std::uint64_t wood = 0, fabric = 0;
  for (const ProbeBlock& b : whole.blocks()) (b.material == "wood" ? wood : fabric) += b.frames;
  EXPECT_EQ(wood, 6000u);
  EXPECT_EQ(fabric, 6000u);
  EXPECT_EQ(whole.blocks()[7].frames, 250u);                         // 6000 / 24
  EXPECT_EQ(whole.blocks()[24].frames, 858u);                        // 6000 = 7 * 857 + 1
  EXPECT_EQ(whole.blocks()[25].frames, 857u);
  EXPECT_NE(whole.blocks()[0].scenario_seed, whole.blocks()[1].scenario_seed);
  EXPECT_EQ(whole.frames(), 12000u);

  // Three shards: disjoint, together the whole schedule press for press, balanced.
  std::set<std::pair<int, std::uint64_t>> all;
  std::uint64_t frames = 0;
  for (int k = 0; k < 3; ++k) {
    const ProbeSchedule shard(materials, 6000, 5, 42, k, 3);
    for (const ProbePress& p : shard.presses()) {
      EXPECT_TRUE(all.insert({p.block, p.press}).second) << "press in two shards";
    }
    frames += shard.frames();
    EXPECT_NEAR(static_cast<double>(shard.frames()), 4000.0, 31 * 5.0);
  }
  EXPECT_EQ(frames, whole.frames());
  EXPECT_EQ(all.size(), whole.presses().size());
  // The last press of a block is cut to the block's frames: 858 = 171 * 5 + 3.
  const ProbePress& last = whole.presses()[1200 + 171];
  EXPECT_EQ(last.block, 24);
  EXPECT_EQ(last.frames, 3);
}

TEST(ProbeScheduleTest, BadPlansAreRejected) {
  test::expectError([] { ProbeSchedule({}, 10, 5, 0); }, {"no material"});
  test::expectError([] { ProbeSchedule({{"wood", 0}}, 10, 5, 0); }, {"wood", "variants"});
  test::expectError([] { ProbeSchedule({{"wood", 2}}, 0, 5, 0); }, {"samples"});
  test::expectError([] { ProbeSchedule({{"wood", 2}}, 10, 5, 0, 2, 2); }, {"shard 2 of 2"});
}

}  // namespace
}  // namespace norm2tex
