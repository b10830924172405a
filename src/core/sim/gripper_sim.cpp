#include "norm2tex/sim/gripper_sim.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>

#include <btBulletDynamicsCommon.h>

#include "norm2tex/common/error.hpp"
#include "sim/bullet_eigen.hpp"
#include "sim/gel_pad_contacts.hpp"
#include "sim/object_collision.hpp"

namespace norm2tex {
namespace {

// The open gripper must clear the object by this much on each side.
constexpr double kSeatClearance = 1e-3;
// After the fingers reach the grasp command, the contact settles this long before gravity.
constexpr double kGraspHoldS = 0.1;
// An object's side must overlap the gel pads by this much (height) at a height offset reset()
// accepts.
constexpr double kMinPadOverlap = 1e-3;
// Collision filter groups: the gels never collide through Bullet (the package makes their
// contacts), the object still meets the floor.
constexpr int kGelGroup = 1 << 6;
constexpr int kObjectGroup = 1 << 7;

// Uniform in [0, 1) from a 64-bit engine, the same on every platform
// (std::uniform_real_distribution is not specified bit for bit).
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

}  // namespace

struct GripperSim::World {
  btDefaultCollisionConfiguration collision_config;
  btCollisionDispatcher dispatcher{&collision_config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &collision_config};

  std::unique_ptr<btCollisionShape> floor_shape;
  std::unique_ptr<btRigidBody> floor;
  std::unique_ptr<GelPadContacts> gels;  ///< the left gel's is pad 0, the right's pad 1
  std::unique_ptr<btRigidBody> object;

