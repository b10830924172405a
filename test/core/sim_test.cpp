// GripperSim, GelLaw, the scene config and ContactPatch, without ROS: physical expectations
// (a held cube stays, harder squeeze = deeper and larger contact following the law, friction
// and mass decide where it drops), determinism, resets, and bad input.
#include <algorithm>
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/contact_patch.hpp"
#include "norm2tex/gel/gel_law.hpp"
#include "norm2tex/sim/gripper_sim.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

GripperSimConfig cubeConfig(double friction = 0.5, double mass_kg = 0.1) {
  GripperSimConfig config;
  config.object.friction = friction;
  config.object.mass_kg = mass_kg;
  setGelFromSensor(makeDigitSensorModel(), config);
  return config;
}

// Opens by 0.0025 (0.1 mm of gap) every 0.1 s from the grasp; returns the opening at which the
// object has slipped 0.5 mm, then keeps opening until the dropped flag rises (NaN if never).
double slipOpening(GripperSim& sim) {
  const EpisodeStart start = sim.reset(7, 0.0);
  const double held_z = sim.objectInWorld().translation().z();
  double slip = NAN;
  for (double opening = start.grasp_opening; opening <= 1.0; opening += 0.0025) {
    sim.setOpening(opening);
    sim.step(100);
    if (std::isnan(slip) && sim.objectInWorld().translation().z() < held_z - 0.5e-3) slip = opening;
    if (sim.dropped()) return slip;
  }
  return NAN;
}

double rotationDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180.0 / M_PI;
}

TEST(GelLawTest, PassesThroughItsTableAndInvertsExactly) {
  const GelLaw law = GelLaw::taximDefault();
  for (const auto& [d, f] : law.points()) {
    EXPECT_NEAR(law.force(d), f, 1e-9 * f);
    EXPECT_NEAR(law.indentation(f), d, 1e-12);
  }
  double previous = 0.0;
  for (double d = 1e-6; d <= 2.5e-3; d += 1e-5) {
    const double f = law.force(d);
    EXPECT_GT(f, previous) << "force must grow with indentation at " << d;
    EXPECT_NEAR(law.indentation(f), d, 1e-9);
    previous = f;
  }
  // Hardening: the secant stiffness grows (4 kN/m at first touch, 9.4 kN/m at 0.5 mm).
  EXPECT_NEAR(law.secantStiffness(0.0), 4000.0, 1.0);
  EXPECT_GT(law.secantStiffness(0.5e-3), 2.0 * law.secantStiffness(0.05e-3));
  EXPECT_EQ(law.force(-1e-3), 0.0);
  EXPECT_EQ(law.indentation(0.0), 0.0);
}

TEST(GelLawTest, RejectsTablesThatAreNotIncreasing) {
  test::expectError([] { GelLaw({}); }, {"gel.law"});
  test::expectError([] { GelLaw({{1e-3, 5.0}, {0.5e-3, 6.0}}); }, {"gel.law", "point 1"});
  test::expectError([] { GelLaw({{1e-3, 5.0}, {2e-3, 5.0}}); }, {"gel.law", "strictly"});
  test::expectError([] { GelLaw({{0.0, 0.0}}); }, {"gel.law", "point 0"});
  test::expectError([] { GelLaw({{1e-3, NAN}}); }, {"gel.law"});
}

