#pragma once
// Private to norm2tex_sim: the compliant contact of DIGIT gel pads with the one object, the
// same for GripperSim's two facing gels and for every gel a HandSim mounts.

#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include <btBulletDynamicsCommon.h>

#include <Eigen/Geometry>

#include "norm2tex/sim/contact_resultant.hpp"
#include "norm2tex/sim/gel_contact.hpp"
#include "norm2tex/gel/gel_law.hpp"
#include "norm2tex/sim/gripper_sim.hpp"

namespace norm2tex {

/// What every pad shares.
struct GelPadOptions {
  double width_m = 0.0;
  double height_m = 0.0;
  double thickness_m = 0.0;
  double friction = 0.0;  ///< Coulomb coefficient object-gel
  double damping = 0.0;   ///< the gel's contact damping (PhysicsOptions::gel_damping)
  GelLaw law = GelLaw::taximDefault();
  /// Half the object's smallest extent: the radius the torsional friction of a lone contact
  /// point assumes (see updateStiffness).
  double object_min_half_size_m = 0.0;
  /// > 0: a convex part reaching further than this behind a gel's surface is on the sensor's
  /// other side and touches nothing (a hand's gel can have the object behind it; two facing
  /// gels never do). 0: off.
  double behind_gel_m = 0.0;
};

/// The options of a simulation's config (GripperSimConfig, HandSimConfig: gel pad, object
/// friction, physics, gel law) for an object of smallest extent 2 x `object_min_half_size_m`.
template <typename Config>
GelPadOptions gelPadOptionsOf(const Config& config, double object_min_half_size_m) {
  GelPadOptions pads;
  pads.width_m = config.gel_width_m;
  pads.height_m = config.gel_height_m;
  pads.thickness_m = config.gel_thickness_m;
  pads.friction = config.object.friction;
  pads.damping = config.physics.gel_damping;
  pads.law = config.gel_law;
  pads.object_min_half_size_m = object_min_half_size_m;
  return pads;
}

/// What the object touches the gels with, in its body frame: convex parts, or one capsule.
struct GelContactGeometry {
  const std::vector<ConvexPolytope>* parts = nullptr;
  const std::optional<Capsule>* capsule = nullptr;
};

/// Gel pads as kinematic Bullet boxes behind their surfaces whose contacts with the object the
/// package makes itself: where the object reaches into a pad (exact for a box, sphere, capsule
/// or convex hull: gelContactPoints), at most four points per convex part and pad, kept between
/// ticks as friction anchors in the package's own manifolds (a contact inside the Coulomb cone
/// keeps its anchor, so a held object does not creep); before every Bullet step each pad's
/// contact stiffness is GelLaw::force(d) / sum(d_i) over its points' penetrations d_i (d the
/// deepest, at most the gel's thickness), so at rest the object sinks into each gel exactly as
/// deep as the law says for the force it carries.
///
/// Per substep: place() every pad, updateContacts(), updateStiffness(), Bullet's step, then
/// measure(). Owned by the Bullet world's owner; destroy it before the object and the world.
class GelPadContacts {
 public:
  /// Adds `count` pads to `world` (collision group `group`, colliding with nothing through
  /// Bullet). Add them before the object, whose body attach() then takes.
  GelPadContacts(btDiscreteDynamicsWorld& world, btCollisionDispatcher& dispatcher, int count,
                 const GelPadOptions& options, int group);
  ~GelPadContacts();
  GelPadContacts(const GelPadContacts&) = delete;
  GelPadContacts& operator=(const GelPadContacts&) = delete;

  /// The object the pads touch: one manifold per pad and convex part. `geometry` must outlive
  /// this.
  void attach(btRigidBody& object, const GelContactGeometry& geometry);

  int count() const { return static_cast<int>(pads_.size()); }
  /// Moves pad `pad` so that its gel frame (the renderer's: +z out of the gel) is `gel_in_world`.
  void place(int pad, const Eigen::Isometry3d& gel_in_world);
  const Eigen::Isometry3d& gelInWorld(int pad) const { return pads_[pad].gel_in_world; }
  /// Where the object reaches into pad `pad` now, per convex part (empty parts: not at all).
  std::vector<std::vector<GelContactPoint>> objectPointsIn(int pad) const {
    return pointsOf(pads_[pad]);
  }
  /// Drops every contact point and anchor (call when the object is moved by hand).
  void clearContacts();

  /// The object's points inside each pad join its manifolds as Bullet adds its own.
  void updateContacts();
  /// Each pad's contact stiffness from the gel law, and a lone point's torsional friction.
  void updateStiffness();

  /// Per contact point of pad `pad` after a step of `dt`: where it lies on the gel (world), the
  /// normal force (N, pushing the gel back into itself) and the friction force on the gel
  /// (world, N).
  using PointForce = std::function<void(int pad, const Eigen::Vector3d& on_gel, double normal_n,
                                        const Eigen::Vector3d& friction_n)>;
  /// What each pad feels after a step of `dt` (penetration from the pose the step ended in:
  /// what the renderer draws), into `states` (one per pad); `visit` (optional) sees every
  /// contact point's force.
  void measure(double dt, const Eigen::Isometry3d& object_in_world,
               std::vector<GelContactState>& states, const PointForce& visit = nullptr);

 private:
  struct Pad {
    std::unique_ptr<btRigidBody> body;
    Eigen::Isometry3d gel_in_world = Eigen::Isometry3d::Identity();
    /// One manifold per convex part of the object (body 0 the gel, body 1 the object).
    std::vector<btPersistentManifold*> manifolds;
    /// Where the object reaches into the pad (per part) after the last step, and the pad's
    /// pose it was measured at.
    std::vector<std::vector<GelContactPoint>> points;
    bool points_valid = false;
    Eigen::Isometry3d points_gel_in_world = Eigen::Isometry3d::Identity();
  };

  std::vector<std::vector<GelContactPoint>> pointsOf(const Pad& pad) const;
  template <typename Visit>
  static void forEachPoint(const Pad& pad, Visit visit);

  btDiscreteDynamicsWorld& world_;
  btCollisionDispatcher& dispatcher_;
  GelPadOptions options_;
  std::unique_ptr<btCollisionShape> shape_;
  std::vector<Pad> pads_;
  btRigidBody* object_ = nullptr;
  GelContactGeometry geometry_;
  std::vector<PointLoad> loads_;  // measure()'s per-point loads of one pad, reused
};

}  // namespace norm2tex
