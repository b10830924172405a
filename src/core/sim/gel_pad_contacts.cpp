#include "sim/gel_pad_contacts.hpp"

#include <algorithm>
#include <cmath>

#include "sim/bullet_eigen.hpp"
#include "sim/object_collision.hpp"

namespace norm2tex {
namespace {

// A gel contact point that slides this far along the gel, or separates this far, is dropped
// (Bullet's contact breaking threshold for the package's own manifolds).
constexpr double kContactBreakingM = 3e-4;

}  // namespace

GelPadContacts::GelPadContacts(btDiscreteDynamicsWorld& world, btCollisionDispatcher& dispatcher,
                               int count, const GelPadOptions& options, int group)
    : world_(world), dispatcher_(dispatcher), options_(options) {
  // Kinematic boxes behind the gel surfaces, soft-contact, with the material's friction.
  auto box = std::make_unique<btBoxShape>(
      btVector3(options_.width_m / 2, options_.height_m / 2, options_.thickness_m / 2));
  box->setMargin(kBoxMargin);
  shape_ = std::move(box);
  pads_.resize(count);
  for (Pad& pad : pads_) {
    btRigidBody::btRigidBodyConstructionInfo info(0, nullptr, shape_.get());
    info.m_friction = options_.friction;
    info.m_restitution = 0;
    pad.body = std::make_unique<btRigidBody>(info);
    pad.body->setCollisionFlags(pad.body->getCollisionFlags() |
                                btCollisionObject::CF_KINEMATIC_OBJECT |
                                btCollisionObject::CF_HAS_FRICTION_ANCHOR);
    pad.body->setActivationState(DISABLE_DEACTIVATION);
    pad.body->setContactStiffnessAndDamping(options_.law.secantStiffness(0.0), options_.damping);
    world_.addRigidBody(pad.body.get(), group, 0);
  }
}

GelPadContacts::~GelPadContacts() {
  for (Pad& pad : pads_) {
    for (btPersistentManifold* manifold : pad.manifolds) dispatcher_.releaseManifold(manifold);
    world_.removeRigidBody(pad.body.get());
  }
}

void GelPadContacts::attach(btRigidBody& object, const GelContactGeometry& geometry) {
  object_ = &object;
  geometry_ = geometry;
  const size_t parts = geometry_.capsule->has_value() ? 1 : geometry_.parts->size();
  for (Pad& pad : pads_) {
    for (size_t k = 0; k < parts; ++k) {
      btPersistentManifold* manifold = dispatcher_.getNewManifold(pad.body.get(), object_);
      manifold->setContactBreakingThreshold(kContactBreakingM);
      pad.manifolds.push_back(manifold);
    }
  }
}

void GelPadContacts::place(int index, const Eigen::Isometry3d& gel_in_world) {
  Pad& pad = pads_[index];
  pad.gel_in_world = gel_in_world;
  // The box's centre sits half a thickness behind the gel surface (gel -z). Kinematic bodies:
  // Bullet derives their velocity from the change of this transform.
  const Eigen::Isometry3d box =
      gel_in_world * Eigen::Translation3d(0, 0, -options_.thickness_m / 2);
  pad.body->setWorldTransform(toBt(box));
  pad.body->setInterpolationWorldTransform(pad.body->getWorldTransform());
}

void GelPadContacts::clearContacts() {
  for (Pad& pad : pads_) {
    for (btPersistentManifold* manifold : pad.manifolds) manifold->clearManifold();
    pad.points_valid = false;
  }
}

template <typename Visit>
void GelPadContacts::forEachPoint(const Pad& pad, Visit visit) {
  for (btPersistentManifold* manifold : pad.manifolds) {
    for (int c = 0; c < manifold->getNumContacts(); ++c) visit(manifold->getContactPoint(c));
  }
}

std::vector<std::vector<GelContactPoint>> GelPadContacts::pointsOf(const Pad& pad) const {
  const GelPad extent{options_.width_m / 2, options_.height_m / 2};
  const Eigen::Isometry3d body_in_gel =
      pad.gel_in_world.inverse() * toEigen(object_->getWorldTransform());
  std::vector<std::vector<GelContactPoint>> points;
  if (geometry_.capsule->has_value()) {
    points.push_back(gelContactPoints(**geometry_.capsule, body_in_gel, extent));
  } else {
    for (const ConvexPolytope& part : *geometry_.parts) {
      points.push_back(gelContactPoints(part, body_in_gel, extent));
    }
  }
  if (options_.behind_gel_m > 0.0) {
    // A real press stops at the gel's thickness (too_deep): a part reaching far further is
    // behind the sensor, not in its gel.
    for (std::vector<GelContactPoint>& part : points) {
      for (const GelContactPoint& p : part) {
        if (p.depth > options_.behind_gel_m) {
          part.clear();
          break;
        }
      }
    }
  }
  return points;
}

void GelPadContacts::updateContacts() {
  // The object's points inside each gel pad, at most four per part, join the manifold as Bullet
  // adds its own: a new point near a kept one replaces it, unless the kept one is an anchor
  // inside its friction cone (btPersistentManifold::replaceContactPoint); kept points are
  // first moved with their bodies and dropped once they separate, slide or leave the pad.
  const btRigidBody& object = *object_;
  const double half_w = options_.width_m / 2, half_h = options_.height_m / 2;
  for (Pad& pad : pads_) {
    const btRigidBody& gel = *pad.body;
    const Eigen::Isometry3d& gel_in_world = pad.gel_in_world;
    const Eigen::Isometry3d world_in_gel = gel_in_world.inverse();
    const Eigen::Vector3d normal_on_object = -gel_in_world.linear().col(2);  // into the gel
    // The last step's measurement still holds unless the pad has moved since (the object has
    // not: nothing moves it between a step and the next tick's contacts).
    if (!pad.points_valid || gel_in_world.matrix() != pad.points_gel_in_world.matrix()) {
      pad.points = pointsOf(pad);
    }
    for (size_t k = 0; k < pad.points.size(); ++k) {
      btPersistentManifold& manifold = *pad.manifolds[k];
      manifold.refreshContactPoints(gel.getWorldTransform(), object.getWorldTransform());
      for (int c = manifold.getNumContacts() - 1; c >= 0; --c) {
        const Eigen::Vector3d on_object =
            world_in_gel * toEigen(manifold.getContactPoint(c).m_positionWorldOnB);
        // (Points the pad's edge clipped lie on it: a kept anchor there may move past it by
        // as much as it may slide, or every held object would lose its anchors there.)
        if (std::abs(on_object.x()) > half_w + kContactBreakingM ||
            std::abs(on_object.y()) > half_h + kContactBreakingM) {
          manifold.removeContactPoint(c);
        }
      }
      for (const GelContactPoint& p : spanningContactPoints(pad.points[k])) {
        const Eigen::Vector3d on_object = gel_in_world * p.position;
        const Eigen::Vector3d on_gel =
            gel_in_world * Eigen::Vector3d(p.position.x(), p.position.y(), 0.0);
        btManifoldPoint point(gel.getWorldTransform().invXform(toBt(on_gel)),
                              object.getWorldTransform().invXform(toBt(on_object)),
                              toBt(normal_on_object), static_cast<btScalar>(-p.depth));
        point.m_positionWorldOnA = toBt(on_gel);
        point.m_positionWorldOnB = toBt(on_object);
        point.m_combinedFriction = static_cast<btScalar>(options_.friction);
        point.m_combinedRestitution = 0;
        point.m_contactPointFlags |= BT_CONTACT_FLAG_FRICTION_ANCHOR;
        const int index = manifold.getCacheEntry(point);
        if (index >= 0) {
          manifold.replaceContactPoint(point, index);
        } else {
          manifold.addManifoldPoint(point);
        }
      }
    }
  }
}

void GelPadContacts::updateStiffness() {
  // Secant stiffness of the law at the current penetration, shared among the contact points
  // in proportion to their depth: sum_i k d_i = F(d_max).
  const double damping = options_.damping + object_->getContactDamping();
  for (Pad& pad : pads_) {
    double deepest = 0.0, sum = 0.0;
    int points = 0;
    forEachPoint(pad, [&](const btManifoldPoint& point) {
      ++points;
      const double d = -point.getDistance();
      if (d > 0.0) {
        deepest = std::max(deepest, d);
        sum += d;
      }
    });
    // Deeper than the gel is thick the object would press on the sensor's body: the force
    // stops growing there, so no mistake can expel the object at absurd speed.
    const double k = sum > 0.0 ? options_.law.force(std::min(deepest, options_.thickness_m)) / sum
                               : options_.law.secantStiffness(0.0);
    pad.body->setContactStiffnessAndDamping(k, options_.damping);
    // The gel touches over a patch, not a point: Coulomb friction over a disc of radius a
    // under Hertzian pressure resists twisting up to (3 pi / 16) mu F a. Several contact points
    // resist it through their lateral friction, but a single one has no such torque, so a ball
    // touching a gel at one hull vertex would spin freely about the gel's normal. A lone point
    // gets the patch's torsional friction, a = sqrt(2 R d) the footprint of a ball of the
    // object's smallest half-size R at its depth d. (Bullet applies torsional friction only
    // with rolling friction on: a negligible one, 1 nm.)
    const double patch_radius =
        points == 1 ? std::sqrt(2.0 * options_.object_min_half_size_m * deepest) : 0.0;
    const btScalar spinning =
        static_cast<btScalar>(3.0 * M_PI / 16.0 * options_.friction * patch_radius);
    // Points kept by a friction anchor are not re-created by collision detection: set them too.
    forEachPoint(pad, [&](btManifoldPoint& point) {
      point.m_combinedContactStiffness1 = k;
      point.m_combinedContactDamping1 = damping;
      point.m_contactPointFlags |= BT_CONTACT_FLAG_CONTACT_STIFFNESS_DAMPING;
      point.m_combinedSpinningFriction = spinning;
      point.m_combinedRollingFriction = spinning > 0 ? btScalar(1e-9) : btScalar(0);
    });
  }
}

void GelPadContacts::measure(double dt, const Eigen::Isometry3d& object_in_world,
                             std::vector<GelContactState>& states, const PointForce& visit) {
  const double deepest_law_point = options_.law.points().back().first;
  states.resize(pads_.size());
  for (size_t i = 0; i < pads_.size(); ++i) {
    Pad& pad = pads_[i];
    const Eigen::Isometry3d& gel_in_world = pad.gel_in_world;
    GelContactState& state = states[i];
    state = GelContactState{};
    state.object_in_gel = gel_in_world.inverse() * object_in_world;
    // The indentation at the pose the step ended in: what the renderer draws.
    pad.points = pointsOf(pad);
    pad.points_valid = true;
    pad.points_gel_in_world = gel_in_world;
    for (const std::vector<GelContactPoint>& part : pad.points) {
      for (const GelContactPoint& p : part)
        state.penetration_m = std::max(state.penetration_m, p.depth);
    }
    state.too_deep = state.penetration_m > deepest_law_point;
    Eigen::Vector3d shear_world = Eigen::Vector3d::Zero();
    const Eigen::Isometry3d world_in_gel = gel_in_world.inverse();
    loads_.clear();
    forEachPoint(pad, [&](const btManifoldPoint& point) {
      const double normal = point.getAppliedImpulse() / dt;
      // Friction impulses act on body A (the gel) along the lateral directions.
      const Eigen::Vector3d friction =
          (toEigen(point.m_lateralFrictionDir1) * point.m_appliedImpulseLateral1 +
           toEigen(point.m_lateralFrictionDir2) * point.m_appliedImpulseLateral2) /
          dt;
      state.normal_force_n += normal;
      shear_world += friction;
      const Eigen::Vector3d on_gel = toEigen(point.m_positionWorldOnA);
      PointLoad load;
      load.position_m = (world_in_gel * on_gel).head<2>();
      load.normal_n = normal;
      load.tangential_n = (world_in_gel.linear() * friction).head<2>();
      loads_.push_back(load);
      if (visit) visit(static_cast<int>(i), on_gel, normal, friction);
    });
    state.in_contact = state.penetration_m > 0.0 && state.normal_force_n > 0.0;
    state.shear_force_n = gel_in_world.linear().transpose() * shear_world;
    state.shear_force_n.z() = 0.0;
    // Where the contact's normal force acts and how hard it twists the gel about it.
    const ContactResultant resultant = contactResultant(loads_);
    state.pressure_centre_m = resultant.pressure_centre_m;
    state.twist_moment_nm = resultant.twist_moment_nm;
  }
}

}  // namespace norm2tex