TEST(GripperSimTest, HeldCubeStaysPutForTenSeconds) {
  GripperSim sim(cubeConfig());
  sim.reset(1, 0.01);
  ASSERT_TRUE(sim.contact(Finger::kLeft).in_contact);
  ASSERT_TRUE(sim.contact(Finger::kRight).in_contact);
  const Eigen::Isometry3d before = sim.objectInWorld();
  sim.step(10000);  // 10 s at 1 kHz
  const Eigen::Isometry3d after = sim.objectInWorld();
  RecordProperty("drift_um",
                 std::to_string((after.translation() - before.translation()).norm() * 1e6));
  RecordProperty("indentation_left_um",
                 std::to_string(sim.contact(Finger::kLeft).penetration_m * 1e6));
  RecordProperty("indentation_right_um",
                 std::to_string(sim.contact(Finger::kRight).penetration_m * 1e6));
  EXPECT_LT((after.translation() - before.translation()).norm(), 0.2e-3);
  EXPECT_LT(rotationDeg(before, after), 0.5);
  EXPECT_FALSE(sim.dropped());
  // The gels carry the weight: the shear on each gel points down the finger (image +y).
  const double weight = 0.1 * 9.81;
  const double carried =
      sim.contact(Finger::kLeft).shear_force_n.y() + sim.contact(Finger::kRight).shear_force_n.y();
  EXPECT_NEAR(carried, weight, 0.02 * weight);
}

TEST(GripperSimTest, SqueezingHarderFollowsTheGelLaw) {
  const GripperSimConfig config = cubeConfig();
  GripperSim sim(config);
  const EpisodeStart start = sim.reset(2, 0.0);
  double previous_force = 0.0, previous_penetration = 0.0;
  for (int i = 0; i <= 4; ++i) {  // 1.0 ... 1.8 mm, below the force limit (2.03 mm)
    sim.setOpening(start.grasp_opening - 0.01 * i);  // 0.2 mm narrower each time
    sim.step(600);
    for (Finger finger : {Finger::kLeft, Finger::kRight}) {
      const GelContactState& c = sim.contact(finger);
      ASSERT_TRUE(c.in_contact);
      EXPECT_NEAR(c.normal_force_n, config.gel_law.force(c.penetration_m),
                  0.1 * config.gel_law.force(c.penetration_m))
          << "squeeze " << i;
    }
    const GelContactState& left = sim.contact(Finger::kLeft);
    EXPECT_GT(left.normal_force_n, previous_force) << "squeeze " << i;
    EXPECT_GT(left.penetration_m, previous_penetration) << "squeeze " << i;
    previous_force = left.normal_force_n;
    previous_penetration = left.penetration_m;
  }
  // The commanded gap is narrower than the cube by 2 x the indentation (fingers centred).
  const double gap = sim.gapForOpening(sim.commandedOpening());
  EXPECT_NEAR(0.030 - gap, 2.0 * sim.contact(Finger::kLeft).penetration_m, 2e-5);
  // ... up to the force limit, where the fingers stop.
  sim.setOpening(0.0);
  double peak_force = 0.0;
  for (int t = 0; t < 2000; ++t) {
    sim.step(1);
    peak_force = std::max({peak_force, sim.contact(Finger::kLeft).normal_force_n,
                           sim.contact(Finger::kRight).normal_force_n});
  }
  RecordProperty("force_limit_peak_n", std::to_string(peak_force));
  RecordProperty("force_limit_left_n", std::to_string(sim.contact(Finger::kLeft).normal_force_n));
  RecordProperty("force_limit_right_n", std::to_string(sim.contact(Finger::kRight).normal_force_n));
  RecordProperty("force_limit_opening", std::to_string(sim.opening()));
  EXPECT_NEAR(sim.contact(Finger::kLeft).normal_force_n, config.gripper.max_force_n,
              0.05 * config.gripper.max_force_n);
  EXPECT_GT(sim.opening(), 0.5);
}

