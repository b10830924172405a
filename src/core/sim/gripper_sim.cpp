#include "norm2tex/sim/gripper_sim.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include <btBulletDynamicsCommon.h>

#include <BulletCollision/CollisionShapes/btShapeHull.h>

#include "norm2tex/common/error.hpp"
#include "sim/convex_decomposition.hpp"

namespace norm2tex {
namespace {

// Bullet's default 4 cm margins are larger than the gel's whole range: keep them far below the
// indentations we resolve (box margins sit inside the box, so boxes stay exact).
constexpr double kBoxMargin = 2e-4;
constexpr double kHullMargin = 2e-5;
// The fingers open this far beyond the object before an episode closes them.
constexpr double kSeatClearance = 1e-3;
// After the fingers reach the grasp command, the contact settles this long before gravity.
constexpr double kGraspHoldS = 0.1;
// A gel contact point whose object-side point lies farther than this outside the object's
// collision shape is not a contact (see dropContactsOffTheObject).
constexpr double kOffObjectTolerance = 5e-5;

btVector3 toBt(const Eigen::Vector3d& v) { return btVector3(v.x(), v.y(), v.z()); }
Eigen::Vector3d toEigen(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

btTransform toBt(const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.rotation());
  return btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()), toBt(pose.translation()));
}

Eigen::Isometry3d toEigen(const btTransform& t) {
  const btQuaternion q = t.getRotation();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()).normalized().toRotationMatrix();
  pose.translation() = toEigen(t.getOrigin());
  return pose;
}

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
  std::unique_ptr<btCollisionShape> gel_shape;
  std::unique_ptr<btRigidBody> floor;
  std::array<std::unique_ptr<btRigidBody>, 2> gels;
  std::unique_ptr<btRigidBody> object;

  ~World() {
    if (object) world.removeRigidBody(object.get());
    for (auto& gel : gels) {
      if (gel) world.removeRigidBody(gel.get());
    }
    if (floor) world.removeRigidBody(floor.get());
  }
};

namespace {

// The object's collision shape is the last element; any before it are its parts.
std::vector<std::unique_ptr<btCollisionShape>> makeObjectShapes(const ObjectMesh& object,
                                                                const std::string& collision,
                                                                const Eigen::Vector3d& centre) {
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  const Eigen::Vector3d half = object.mesh.bounds().sizes().cast<double>() / 2.0;
  if (collision == "box" || (collision == "auto" && object.shape == ObjectMesh::Shape::kBox)) {
    auto box = std::make_unique<btBoxShape>(toBt(half));
    box->setMargin(std::min(kBoxMargin, 0.25 * half.minCoeff()));
    shapes.push_back(std::move(box));
    return shapes;
  }
  if (collision == "decomposition") return decomposeConvex(object.mesh, centre, kHullMargin);
  // Spheres take their mesh's hull too (within 5 um of the sphere at 96 x 192): Bullet's
  // sphere-box contact is a single point that did not hold a pinched ball (it slid 7 mm
  // under its own weight at 2.6 N of grip), while the polyhedral hull holds it still. (The
  // hull too touches each gel at one vertex; the gel's torsional friction keeps it from
  // spinning, see updateGelStiffness.)
  // Convex hull of the render mesh's vertices about the body origin, reduced by btShapeHull
  // so contact generation stays cheap for big meshes.
  btConvexHullShape full;
  for (const Eigen::Vector3f& v : object.mesh.vertices()) {
    full.addPoint(toBt(v.cast<double>() - centre), false);
  }
  full.recalcLocalAabb();
  full.setMargin(0.0);
  btShapeHull reducer(&full);
  reducer.buildHull(0.0);
  auto hull = std::make_unique<btConvexHullShape>();
  for (int i = 0; i < reducer.numVertices(); ++i) {
    hull->addPoint(reducer.getVertexPointer()[i], false);
  }
  hull->recalcLocalAabb();
  hull->setMargin(kHullMargin);
  shapes.push_back(std::move(hull));
  return shapes;
}

// How far (m) a point in the object's body frame lies outside its collision shape, at least:
// the largest p.u - h(u) over the point's own direction and the six axes, h the shape's
// support function (margin included). Never positive for a point on or in the shape; part is
// the compound child the point is on.
double distanceOutsideObject(const btCollisionShape& shape, int part, const btVector3& point) {
  const btCollisionShape* child = &shape;
  btVector3 p = point;
  if (shape.isCompound()) {
    const auto& compound = static_cast<const btCompoundShape&>(shape);
    if (part < 0 || part >= compound.getNumChildShapes()) return 0.0;
    child = compound.getChildShape(part);
    p = compound.getChildTransform(part).invXform(point);
  }
  if (!child->isConvex()) return 0.0;
  const auto& convex = static_cast<const btConvexShape&>(*child);
  double outside = 0.0;
  const auto probe = [&](const btVector3& u) {
    outside = std::max(outside, static_cast<double>(p.dot(u) -
                                                    convex.localGetSupportingVertex(u).dot(u)));
  };
  if (p.length2() > 0) probe(p.normalized());
  for (int axis = 0; axis < 3; ++axis) {
    btVector3 u(0, 0, 0);
    u[axis] = 1;
    probe(u);
    probe(-u);
  }
  return outside;
}

}  // namespace

