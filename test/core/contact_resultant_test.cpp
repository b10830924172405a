// The twisting moment a contact puts on a gel: contactResultant against moments worked out by
// hand, and HandSim's gels balancing the moment of a held cube's weight about its grip.
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/contact_resultant.hpp"
#include "norm2tex/sim/gripper_sim_config.hpp"
#include "norm2tex/sim/hand_sim.hpp"

namespace norm2tex {
namespace {

PointLoad at(double x, double y, double normal, double fx, double fy) {
  PointLoad p;
  p.position_m = {x, y};
  p.normal_n = normal;
  p.tangential_n = {fx, fy};
  return p;
}

TEST(ContactResultant, TwoOpposedFrictionForcesTwistTheGelCounterClockwise) {
  // 1 N up the image at x = +5 mm, 1 N down it at x = -5 mm: a couple of 2 x 5 mm x 1 N turning
  // +x towards +y, no net force, about the centre of equal normal forces.
  const ContactResultant r =
      contactResultant({at(0.005, 0.0, 2.0, 0.0, 1.0), at(-0.005, 0.0, 2.0, 0.0, -1.0)});
  EXPECT_DOUBLE_EQ(r.normal_n, 4.0);
  EXPECT_NEAR(r.tangential_n.norm(), 0.0, 1e-15);
  EXPECT_NEAR(r.pressure_centre_m.norm(), 0.0, 1e-15);
  EXPECT_NEAR(r.twist_moment_nm, 0.010, 1e-15);
  // The other way round turns +x away from +y.
  const ContactResultant back =
      contactResultant({at(0.005, 0.0, 2.0, 0.0, -1.0), at(-0.005, 0.0, 2.0, 0.0, 1.0)});
  EXPECT_NEAR(back.twist_moment_nm, -0.010, 1e-15);
}

TEST(ContactResultant, TheMomentIsTakenAboutTheNormalForcesCentroid) {
  // 3 N at the origin and 1 N at x = 4 mm press around x = 1 mm; 1 N along +y at the origin
  // acts 1 mm to the centre's -x side: -1 mN m (moving the reference point by c changes the
  // moment by -c x F).
  const ContactResultant r =
      contactResultant({at(0.0, 0.0, 3.0, 0.0, 1.0), at(0.004, 0.0, 1.0, 0.0, 0.0)});
  EXPECT_NEAR(r.pressure_centre_m.x(), 0.001, 1e-15);
  EXPECT_NEAR(r.pressure_centre_m.y(), 0.0, 1e-15);
  EXPECT_NEAR(r.tangential_n.y(), 1.0, 1e-15);
  EXPECT_NEAR(r.twist_moment_nm, -0.001, 1e-15);
  // A force along its own arm has no moment.
  EXPECT_NEAR(contactResultant({at(0.0, 0.0, 1.0, 0.0, 0.0), at(0.002, 0.0, 1.0, 3.0, 0.0)})
                  .twist_moment_nm,
              0.0, 1e-15);
}

TEST(ContactResultant, UnloadedPointsStillSayWhereTheContactIs) {
  const ContactResultant idle =
      contactResultant({at(0.002, 0.001, 0.0, 0.0, 0.0), at(0.004, 0.003, 0.0, 0.0, 0.0)});
  EXPECT_NEAR(idle.pressure_centre_m.x(), 0.003, 1e-15);
  EXPECT_NEAR(idle.pressure_centre_m.y(), 0.002, 1e-15);
  EXPECT_EQ(idle.twist_moment_nm, 0.0);
  const ContactResultant none = contactResultant({});
  EXPECT_EQ(none.normal_n, 0.0);
  EXPECT_EQ(none.pressure_centre_m, Eigen::Vector2d::Zero());
  EXPECT_EQ(none.twist_moment_nm, 0.0);
}

TEST(GelTwistMoment, TheGelsHoldTheMomentOfACubeGrippedOffItsCentre) {
  // The built-in parallel gripper grips the 30 mm cube 4 mm off its centre along world x: its
  // weight then turns it about the grip axis (world y) with m g dx, which only the gels'
  // friction can hold, as a twist about each gel's normal. The cube's faces cover both pads
  // whatever the offset, so where the gels press does not move with it.
  const std::string source = NORM2TEX_SOURCE_DIR;
  GripperSimConfig scene = loadGripperSimConfig(source + "/config/scenes/cube.yaml");
  setGelFromSensor(makeDigitSensorModel(), scene);
  HandSimConfig config = makeHandSimConfig(source + "/config/hands/parallel_gripper.yaml", scene);
  config.hand.drives["finger_left_joint"].effort = 2.0 * scene.gel_law.force(1e-3);
  const double dx = 0.004;
  config.object_pose = Eigen::Isometry3d(Eigen::Translation3d(dx, 0.0, 0.2));
  HandSim hand(config);
  hand.resetObject(config.object_pose, false);
  hand.setOpening(0.0);
  hand.step(1500);
  hand.setObjectGravity(true);
  hand.step(1000);

  const double weight = scene.object.mass_kg * scene.physics.gravity_m_s2;
  const Eigen::Vector3d com = hand.objectInWorld().translation();
  // The object in equilibrium: about its centre of mass (where its weight acts) the gels'
  // forces at their pressure centres and their twists cancel. A gel's state is what the object
  // does to it, so the sums below are of the gels' loads: they cancel as the object's do.
  Eigen::Vector3d force = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
  double twist[2];
  for (int s = 0; s < 2; ++s) {
    const GelContactState& c = hand.contact(s);
    ASSERT_TRUE(c.in_contact) << hand.sensor(s).name;
    const Eigen::Isometry3d gel = hand.gelInWorld(s);
    const Eigen::Vector3d normal = gel.linear().col(2);
    const Eigen::Vector3d on_gel = gel.linear() * c.shear_force_n - c.normal_force_n * normal;
    const Eigen::Vector3d centre =
        gel * Eigen::Vector3d(c.pressure_centre_m.x(), c.pressure_centre_m.y(), 0.0);
    force += on_gel;
    moment += (centre - com).cross(on_gel) + c.twist_moment_nm * normal;
    // About the grip axis: world y, each gel's +z pointing at the other finger.
    twist[s] = c.twist_moment_nm * normal.y();
    std::printf("%s: twist %.3f mN m (about world y %.3f), pressure centre (%.2f, %.2f) mm\n",
                hand.sensor(s).name.c_str(), c.twist_moment_nm * 1e3, twist[s] * 1e3,
                c.pressure_centre_m.x() * 1e3, c.pressure_centre_m.y() * 1e3);
  }
  const double expected = weight * dx;  // 3.9 mN m
  EXPECT_NEAR(force.z(), -weight, 0.01 * weight);
  EXPECT_LT(moment.norm(), 0.05 * expected) << moment.transpose();
  // Each gel carries about half of it, and the sign says which way: the cube's centre sits at
  // +x, so its weight turns it from +x towards -z, i.e. about +y (right hand), and it drags
  // the gels the same way.
  for (int s = 0; s < 2; ++s) {
    EXPECT_NEAR(twist[s], 0.5 * expected, 0.2 * expected) << hand.sensor(s).name;
  }
  EXPECT_NEAR(twist[0] + twist[1], expected, 0.05 * expected);
}

}  // namespace
}  // namespace norm2tex