TEST(GripperSimTest, DropOpeningGrowsWithFrictionAndShrinksWithMass) {
  GripperSim slippery(cubeConfig(0.3, 0.1)), grippy(cubeConfig(0.8, 0.1));
  GripperSim heavy(cubeConfig(0.5, 0.2)), light(cubeConfig(0.5, 0.05));
  const double slippery_drop = slipOpening(slippery), grippy_drop = slipOpening(grippy);
  const double heavy_drop = slipOpening(heavy), light_drop = slipOpening(light);
  ASSERT_TRUE(std::isfinite(slippery_drop) && std::isfinite(grippy_drop));
  ASSERT_TRUE(std::isfinite(heavy_drop) && std::isfinite(light_drop));
  RecordProperty("slip_opening_mu03_100g", std::to_string(slippery_drop));
  RecordProperty("slip_opening_mu08_100g", std::to_string(grippy_drop));
  RecordProperty("slip_opening_mu05_200g", std::to_string(heavy_drop));
  RecordProperty("slip_opening_mu05_50g", std::to_string(light_drop));
  EXPECT_GT(grippy_drop, slippery_drop);
  EXPECT_LT(heavy_drop, light_drop);
  EXPECT_TRUE(heavy.dropped());
  // Coulomb: it slips once 2 mu F < m g, i.e. at F = m g / (2 mu) = 1.64 N for mu 0.3, 100 g:
  // the gap then is the cube minus 2 x the law's indentation for that force (+- one 0.1 mm
  // opening step).
  const GelLaw law = GelLaw::taximDefault();
  const double expected_gap = 0.030 - 2.0 * law.indentation(0.1 * 9.81 / (2 * 0.3));
  EXPECT_NEAR(slippery.gapForOpening(slippery_drop), expected_gap, 0.15e-3);
  // The dropped cube lies on the floor.
  slippery.step(1000);
  EXPECT_LT(slippery.objectInWorld().translation().z(), 0.016);
}

TEST(GripperSimTest, StoppingTheSolverAtConvergenceKeepsTheGrasp) {
  // Every one of the 50 iterations per tick against stopping once no contact velocity changes
  // by 1 um/s: the same hold and the same slip opening. Measured: 0.005 um and 5e-6 of the
  // force apart; a tolerance of 1 cm/s would be 0.6 um and 2e-3 apart.
  GripperSimConfig exhaustive_config = cubeConfig(0.3, 0.1);
  exhaustive_config.physics.solver_tolerance_m_s = 0.0;
  const GripperSimConfig converged_config = cubeConfig(0.3, 0.1);
  ASSERT_GT(converged_config.physics.solver_tolerance_m_s, 0.0);
  GripperSim exhaustive(exhaustive_config), converged(converged_config);
  for (GripperSim* sim : {&exhaustive, &converged}) {
    sim->reset(3, 0.01);
    sim->step(2000);
  }
  EXPECT_LT((exhaustive.objectInWorld().translation() - converged.objectInWorld().translation())
                .norm(),
            1e-7);
  EXPECT_NEAR(exhaustive.contact(Finger::kLeft).normal_force_n,
              converged.contact(Finger::kLeft).normal_force_n,
              1e-4 * exhaustive.contact(Finger::kLeft).normal_force_n);
  // (The grasp is measured on the object, so the two start a few nm apart.)
  EXPECT_NEAR(slipOpening(exhaustive), slipOpening(converged), 1e-9);
}

TEST(GripperSimTest, SameSeedAndCommandsGiveIdenticalTrajectories) {
  auto run = [](std::uint64_t seed) {
    GripperSim sim(cubeConfig());
    sim.reset(seed);
    std::vector<Eigen::Matrix4d> poses;
    for (int i = 0; i < 40; ++i) {
      sim.addOpening(i % 3 == 0 ? -0.005 : 0.005 * (i % 2));
      sim.step(17);
      poses.push_back(sim.objectInWorld().matrix());
    }
    return poses;
  };
  const auto a = run(42), b = run(42), c = run(43);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(a[i] == b[i]) << "frame " << i << " differs between identical runs";
  }
  EXPECT_FALSE(a.back() == c.back()) << "another seed should seat the cube elsewhere";
}