GripperSim::GripperSim(const GripperSimConfig& config) : config_(config) {
  validate(config_);
  object_ = loadObjectMesh(config_.object.mesh, config_.object.scale);
  const Eigen::Vector3d centre = object_.mesh.bounds().center().cast<double>();
  object_in_body_ = Eigen::Translation3d(-centre);
  // Built once: resets rebuild the world but reuse the (stateless) shape.
  object_shapes_ = makeObjectShapes(object_, config_.object.collision, centre);
  if (objectWidthM() + 2 * kSeatClearance > config_.gripper.max_gap_m) {
    std::ostringstream message;
    message << "object '" << config_.object.mesh << "' is " << objectWidthM() * 1e3
            << " mm wide along the grip axis: more than gripper.max_gap_mm = "
            << config_.gripper.max_gap_m * 1e3 << " minus 2 mm of clearance";
    throw Error(message.str());
  }
  command_ = 1.0;
  finger_position_m_ = config_.gripper.max_gap_m / 2.0;
  buildWorld(config_.episode.height_offset_low_m);
}

GripperSim::~GripperSim() = default;

int GripperSim::collisionPartCount() const {
  return std::max<int>(1, static_cast<int>(object_shapes_.size()) - 1);
}

double GripperSim::objectMinHalfSizeM() const {
  return static_cast<double>(object_.mesh.bounds().sizes().minCoeff()) / 2.0;
}

double GripperSim::objectWidthM() const {
  return static_cast<double>(object_.mesh.bounds().sizes().y());
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
  w.addRigidBody(world_->floor.get());

  // Gels: kinematic boxes behind the gel surface, soft-contact, with the material's friction
  // (Bullet multiplies the two bodies' coefficients; the object's is 1).
  const btVector3 gel_half(config_.gel_width_m / 2, config_.gel_height_m / 2,
                           config_.gel_thickness_m / 2);
  auto gel_box = std::make_unique<btBoxShape>(gel_half);
  gel_box->setMargin(kBoxMargin);
  world_->gel_shape = std::move(gel_box);
  for (int i = 0; i < 2; ++i) {
    btRigidBody::btRigidBodyConstructionInfo info(0, nullptr, world_->gel_shape.get());
    info.m_friction = config_.object.friction;
    info.m_restitution = 0;
    auto gel = std::make_unique<btRigidBody>(info);
    gel->setCollisionFlags(gel->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT |
                           btCollisionObject::CF_HAS_FRICTION_ANCHOR);
    gel->setActivationState(DISABLE_DEACTIVATION);
    gel->setContactStiffnessAndDamping(config_.gel_law.secantStiffness(0.0), p.gel_damping);
    w.addRigidBody(gel.get());
    world_->gels[i] = std::move(gel);
  }

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
  w.addRigidBody(world_->object.get());

  moveFingers(0.0);
  contacts_ = {};
  for (int i = 0; i < 2; ++i) {
    contacts_[i].object_in_gel = gelInWorld(static_cast<Finger>(i)).inverse() * objectInWorld();
  }
}

void GripperSim::moveFingers(double dt) {
  // Coupled, speed-limited position control; the force limit stops closing (never opening).
  const double target = gapForOpening(command_) / 2.0;
  const double max_move = config_.gripper.max_speed_m_s * dt;
  double next = finger_position_m_ + std::clamp(target - finger_position_m_, -max_move, max_move);
  const double force = std::max(contacts_[0].normal_force_n, contacts_[1].normal_force_n);
  if (next < finger_position_m_ && force >= config_.gripper.max_force_n) next = finger_position_m_;
  finger_position_m_ = next;
  for (int i = 0; i < 2; ++i) {
    // The gel box's centre sits half a thickness behind the gel surface (gel -z).
    const Eigen::Isometry3d box = gelInWorld(static_cast<Finger>(i)) *
                                  Eigen::Translation3d(0, 0, -config_.gel_thickness_m / 2);
    btRigidBody& gel = *world_->gels[i];
    // Kinematic bodies: Bullet derives their velocity from the change of this transform.
    gel.setWorldTransform(toBt(box));
    gel.setInterpolationWorldTransform(gel.getWorldTransform());
  }
}