  ~World() {
    gels.reset();  // its manifolds name the object
    if (object) world.removeRigidBody(object.get());
    if (floor) world.removeRigidBody(floor.get());
  }
};

GripperSim::GripperSim(const GripperSimConfig& config) : config_(config) {
  validate(config_);
  object_ = loadObjectMesh(config_.object.mesh, config_.object.scale);
  const Eigen::Vector3d centre = object_.mesh.bounds().center().cast<double>();
  object_in_body_ = Eigen::Translation3d(-centre);
  if (objectWidthM() + 2 * kSeatClearance > config_.gripper.max_gap_m) {
    std::ostringstream message;
    message << "object '" << config_.object.mesh << "' is " << objectWidthM() * 1e3
            << " mm wide along the grip axis: more than gripper.max_gap_mm = "
            << config_.gripper.max_gap_m * 1e3 << " minus 2 mm of clearance";
    throw Error(message.str());
  }
  const EpisodeOptions& e = config_.episode;
  const double grip_depth =
      e.grasp_force_n > 0 ? config_.gel_law.indentation(e.grasp_force_n) : e.grasp_indentation_m;
  const double grip_reach = grip_depth + drivePreload(grip_depth);
  if (e.grasp_opening < 0 && objectWidthM() - 2 * grip_reach < config_.gripper.min_gap_m) {
    std::ostringstream message;
    message << "object '" << config_.object.mesh << "' is " << objectWidthM() * 1e3
            << " mm wide along the grip axis: the closed gripper (gripper.min_gap_mm = "
            << config_.gripper.min_gap_m * 1e3 << ") cannot indent both gels " << grip_depth * 1e3
            << " mm into it";
    if (grip_reach > grip_depth) {
      message << " (its drive would have to close " << (grip_reach - grip_depth) * 1e3
              << " mm further on each side: gripper.stiffness_n_per_mm)";
    }
    throw Error(message.str());
  }
  // Built once: resets rebuild the world but reuse the (stateless) shapes.
  makeCollision(centre);
  findHeightOffsetRange(centre);
  command_ = 1.0;
  finger_position_m_ = config_.gripper.max_gap_m / 2.0;
  drive_position_m_ = finger_position_m_;
  buildWorld(height_offset_range_.first);
}

GripperSim::~GripperSim() = default;

void GripperSim::makeCollision(const Eigen::Vector3d& centre) {
  // The object starts unrotated: the gels face its world +-y sides.
  ObjectCollisionShapes shapes =
      makeObjectCollision(object_, config_.object.collision, centre,
                          config_.gel_law.points().back().first, Eigen::Vector3d::UnitY());
  object_shapes_ = std::move(shapes.shapes);
  contact_parts_ = std::move(shapes.contact_parts);
  contact_capsule_ = shapes.contact_capsule;
  collision_ = shapes.collision;
}

void GripperSim::findHeightOffsetRange(const Eigen::Vector3d& centre) {
  // The gels meet the object within their reach (the law's deepest point) of its extent along
  // the grip axis: both sides' bands must overlap the pads' height, or no grasp can be made.
  const EpisodeOptions& e = config_.episode;
  const double reach = config_.gel_law.points().back().first;
  const double pad = config_.gel_height_m / 2;
  const Eigen::AlignedBox3d bounds = object_.mesh.bounds().cast<double>();
  double low = e.height_offset_low_m, high = e.height_offset_high_m;
  std::ostringstream sides;
  for (double side : {1.0, -1.0}) {
    const double extreme = side > 0 ? bounds.max().y() : bounds.min().y();
    double z_lo = std::numeric_limits<double>::infinity(), z_hi = -z_lo;
    for (const Eigen::Vector3f& v : object_.mesh.vertices()) {
      if (side * (extreme - v.y()) <= reach) {
        z_lo = std::min(z_lo, v.z() - centre.z());
        z_hi = std::max(z_hi, v.z() - centre.z());
      }
    }
    // At offset o its side spans o + [z_lo, z_hi]; the pads [-pad, pad]; they must overlap by
    // kMinPadOverlap, or the gels would meet it only at their very rim.
    low = std::max(low, -pad - z_hi + kMinPadOverlap);
    high = std::min(high, pad - z_lo - kMinPadOverlap);
    sides << (side > 0 ? "" : ", ") << (side > 0 ? "+y" : "-y") << " side " << z_lo * 1e3 << " to "
          << z_hi * 1e3;
  }
  if (low > high) {
    std::ostringstream message;
    message << "object '" << config_.object.mesh
            << "' cannot be gripped at any height offset of episode.height_offset_mm ["
            << e.height_offset_low_m * 1e3 << ", " << e.height_offset_high_m * 1e3 << "]: within "
            << reach * 1e3 << " mm of its extent along the grip axis its sides span"
            << " z = " << sides.str() << " mm about its centre, the gel pads +-" << pad * 1e3
            << " mm (with " << kMinPadOverlap * 1e3 << " mm of overlap)";
    throw Error(message.str());
  }
  height_offset_range_ = {low, high};
}

double GripperSim::objectMinHalfSizeM() const {
  return static_cast<double>(object_.mesh.bounds().sizes().minCoeff()) / 2.0;
}

double GripperSim::objectWidthM() const {
  return static_cast<double>(object_.mesh.bounds().sizes().y());
}

double GripperSim::drivePreload(double depth) const {
  const double k = config_.gripper.stiffness_n_per_m;
  return k > 0.0 ? config_.gel_law.force(depth) / k : 0.0;
}

double GripperSim::gapForOpening(double opening) const {
  const GripperOptions& g = config_.gripper;
  return g.min_gap_m + opening * (g.max_gap_m - g.min_gap_m);
}

double GripperSim::opening() const {
  const GripperOptions& g = config_.gripper;
  return (2.0 * finger_position_m_ - g.min_gap_m) / (g.max_gap_m - g.min_gap_m);
}

void GripperSim::setOpening(double opening) {
  if (!(opening >= 0.0 && opening <= 1.0)) {
    std::ostringstream message;
    message << "gripper opening " << opening << " is out of range; valid: [0, 1] (0 = closed)";
    throw Error(message.str());
  }
  command_ = opening;
}

void GripperSim::addOpening(double delta) {
  if (!(std::abs(delta) <= 1.0)) {
    std::ostringstream message;
    message << "gripper opening delta " << delta << " is out of range; valid: [-1, 1]";
    throw Error(message.str());
  }
  command_ = std::clamp(command_ + delta, 0.0, 1.0);
}

Eigen::Isometry3d GripperSim::baseInWorld() const {
  return Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, config_.gripper.base_height_m));
}