TEST(GripperSimTest, ResetPlacesTheObjectAtTheOffset) {
  GripperSim sim(cubeConfig());
  for (double offset : {0.0, 0.012, 0.025}) {
    const EpisodeStart start = sim.reset(3, offset);
    EXPECT_DOUBLE_EQ(start.height_offset_m, offset);
    const double above_gels =
        sim.objectInWorld().translation().z() - sim.gelInWorld(Finger::kLeft).translation().z();
    EXPECT_NEAR(above_gels, offset, 0.2e-3) << "offset " << offset;
    EXPECT_FALSE(sim.dropped());
  }
  // Random offsets stay in the configured range and follow the seed.
  for (std::uint64_t seed = 10; seed < 20; ++seed) {
    const EpisodeStart start = sim.reset(seed);
    EXPECT_GE(start.height_offset_m, 0.0);
    EXPECT_LE(start.height_offset_m, 0.025);
  }
  EXPECT_EQ(sim.reset(5).height_offset_m, sim.reset(5).height_offset_m);
  EXPECT_NE(sim.reset(5).height_offset_m, sim.reset(6).height_offset_m);
}

TEST(GripperSimTest, GelFramesFaceEachOtherAndPosesAreConsistent) {
  GripperSim sim(cubeConfig());
  sim.reset(4, 0.005);
  const Eigen::Isometry3d left = sim.gelInWorld(Finger::kLeft);
  const Eigen::Isometry3d right = sim.gelInWorld(Finger::kRight);
  // +z of each gel points at the other finger, +y (image down) towards the floor.
  EXPECT_TRUE(left.linear().col(2).isApprox(Eigen::Vector3d(0, -1, 0)));
  EXPECT_TRUE(right.linear().col(2).isApprox(Eigen::Vector3d(0, 1, 0)));
  EXPECT_TRUE(left.linear().col(1).isApprox(Eigen::Vector3d(0, 0, -1)));
  EXPECT_TRUE(right.linear().col(1).isApprox(Eigen::Vector3d(0, 0, -1)));
  EXPECT_NEAR(left.translation().y() - right.translation().y(), sim.gapForOpening(sim.opening()),
              1e-12);
  for (Finger finger : {Finger::kLeft, Finger::kRight}) {
    const GelContactState& c = sim.contact(finger);
    const Eigen::Isometry3d expected = sim.gelInWorld(finger).inverse() * sim.objectInWorld();
    EXPECT_TRUE(c.object_in_gel.isApprox(expected, 1e-12));
    // The cube's face lies c.penetration below the gel surface: its centre at 15 mm - d.
    EXPECT_NEAR(c.object_in_gel.translation().z(), 0.015 - c.penetration_m, 1e-6);
    // 5 mm above the gel centre = 5 mm towards image top (-y).
    EXPECT_NEAR(c.object_in_gel.translation().y(), -0.005, 0.2e-3);
  }
}

TEST(GripperSimTest, BadCommandsAreRejectedAndChangeNothing) {
  GripperSim sim(cubeConfig());
  sim.setOpening(0.6);
  test::expectError([&] { sim.setOpening(NAN); }, {"opening", "[0, 1]"});
  test::expectError([&] { sim.setOpening(1.5); }, {"opening", "1.5"});
  test::expectError([&] { sim.setOpening(-0.1); }, {"opening"});
  test::expectError([&] { sim.addOpening(NAN); }, {"delta", "[-1, 1]"});
  test::expectError([&] { sim.addOpening(2.0); }, {"delta"});
  test::expectError([&] { sim.reset(1, NAN); }, {"height offset"});
  // Outside the scene's range: refused with the range (0.5 m used to be taken and labelled).
  for (double offset : {0.5, 0.03, -0.5, -1e-4}) {
    test::expectError([&] { sim.reset(1, offset); }, {"height offset", "[0, 0.025]"});
  }
  EXPECT_EQ(sim.commandedOpening(), 0.6);
  sim.addOpening(0.5);
  EXPECT_EQ(sim.commandedOpening(), 1.0);  // clamped
}