template <typename Visit>
void GripperSim::forEachGelPoint(int gel_index, Visit visit) const {
  btDispatcher& dispatcher = world_->dispatcher;
  const btCollisionObject* gel = world_->gels[gel_index].get();
  const btCollisionObject* object = world_->object.get();
  for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
    btPersistentManifold* manifold = dispatcher.getManifoldByIndexInternal(m);
    const bool gel_is_a = manifold->getBody0() == gel && manifold->getBody1() == object;
    if (!gel_is_a && !(manifold->getBody1() == gel && manifold->getBody0() == object)) continue;
    for (int c = 0; c < manifold->getNumContacts(); ++c) {
      visit(manifold->getContactPoint(c), gel_is_a);
    }
  }
}

void GripperSim::dropContactsOffTheObject() {
  // Bullet's GJK can hand back a witness point that is not on the object at all when a hull
  // vertex first touches a gel face at distance ~0: a sphere's hull touched the gel with points
  // 18.7 mm from the centre of a 10 mm ball, at the gel's corners. Such a point is never broken
  // (neither body slides along the gel), so it stays in the manifold as a rigid lever arm on the
  // object: a 0.26 degree tilt of the held ball made it 0.11 mm deeper than the real contact,
  // the deepest point set the gel's force, and the ball sat 0.13 mm shallower than the physics
  // reported (Bullet 2.88; 0.11 mm with 3.x). Points off the object are removed after each step;
  // real ones lie on the shape, within its margin.
  const btCollisionShape& shape = *object_shapes_.back();
  btDispatcher& dispatcher = world_->dispatcher;
  for (int i = 0; i < 2; ++i) {
    const btCollisionObject* gel = world_->gels[i].get();
    const btCollisionObject* object = world_->object.get();
    for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
      btPersistentManifold* manifold = dispatcher.getManifoldByIndexInternal(m);
      const bool gel_is_a = manifold->getBody0() == gel && manifold->getBody1() == object;
      if (!gel_is_a && !(manifold->getBody1() == gel && manifold->getBody0() == object)) continue;
      for (int c = manifold->getNumContacts() - 1; c >= 0; --c) {
        const btManifoldPoint& point = manifold->getContactPoint(c);
        const double outside =
            gel_is_a ? distanceOutsideObject(shape, point.m_index1, point.m_localPointB)
                     : distanceOutsideObject(shape, point.m_index0, point.m_localPointA);
        if (outside > kOffObjectTolerance) manifold->removeContactPoint(c);
      }
    }
  }
}

void GripperSim::updateGelStiffness() {
  // Secant stiffness of the law at the current penetration, shared among the contact points
  // in proportion to their depth: sum_i k d_i = F(d_max).
  const double damping = config_.physics.gel_damping + world_->object->getContactDamping();
  for (int i = 0; i < 2; ++i) {
    double deepest = 0.0, sum = 0.0;
    int points = 0;
    forEachGelPoint(i, [&](const btManifoldPoint& point, bool) {
      ++points;
      const double d = -point.getDistance();
      if (d > 0.0) {
        deepest = std::max(deepest, d);
        sum += d;
      }
    });
    const double k =
        sum > 0.0 ? config_.gel_law.force(deepest) / sum : config_.gel_law.secantStiffness(0.0);
    world_->gels[i]->setContactStiffnessAndDamping(k, config_.physics.gel_damping);
    // The gel touches over a patch, not a point: Coulomb friction over a disc of radius a
    // under Hertzian pressure resists twisting up to (3 pi / 16) mu F a. Several contact points
    // resist it through their lateral friction, but a single one has no such torque, so a ball
    // touching each gel at one hull vertex would spin freely about the grip axis. A lone point
    // gets the patch's torsional friction, a = sqrt(2 R d) the footprint of a ball of the
    // object's smallest half-size R at its depth d. (Bullet applies torsional friction only
    // with rolling friction on: a negligible one, 1 nm.)
    const double patch_radius =
        points == 1 ? std::sqrt(2.0 * objectMinHalfSizeM() * deepest) : 0.0;
    const btScalar spinning = static_cast<btScalar>(3.0 * M_PI / 16.0 *
                                                    config_.object.friction * patch_radius);
    // Points kept by a friction anchor are not re-created by collision detection: set them too.
    forEachGelPoint(i, [&](btManifoldPoint& point, bool) {
      point.m_combinedContactStiffness1 = k;
      point.m_combinedContactDamping1 = damping;
      point.m_contactPointFlags |= BT_CONTACT_FLAG_CONTACT_STIFFNESS_DAMPING;
      point.m_combinedSpinningFriction = spinning;
      point.m_combinedRollingFriction = spinning > 0 ? btScalar(1e-9) : btScalar(0);
    });
  }
}