Eigen::Isometry3d GripperSim::fingerInBase(Finger finger) const {
  const double side = finger == Finger::kLeft ? 1.0 : -1.0;
  return Eigen::Isometry3d(Eigen::Translation3d(0.0, side * finger_position_m_, 0.0));
}

Eigen::Isometry3d GripperSim::gelInFinger(Finger finger) {
  // Columns: the gel's x (image right), y (image down = world -z), z (towards the other finger).
  Eigen::Matrix3d r;
  if (finger == Finger::kLeft) {
    r << -1, 0, 0,  //
        0, 0, -1,   //
        0, -1, 0;
  } else {
    r << 1, 0, 0,  //
        0, 0, 1,   //
        0, -1, 0;
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = r;
  return pose;
}

Eigen::Isometry3d GripperSim::gelInWorld(Finger finger) const {
  return baseInWorld() * fingerInBase(finger) * gelInFinger(finger);
}

Eigen::Isometry3d GripperSim::objectInWorld() const {
  return toEigen(world_->object->getWorldTransform()) * object_in_body_;
}

void GripperSim::buildWorld(double object_height_m) {
  world_ = std::make_unique<World>();
  btDiscreteDynamicsWorld& w = world_->world;
  const PhysicsOptions& p = config_.physics;
  w.setGravity(btVector3(0, 0, -p.gravity_m_s2));
  btContactSolverInfo& solver = w.getSolverInfo();
  solver.m_numIterations = p.solver_iterations;
  solver.m_frictionERP = p.friction_erp;
  // Bullet's residual is the largest squared velocity correction (m/s) of an iteration: stop
  // once the contacts have converged instead of always running every iteration (a held object
  // converges in a few; 3-4x fewer per tick, the same grasp).
  solver.m_leastSquaresResidualThreshold =
      static_cast<btScalar>(p.solver_tolerance_m_s * p.solver_tolerance_m_s);
  // Two friction directions per contact: a held object resists slip along the gel in 2-D.
  solver.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;

  // Floor: where a dropped object ends up.
  world_->floor_shape = std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0);
  world_->floor = std::make_unique<btRigidBody>(
      btRigidBody::btRigidBodyConstructionInfo(0, nullptr, world_->floor_shape.get()));
  world_->floor->setFriction(0.5);
  w.addRigidBody(world_->floor.get(), btBroadphaseProxy::StaticFilter,
                 btBroadphaseProxy::AllFilter & ~kGelGroup);

  // Gels: the package's compliant contact with the material's friction (Bullet multiplies the
  // two bodies' coefficients; the object's is 1).
  const GelPadOptions pads = gelPadOptionsOf(config_, objectMinHalfSizeM());
  world_->gels = std::make_unique<GelPadContacts>(w, world_->dispatcher, 2, pads, kGelGroup);

  // Object: dynamic, its body at its bounds' centre.
  btCollisionShape* shape = object_shapes_.back().get();
  btVector3 inertia(0, 0, 0);
  shape->calculateLocalInertia(config_.object.mass_kg, inertia);
  btRigidBody::btRigidBodyConstructionInfo info(config_.object.mass_kg, nullptr, shape, inertia);
  info.m_friction = 1.0;
  info.m_restitution = 0;
  world_->object = std::make_unique<btRigidBody>(info);
  world_->object->setActivationState(DISABLE_DEACTIVATION);
  world_->object->setCollisionFlags(world_->object->getCollisionFlags() |
                                    btCollisionObject::CF_HAS_FRICTION_ANCHOR);
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.translation() = Eigen::Vector3d(0, 0, config_.gripper.base_height_m + object_height_m);
  world_->object->setWorldTransform(toBt(body));
  w.addRigidBody(world_->object.get(), kObjectGroup, btBroadphaseProxy::StaticFilter);
  // The gel contacts live in the package's own manifolds, which the solver takes like any other.
  world_->gels->attach(*world_->object, GelContactGeometry{&contact_parts_, &contact_capsule_});

  moveFingers(0.0);
  contacts_.assign(2, GelContactState{});
  for (int i = 0; i < 2; ++i) {
    contacts_[i].object_in_gel = gelInWorld(static_cast<Finger>(i)).inverse() * objectInWorld();
  }
}