TEST(GripperSimConfigTest, LoadsTheShippedScenesAndRejectsBadOnes) {
  const std::string scenes = std::string(NORM2TEX_SOURCE_DIR) + "/config/scenes/";
  for (const char* name : {"cube.yaml", "sphere.yaml"}) {
    GripperSimConfig config = loadGripperSimConfig(scenes + name);
    setGelFromSensor(makeDigitSensorModel(), config);
    GripperSim sim(config);
    sim.reset(0);
    EXPECT_TRUE(sim.contact(Finger::kLeft).in_contact) << name;
    EXPECT_FALSE(sim.dropped()) << name;
  }
  const GripperSimConfig cube = loadGripperSimConfig(scenes + "cube.yaml");
  EXPECT_EQ(cube.object.mesh, "box:30x30x30");
  EXPECT_DOUBLE_EQ(cube.episode.height_offset_high_m, 0.025);
  EXPECT_NEAR(cube.gel_law.force(0.58e-3), 5.94, 1e-9);

  test::ScratchDirectory dir;
  auto write = [&](const std::string& text) {
    std::ofstream(dir.path("scene.yaml")) << text;
    return dir.path("scene.yaml");
  };
  test::expectError([&] { loadGripperSimConfig(write("gripper: {max_gap_mmm: 4}\n")); },
                    {"scene.yaml", "gripper.max_gap_mmm", "not a known key"});
  test::expectError([&] { loadGripperSimConfig(write("object: {mass_kg: -1}\n")); },
                    {"scene.yaml", "object.mass_kg", "(0, 100] kg"});
  test::expectError([&] { loadGripperSimConfig(write("physics: {rate_hz: 10}\n")); },
                    {"physics.rate_hz", "[100, 100000]"});
  test::expectError([&] { loadGripperSimConfig(write("object: {collision: hacd}\n")); },
                    {"object.collision", "auto, box, hull, decomposition"});
  test::expectError([&] { loadGripperSimConfig(write("gel: {law: [[0.1, 1], [0.05, 2]]}\n")); },
                    {"scene.yaml", "gel.law"});
  test::expectError([&] { loadGripperSimConfig(dir.path("missing.yaml")); }, {"missing.yaml"});
  // A missing mesh is named when the simulation loads it.
  GripperSimConfig config = loadGripperSimConfig(write("object: {mesh: no_such_mesh.stl}\n"));
  test::expectError([&] { GripperSim sim(config); }, {"no_such_mesh.stl"});
  config.object.mesh = "box:50x50x50";
  test::expectError([&] { GripperSim sim(config); }, {"50 mm wide", "max_gap_mm"});
}