void GripperSim::measureContacts(double dt) {
  const Eigen::Isometry3d object_in_world = objectInWorld();
  for (int i = 0; i < 2; ++i) {
    const Eigen::Isometry3d gel_in_world = gelInWorld(static_cast<Finger>(i));
    GelContactState& state = contacts_[i];
    state = GelContactState{};
    state.object_in_gel = gel_in_world.inverse() * object_in_world;
    Eigen::Vector3d shear_world = Eigen::Vector3d::Zero();
    forEachGelPoint(i, [&](const btManifoldPoint& point, bool gel_is_a) {
      state.penetration_m =
          std::max(state.penetration_m, -static_cast<double>(point.getDistance()));
      state.normal_force_n += point.getAppliedImpulse() / dt;
      // Friction impulses act on body A along the lateral directions; the gel feels the
      // object's reaction.
      const Eigen::Vector3d on_a =
          (toEigen(point.m_lateralFrictionDir1) * point.m_appliedImpulseLateral1 +
           toEigen(point.m_lateralFrictionDir2) * point.m_appliedImpulseLateral2) /
          dt;
      shear_world += gel_is_a ? on_a : Eigen::Vector3d(-on_a);
    });
    state.in_contact = state.penetration_m > 0.0 && state.normal_force_n > 0.0;
    state.shear_force_n = gel_in_world.linear().transpose() * shear_world;
    state.shear_force_n.z() = 0.0;
  }
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
      updateGelStiffness();
      world_->world.stepSimulation(dt, 0, dt);
      dropContactsOffTheObject();
      measureContacts(dt);
    }
    ++ticks_;
  }
}

EpisodeStart GripperSim::reset(std::uint64_t seed, std::optional<double> height_offset_m) {
  const EpisodeOptions& e = config_.episode;
  std::mt19937_64 rng(seed);
  const double offset = height_offset_m
                            ? *height_offset_m
                            : e.height_offset_low_m +
                                  uniform01(rng) * (e.height_offset_high_m - e.height_offset_low_m);
  // Outside the scene's range the grasp is not the scene's (too high: the object barely touches
  // the gels; below: it tumbles), so a given offset is refused rather than clamped.
  if (!(offset >= e.height_offset_low_m && offset <= e.height_offset_high_m)) {
    std::ostringstream message;
    message << "height offset " << offset << " m is out of the scene's range; valid: ["
            << e.height_offset_low_m << ", " << e.height_offset_high_m
            << "] m (episode.height_offset_mm)";
    throw Error(message.str());
  }
  EpisodeStart start;
  start.episode = ++episode_;
  start.seed = seed;
  start.height_offset_m = offset;
  const GripperOptions& g = config_.gripper;
  start.grasp_opening =
      e.grasp_opening >= 0.0
          ? e.grasp_opening
          : std::clamp((objectWidthM() - 2.0 * e.grasp_indentation_m - g.min_gap_m) /
                           (g.max_gap_m - g.min_gap_m),
                       0.0, 1.0);

  // Seat the object between gels opened just wider than it, without gravity on it.
  dropped_ = false;
  command_ = std::clamp(
      (objectWidthM() + 2 * kSeatClearance - g.min_gap_m) / (g.max_gap_m - g.min_gap_m), 0.0, 1.0);
  finger_position_m_ = gapForOpening(command_) / 2.0;
  buildWorld(offset);
  world_->object->setGravity(btVector3(0, 0, 0));

  // Close to the grasp command; then hold, still weightless, until the contacts settle.
  command_ = start.grasp_opening;
  const double travel = std::abs(finger_position_m_ - gapForOpening(command_) / 2.0);
  const int close_ticks = static_cast<int>(std::ceil(travel / g.max_speed_m_s / tickSeconds()));
  step(close_ticks + static_cast<int>(std::ceil(kGraspHoldS / tickSeconds())));

  world_->object->setGravity(world_->world.getGravity());
  step(static_cast<int>(std::ceil(e.settle_s / tickSeconds())));
  return start;
}

}  // namespace norm2tex