void GripperSim::moveFingers(double dt) {
  // The drive: coupled, speed-limited position control; the force limit stops closing (never
  // opening).
  const double target = gapForOpening(command_) / 2.0;
  const double max_move = config_.gripper.max_speed_m_s * dt;
  double next = drive_position_m_ + std::clamp(target - drive_position_m_, -max_move, max_move);
  const double force = std::max(contacts_[0].normal_force_n, contacts_[1].normal_force_n);
  if (next < drive_position_m_ && force >= config_.gripper.max_force_n) next = drive_position_m_;
  drive_position_m_ = next;
  finger_position_m_ = config_.gripper.stiffness_n_per_m > 0.0 ? compliantFingerPosition(max_move)
                                                               : drive_position_m_;
  for (int i = 0; i < 2; ++i) world_->gels->place(i, gelInWorld(static_cast<Finger>(i)));
}

double GripperSim::compliantFingerPosition(double max_move) const {
  // Each finger is a spring of stiffness k in series with its gel: at rest it sits at
  // x = drive + F(x) / k, F the gel's force at finger position x. The gel is 4-15 times
  // stiffer than a 1 N/mm drive (its law's slope is 4 N/mm at first touch, 15 N/mm at 0.5 mm),
  // so x <- drive + F / k per tick would overshoot by that factor: it diverges until the speed
  // limit catches it, then rings there (0.2 N and 20 um on a held cube). One Newton step
  // of x - drive - F(x) / k = 0 per tick instead, with dF/dx = -k_gel the law's tangent at the
  // indentation that carries F (both gels are pressed deeper when the fingers close, the
  // object between them staying put): the residual shrinks every tick by the error in k_gel
  // alone, however stiff the gel. Out of contact k_gel = 0 and the finger is where the drive
  // is. One drive moves both fingers (a servo through a rack or linkage), so both sit back by
  // the mean of the two forces: at rest the object's balance along the grip axis makes them
  // equal, in motion the mean is what the drive carries.
  const double k = config_.gripper.stiffness_n_per_m;
  const double force = 0.5 * (contacts_[0].normal_force_n + contacts_[1].normal_force_n);
  const double k_gel =
      force > 0.0 ? config_.gel_law.tangentStiffness(config_.gel_law.indentation(force)) : 0.0;
  const double residual = drive_position_m_ + force / k - finger_position_m_;
  return finger_position_m_ + std::clamp(residual * k / (k + k_gel), -max_move, max_move);
}

void GripperSim::measureContacts(double dt) {
  const Eigen::Isometry3d object_in_world = objectInWorld();
  world_->gels->measure(dt, object_in_world, contacts_);
  // Dropped: free of both gels and below their lower edge.
  const double lower_edge = config_.gripper.base_height_m - config_.gel_height_m / 2.0;
  if (!contacts_[0].in_contact && !contacts_[1].in_contact &&
      object_in_world.translation().z() < lower_edge) {
    dropped_ = true;
  }
}

void GripperSim::step(int ticks) {
  const int substeps = config_.physics.substeps;
  const double dt = tickSeconds() / substeps;
  for (int t = 0; t < ticks; ++t) {
    for (int s = 0; s < substeps; ++s) {
      moveFingers(dt);
      world_->gels->updateContacts();
      world_->gels->updateStiffness();
      world_->world.stepSimulation(dt, 0, dt);
      measureContacts(dt);
    }
    ++ticks_;
  }
}