TEST(GripperSimTest, MeshObjectsUseTheirConvexHull) {
  // A mesh that is no box is held through its convex hull.
  test::ScratchDirectory dir;
  {
    // A 12-sided prism (24 mm across the flats that face the gels, 30 mm tall), off-centre
    // in its file: the body sits at its bounds' centre, the object frame stays the file's.
    std::ofstream obj(dir.path("prism.obj"));
    for (int k = 0; k < 12; ++k) {
      const double a = (15.0 + 30.0 * k) * M_PI / 180.0, r = 12.0 / std::cos(M_PI / 12.0);
      obj << "v " << 5 + r * std::cos(a) << " " << r * std::sin(a) << " -15\n";
      obj << "v " << 5 + r * std::cos(a) << " " << r * std::sin(a) << " 15\n";
    }
    for (int k = 0; k < 12; ++k) {
      const int a = 2 * k + 1, b = 2 * k + 2, c = (2 * k + 2) % 24 + 1, d = (2 * k + 3) % 24 + 1;
      obj << "f " << a << " " << c << " " << d << "\nf " << a << " " << d << " " << b << "\n";
    }
    for (int k = 1; k < 11; ++k) {
      obj << "f 1 " << 2 * k + 3 << " " << 2 * k + 1 << "\n";
      obj << "f 2 " << 2 * k + 2 << " " << 2 * k + 4 << "\n";
    }
  }
  GripperSimConfig config = cubeConfig();
  config.object.mesh = dir.path("prism.obj");
  config.object.scale = 0.001;
  config.object.mass_kg = 0.02;
  GripperSim sim(config);
  EXPECT_EQ(sim.object().shape, ObjectMesh::Shape::kMesh);
  // A box given as a file collides as an exact box; four of its corners (a tetrahedron) do not.
  std::ofstream(dir.path("box.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                                        "v 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
                                        "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\n"
                                        "f 1 5 7 3\nf 2 4 8 6\n";
  std::ofstream(dir.path("tetra.obj")) << "v 0 0 0\nv 1 1 0\nv 1 0 1\nv 0 1 1\n"
                                          "f 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n";
  EXPECT_EQ(loadObjectMesh(dir.path("box.obj")).shape, ObjectMesh::Shape::kBox);
  EXPECT_EQ(loadObjectMesh(dir.path("tetra.obj")).shape, ObjectMesh::Shape::kMesh);
  EXPECT_EQ(loadObjectMesh("box:30x20x10").shape, ObjectMesh::Shape::kBox);
  test::expectError([] { loadObjectMesh("box:30x20"); }, {"box:30x20", "box:<x_mm>x<y_mm>x<z_mm>"});
  test::expectError([] { loadObjectMesh("sphere:-1"); }, {"sphere:-1", "radius > 0"});
  sim.reset(1, 0.0);
  EXPECT_TRUE(sim.contact(Finger::kLeft).in_contact);
  EXPECT_TRUE(sim.contact(Finger::kRight).in_contact);
  EXPECT_NEAR(sim.contact(Finger::kLeft).penetration_m, 1e-3, 0.1e-3);
  EXPECT_FALSE(sim.dropped());
  // The object frame is the file's: 5 mm off the body centre along world x.
  EXPECT_NEAR(sim.objectInWorld().translation().x(), -0.005, 0.1e-3);
  const Eigen::Isometry3d before = sim.objectInWorld();
  sim.step(3000);
  EXPECT_LT((sim.objectInWorld().translation() - before.translation()).norm(), 0.1e-3);
}

TEST(GripperSimTest, ConcaveObjectsCanCollideAsConvexParts) {
  // A U-shaped block (24 mm across its outer faces, a 12 x 20 mm notch from below), 20 mm deep:
  // its decomposition has several convex parts, and it is held like any other object.
  test::ScratchDirectory dir;
  {
    const double yz[10][2] = {{-12, -15}, {-6, -15}, {-6, 5}, {6, 5},   {6, -15},
                              {12, -15},  {12, 15},  {6, 15}, {-6, 15}, {-12, 15}};
    std::ofstream obj(dir.path("u.obj"));
    for (double x : {-10.0, 10.0}) {
      for (const auto& p : yz) obj << "v " << x << " " << p[0] << " " << p[1] << "\n";
    }
    const int caps[8][3] = {{0, 1, 2}, {0, 2, 9}, {2, 8, 9}, {2, 3, 7},
                            {2, 7, 8}, {4, 5, 3}, {3, 5, 6}, {3, 6, 7}};
    for (const auto& t : caps) {
      obj << "f " << t[0] + 1 << " " << t[2] + 1 << " " << t[1] + 1 << "\n";     // x = -10
      obj << "f " << t[0] + 11 << " " << t[1] + 11 << " " << t[2] + 11 << "\n";  // x = +10
    }
    for (int i = 0; i < 10; ++i) {
      const int a = i + 1, b = (i + 1) % 10 + 1;
      obj << "f " << a << " " << b << " " << b + 10 << "\nf " << a << " " << b + 10 << " " << a + 10
          << "\n";
    }
  }
  GripperSimConfig config = cubeConfig();
  config.object.mesh = dir.path("u.obj");
  config.object.scale = 0.001;
  config.object.mass_kg = 0.05;
  config.object.collision = "hull";
  EXPECT_EQ(GripperSim(config).collisionPartCount(), 1);
  config.object.collision = "decomposition";
  GripperSim sim(config);
  EXPECT_GE(sim.collisionPartCount(), 2);
  sim.reset(1, 0.0);
  for (Finger finger : {Finger::kLeft, Finger::kRight}) {
    EXPECT_TRUE(sim.contact(finger).in_contact);
    EXPECT_NEAR(sim.contact(finger).penetration_m, 1e-3, 0.05e-3);
  }
  const Eigen::Isometry3d before = sim.objectInWorld();
  sim.step(3000);
  EXPECT_LT((sim.objectInWorld().translation() - before.translation()).norm(), 0.1e-3);
  EXPECT_FALSE(sim.dropped());
}

TEST(ContactPatchTest, SphereContactGrowsWithTheSqueezeAsGeometryPredicts) {
  const SensorModel sensor = makeDigitSensorModel();
  GripperSimConfig config = cubeConfig();
  config.object.mesh = "sphere:10";
  config.object.mass_kg = 0.03;
  config.episode.grasp_indentation_m = 0.3e-3;
  GripperSim sim(config);
  const EpisodeStart start = sim.reset(1, 0.0);
  ContactPatchMeter meter(sensor);
  double previous_area = 0.0;
  for (int i = 0; i < 4; ++i) {
    sim.setOpening(start.grasp_opening - 0.01 * i);
    sim.step(600);
    const GelContactState& c = sim.contact(Finger::kLeft);
    const ContactPatch patch = meter.measure(sim.object().mesh, c.object_in_gel);
    // The footprint of a sphere cap as deep as the rendered indentation.
    const double d = patch.max_indentation_m, r = 0.010;
    const double disc = M_PI * (2 * r * d - d * d);
    EXPECT_NEAR(patch.area_m2, disc, 0.06 * disc) << "squeeze " << i;
    // Physics (the exact sphere) and image (its 96 x 192 tessellation, at the sensor's pixels)
    // agree on the depth.
    EXPECT_NEAR(c.penetration_m, d, 0.01e-3) << "squeeze " << i;
    EXPECT_LT(patch.centroid_m.norm(), 0.2e-3);  // seated at the gel centre
    EXPECT_GT(patch.area_m2, previous_area);
    previous_area = patch.area_m2;
  }
}

TEST(ContactPatchTest, CentroidIsWhereTheBallPressesInGelMillimetres) {
  const SensorModel sensor = makeDigitSensorModel();
  ContactPatchMeter meter(sensor);
  const TexturedMesh ball = makeUvSphere(0.004, 64, 128);
  for (const Eigen::Vector2d& at :
       {Eigen::Vector2d(2.0e-3, -3.0e-3), Eigen::Vector2d(-4.5e-3, 5e-3)}) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Vector3d(at.x(), at.y(), 0.004 - 0.6e-3);  // 0.6 mm deep
    const ContactPatch patch = meter.measure(ball, pose);
    ASSERT_GT(patch.pixels, 100);
    // Symmetric footprint: its centroid is the ball's centre to well within a pixel (0.053 mm).
    EXPECT_NEAR(patch.centroid_m.x(), at.x(), 0.02e-3);
    EXPECT_NEAR(patch.centroid_m.y(), at.y(), 0.02e-3);
    EXPECT_NEAR(patch.max_indentation_m, 0.6e-3, 0.01e-3);
    EXPECT_NEAR(patch.area_m2, M_PI * (2 * 0.004 * 0.6e-3 - 0.36e-6), 0.03 * patch.area_m2);
  }
}

TEST(ContactPatchTest, CubeFaceCoversTheGelAndNothingTouchesWhenOpen) {
  const SensorModel sensor = makeDigitSensorModel();
  GripperSim sim(cubeConfig());
  sim.reset(1, 0.0);
  ContactPatchMeter meter(sensor);
  const ContactPatch held =
      meter.measure(sim.object().mesh, sim.contact(Finger::kRight).object_in_gel);
  EXPECT_EQ(held.pixels, sensor.rows * sensor.cols);
  EXPECT_NEAR(held.max_indentation_m, sim.contact(Finger::kRight).penetration_m, 1e-6);
  sim.setOpening(1.0);
  sim.step(1500);
  EXPECT_TRUE(sim.dropped());
  const ContactPatch open =
      meter.measure(sim.object().mesh, sim.contact(Finger::kRight).object_in_gel);
  EXPECT_EQ(open.pixels, 0);
  EXPECT_EQ(open.area_m2, 0.0);
}

}  // namespace
}  // namespace norm2tex
