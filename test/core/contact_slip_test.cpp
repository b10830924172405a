// How much of a contact slips, as the contact nodes report it (ContactPatchMeter with a load):
// none under a press, Mindlin's annulus under a tangential force, all of it past friction, and
// near what the renderer's coarser shear stage solves for the same frame.
#include <cmath>

#include <gtest/gtest.h>

#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "norm2tex/sim/contact_patch.hpp"
#include "norm2tex/sim/contact_shear_load.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

// A 4 mm ball 0.6 mm into the gel: a 2.2 mm contact radius, some 90 cells of the shear grid.
Eigen::Isometry3d ballPress() {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(0.0, 0.0, 0.004 - 0.6e-3);
  return pose;
}

ShearLoad load(double fx, double fy, double friction) {
  ShearLoad l;
  l.force_n = {fx, fy};
  l.friction = friction;
  return l;
}

TEST(ContactSlip, APurePressSticksEverywhere) {
  ContactPatchMeter meter(makeDigitSensorModel());
  const TexturedMesh ball = makeUvSphere(0.004, 64, 128);
  const ContactPatch patch = meter.measure(ball, ballPress(), 2.0, ShearLoad{});
  ASSERT_GT(patch.pixels, 1000);
  EXPECT_EQ(patch.slip_fraction, 0.0);
  // Without a load the plain measure reports none either.
  EXPECT_EQ(meter.measure(ball, ballPress()).slip_fraction, 0.0);
}

TEST(ContactSlip, ATangentialForceSlipsMindlinsAnnulus) {
  // Mindlin: the stick disc's radius is a (1 - Q / (mu P))^(1/3), so the slipping share of the
  // area is 1 - (1 - Q / (mu P))^(2/3): 0.37 at half the friction limit, 0.54 at 0.7 of it.
  ContactPatchMeter meter(makeDigitSensorModel());
  const TexturedMesh ball = makeUvSphere(0.004, 64, 128);
  double previous = 0.0;
  for (const double ratio : {0.2, 0.5, 0.7}) {
    const double expected = 1.0 - std::pow(1.0 - ratio, 2.0 / 3.0);
    // Any direction, and the friction from the load.
    const ContactPatch patch =
        meter.measure(ball, ballPress(), 2.0, load(0.6 * ratio * 2.0, 0.8 * ratio * 2.0, 1.0));
    EXPECT_NEAR(patch.slip_fraction, expected, 0.03) << "Q / (mu P) = " << ratio;
    EXPECT_GT(patch.slip_fraction, previous);
    previous = patch.slip_fraction;
  }
  // Without a friction in the load, the sensor model's (1.0 in the DIGIT's): the same slip as
  // with 1.0 given, and with half the friction the force is nearer its limit.
  ShearLoad unset = load(0.0, 1.0, 1.0);
  unset.friction.reset();
  EXPECT_EQ(meter.measure(ball, ballPress(), 2.0, unset).slip_fraction,
            meter.measure(ball, ballPress(), 2.0, load(0.0, 1.0, 1.0)).slip_fraction);
  EXPECT_GT(meter.measure(ball, ballPress(), 2.0, load(0.0, 1.0, 0.6)).slip_fraction,
            meter.measure(ball, ballPress(), 2.0, load(0.0, 1.0, 1.0)).slip_fraction);
}

TEST(ContactSlip, PastFrictionTheWholeContactSlides) {
  ContactPatchMeter meter(makeDigitSensorModel());
  const TexturedMesh ball = makeUvSphere(0.004, 64, 128);
  EXPECT_EQ(meter.measure(ball, ballPress(), 2.0, load(1.2, 0.0, 0.5)).slip_fraction, 1.0);
  // So does a twist beyond what friction holds (a 2.2 mm disc at 2 N and mu 0.5: ~0.6 mN m).
  ShearLoad twist = load(0.0, 0.0, 0.5);
  twist.torque_nm = 0.01;
  EXPECT_EQ(meter.measure(ball, ballPress(), 2.0, twist).slip_fraction, 1.0);
  twist.torque_nm = 0.0001;
  const double partial = meter.measure(ball, ballPress(), 2.0, twist).slip_fraction;
  EXPECT_GT(partial, 0.0);
  EXPECT_LT(partial, 1.0);
}

TEST(ContactSlip, TheRendererSolvesASlipAsLargeOrLargerOnItsCoarserCells) {
  // The same traction on the renderer's 0.4 mm cells: its rim cells, partly in contact and so
  // shallow on average, slip first. No slip and gross slip it solves the same.
  const SensorModel model = makeDigitSensorModel();
  const TexturedMesh ball = makeUvSphere(0.004, 64, 128);
  ContactPatchMeter meter(model);
  TactileRenderer renderer(model);
  renderer.setObject(std::make_shared<TexturedMesh>(ball));
  for (const ShearLoad& l : {load(0.3, 0.4, 0.8), load(-0.9, 0.2, 0.8), load(0.0, 0.0, 0.8),
                             load(2.0, 0.0, 0.8)}) {
    const TactileFrame& frame = renderer.render(ballPress(), -1, 2.0, l);
    ASSERT_TRUE(frame.shear.has_value());
    const double fine = meter.measure(ball, ballPress(), 2.0, l).slip_fraction;
    const double coarse = frame.shear->slipFraction();
    if (fine == 0.0 || fine == 1.0) {
      EXPECT_EQ(coarse, fine);
    } else {
      EXPECT_GE(coarse, fine - 0.02);
      EXPECT_LE(coarse, fine + 0.15);
    }
  }
}

TEST(ContactSlip, BadLoadsAreErrorsWithOrWithoutContact) {
  ContactPatchMeter meter(makeDigitSensorModel());
  const TexturedMesh ball = makeUvSphere(0.004, 64, 128);
  Eigen::Isometry3d away = ballPress();
  away.translation().z() = 0.01;
  for (const Eigen::Isometry3d& pose : {ballPress(), away}) {
    test::expectError([&] { meter.measure(ball, pose, -1.0, ShearLoad{}); }, {"normal force"});
    test::expectError([&] { meter.measure(ball, pose, 1.0, load(NAN, 0.0, 0.5)); }, {"finite"});
    test::expectError([&] { meter.measure(ball, pose, 1.0, load(0.1, 0.0, 0.0)); }, {"friction"});
  }
}

TEST(GelShearLoad, TakesTheContactsForceAndMomentAndAPositiveFriction) {
  GelContactState state;
  state.shear_force_n = Eigen::Vector3d(0.1, -0.4, 1e-9);
  state.twist_moment_nm = 2e-3;
  const ShearLoad l = shearLoadOf(state, 0.7);
  EXPECT_EQ(l.force_n, Eigen::Vector2d(0.1, -0.4));
  EXPECT_EQ(l.torque_nm, 2e-3);
  ASSERT_TRUE(l.friction.has_value());
  EXPECT_EQ(*l.friction, 0.7);
  // A frictionless (or unknown) scene leaves the sensor model's coefficient to the shear stage.
  EXPECT_FALSE(shearLoadOf(state, 0.0).friction.has_value());
  EXPECT_FALSE(shearLoadOf(Eigen::Vector2d::Zero(), 0.0, -1.0).friction.has_value());
}

}  // namespace
}  // namespace norm2tex