double GripperSim::closeOnTheObject(double offset_m) {
  const EpisodeOptions& e = config_.episode;
  const GripperOptions& g = config_.gripper;
  const auto openingForGap = [&](double gap) {
    return std::clamp((gap - g.min_gap_m) / (g.max_gap_m - g.min_gap_m), 0.0, 1.0);
  };
  const auto ticksToArrive = [&] {
    const double travel = std::abs(drive_position_m_ - gapForOpening(command_) / 2.0);
    return static_cast<int>(std::ceil(travel / g.max_speed_m_s / tickSeconds()));
  };
  if (e.grasp_opening >= 0.0) {
    command_ = e.grasp_opening;
    step(ticksToArrive());
    return command_;
  }
  // Close until both gels touch. An object that has not touched both by the time the gap is
  // narrower than its width minus the gel law's deepest point on each side never will: its
  // sides miss the pads at this height.
  const double deepest_law_point = config_.gel_law.points().back().first;
  command_ = openingForGap(objectWidthM() - 2 * deepest_law_point);
  const int limit = ticksToArrive() + 1;
  for (int t = 0; !(contacts_[0].in_contact && contacts_[1].in_contact); ++t) {
    if (t > limit) {
      std::ostringstream message;
      message << "the object does not reach both gel pads at height offset " << offset_m * 1e3
              << " mm: its sides miss the " << config_.gel_width_m * 1e3 << " x "
              << config_.gel_height_m * 1e3
              << " mm pads there (choose a smaller episode.height_offset_mm)";
      throw Error(message.str());
    }
    step(1);
  }
  // Then on to the grip, measured on the object's surface: its width between the gels is the gap
  // plus what each gel is already indented.
  const double depth =
      e.grasp_force_n > 0.0 ? config_.gel_law.indentation(e.grasp_force_n) : e.grasp_indentation_m;
  const double width =
      2.0 * finger_position_m_ + contacts_[0].penetration_m + contacts_[1].penetration_m;
  // A compliant drive must go further by the deflection the grip's force causes.
  command_ = openingForGap(width - 2.0 * (depth + drivePreload(depth)));
  step(ticksToArrive());
  return command_;
}

EpisodeStart GripperSim::reset(std::uint64_t seed, std::optional<double> height_offset_m) {
  const EpisodeOptions& e = config_.episode;
  std::mt19937_64 rng(seed);
  const auto [low, high] = height_offset_range_;
  const double offset = height_offset_m ? *height_offset_m : low + uniform01(rng) * (high - low);
  // Outside the scene's range the grasp is not the scene's (too high: the object barely touches
  // the gels; below: it tumbles), so a given offset is refused rather than clamped.
  if (!(offset >= e.height_offset_low_m && offset <= e.height_offset_high_m)) {
    std::ostringstream message;
    message << "height offset " << offset << " m is out of the scene's range; valid: ["
            << e.height_offset_low_m << ", " << e.height_offset_high_m
            << "] m (episode.height_offset_mm)";
    throw Error(message.str());
  }
  if (!(offset >= low && offset <= high)) {
    std::ostringstream message;
    message << "height offset " << offset << " m: the object's sides miss the gel pads there; "
            << "valid for this object: [" << low << ", " << high << "] m";
    throw Error(message.str());
  }
  EpisodeStart start;
  start.seed = seed;
  start.height_offset_m = offset;
  const GripperOptions& g = config_.gripper;

  // Seat the object, centred on its extent along the grip axis, between gels opened
  // kSeatClearance wider than it on each side, without gravity on it.
  dropped_ = false;
  const auto seat = [&] {
    command_ = std::clamp(
        (objectWidthM() + 2 * kSeatClearance - g.min_gap_m) / (g.max_gap_m - g.min_gap_m), 0.0,
        1.0);
    finger_position_m_ = gapForOpening(command_) / 2.0;
    drive_position_m_ = finger_position_m_;
    buildWorld(offset);
  };
  seat();
  for (int i = 0; i < 2; ++i) {
    for (const auto& part : world_->gels->objectPointsIn(i)) {
      if (!part.empty()) throw Error("the seated object overlaps a gel (a bug: please report it)");
    }
  }
  world_->object->setGravity(btVector3(0, 0, 0));
  try {
    start.grasp_opening = closeOnTheObject(offset);
  } catch (const Error&) {
    seat();  // open again, the object at rest between the gels
    throw;
  }
  // Hold, still weightless, until the contacts settle; then gravity.
  step(static_cast<int>(std::ceil(kGraspHoldS / tickSeconds())));
  world_->object->setGravity(world_->world.getGravity());
  step(static_cast<int>(std::ceil(e.settle_s / tickSeconds())));
  start.episode = ++episode_;
  return start;
}

}  // namespace norm2tex
