#pragma once
// Private to norm2tex_sim: how a grasped object collides, shared by GripperSim and HandSim.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <btBulletCollisionCommon.h>

#include <Eigen/Core>

#include "norm2tex/mesh/object_mesh.hpp"
#include "norm2tex/sim/gel_contact.hpp"
#include "norm2tex/sim/gripper_sim.hpp"

namespace norm2tex {

// Bullet's default 4 cm margins are larger than the gel's whole range: keep them far below the
// indentations we resolve (box margins sit inside the box, so boxes stay exact).
constexpr double kBoxMargin = 2e-4;
constexpr double kHullMargin = 2e-5;

/// The object's Bullet shapes and what the gels touch, about its body origin (its bounds'
/// centre).
struct ObjectCollisionShapes {
  /// The Bullet shape (for the floor, rigid links and the inertia) is back(); any shapes
  /// before it are its convex parts.
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  /// What the gels touch, in the body frame: convex parts, or one capsule (a sphere: a == b).
  std::vector<ConvexPolytope> contact_parts;
  std::optional<Capsule> contact_capsule;
  ObjectCollision collision;
};

/// Chooses the object's collision for `mode` (ObjectOptions::collision): an exact box, sphere
/// or capsule, the hull, or a decomposition when the hull bridges a hollow deeper than 0.15 mm
/// within `reach` of its extreme along +-`gel_axis` (the sides the gels face).
ObjectCollisionShapes makeObjectCollision(const ObjectMesh& object, const std::string& mode,
                                          const Eigen::Vector3d& centre, double reach,
                                          const Eigen::Vector3d& gel_axis);

/// Bullet's convex hull of `points` reduced by btShapeHull (cheap against the floor), with
/// kHullMargin.
std::unique_ptr<btCollisionShape> bulletHull(const std::vector<Eigen::Vector3d>& points);

}  // namespace norm2tex
