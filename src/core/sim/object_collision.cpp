#include "sim/object_collision.hpp"

#include <BulletCollision/CollisionShapes/btShapeHull.h>

#include "norm2tex/common/error.hpp"
#include "sim/convex_decomposition.hpp"

namespace norm2tex {
namespace {

// "auto" collision decomposes a mesh whose hull bridges a hollow deeper than this on a side
// facing the gels: the tolerance the physics keeps to the rendered indentation.
constexpr double kMaxHullDeviationM = 0.15e-3;

btVector3 toBt(const Eigen::Vector3d& v) { return btVector3(v.x(), v.y(), v.z()); }
Eigen::Vector3d toEigen(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

std::vector<Eigen::Vector3d> verticesAbout(const TexturedMesh& mesh,
                                           const Eigen::Vector3d& centre) {
  std::vector<Eigen::Vector3d> points;
  points.reserve(mesh.vertices().size());
  for (const Eigen::Vector3f& v : mesh.vertices()) points.push_back(v.cast<double>() - centre);
  return points;
}

std::unique_ptr<btCollisionShape> roundShape(const ObjectMesh& object) {
  const double r = object.radius_m, h = object.half_length_m;
  std::unique_ptr<btCollisionShape> shape;
  if (object.shape == ObjectMesh::Shape::kSphere) {
    shape = std::make_unique<btSphereShape>(r);
  } else if (object.shape == ObjectMesh::Shape::kCapsule) {
    if (object.axis == 0) shape = std::make_unique<btCapsuleShapeX>(r, 2 * h);
    if (object.axis == 1) shape = std::make_unique<btCapsuleShape>(r, 2 * h);
    if (object.axis == 2) shape = std::make_unique<btCapsuleShapeZ>(r, 2 * h);
  }
  return shape;
}

}  // namespace

std::unique_ptr<btCollisionShape> bulletHull(const std::vector<Eigen::Vector3d>& points) {
  btConvexHullShape full;
  for (const Eigen::Vector3d& p : points) full.addPoint(toBt(p), false);
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
  return hull;
}

ObjectCollisionShapes makeObjectCollision(const ObjectMesh& o, const std::string& mode,
                                          const Eigen::Vector3d& centre, double reach,
                                          const Eigen::Vector3d& gel_axis) {
  ObjectCollisionShapes out;
  if (mode == "box" || (mode == "auto" && o.shape == ObjectMesh::Shape::kBox)) {
    const Eigen::Vector3d half = o.mesh.bounds().sizes().cast<double>() / 2.0;
    auto box = std::make_unique<btBoxShape>(toBt(half));
    box->setMargin(std::min(kBoxMargin, 0.25 * half.minCoeff()));
    out.shapes.push_back(std::move(box));
    std::vector<Eigen::Vector3d> corners;
    for (int k = 0; k < 8; ++k) {
      corners.push_back(
          half.cwiseProduct(Eigen::Vector3d(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1)));
    }
    out.contact_parts.push_back(ConvexPolytope::hullOf(corners));
    out.collision.kind = "box";
    return out;
  }
  if (mode == "auto" &&
      (o.shape == ObjectMesh::Shape::kSphere || o.shape == ObjectMesh::Shape::kCapsule)) {
    out.shapes.push_back(roundShape(o));
    Capsule capsule;
    capsule.radius = o.radius_m;
    if (o.shape == ObjectMesh::Shape::kCapsule) {
      capsule.b[o.axis] = o.half_length_m;
      capsule.a[o.axis] = -o.half_length_m;
    }
    out.contact_capsule = capsule;
    out.collision.kind = shapeName(o.shape);
    return out;
  }
  const std::vector<Eigen::Vector3d> points = verticesAbout(o.mesh, centre);
  ConvexPolytope hull = ConvexPolytope::hullOf(points);
  // A flat gel meets a concave mesh where its hull does, to the same depth (the deepest point of
  // a body in a half-space is a hull vertex); only where the hull bridges a hollow within the
  // gel's reach (the law's deepest point) on the sides facing the gels does the contact's
  // footprint differ from the mesh's.
  if (mode == "auto") out.collision.hull_deviation_m = hullDeviation(hull, points, gel_axis, reach);
  if (mode == "decomposition" ||
      (mode == "auto" && out.collision.hull_deviation_m > kMaxHullDeviationM)) {
    out.shapes = decomposeConvex(o.mesh, centre, kHullMargin);
    for (size_t i = 0; i + 1 < out.shapes.size(); ++i) {
      const auto& part = static_cast<const btConvexHullShape&>(*out.shapes[i]);
      std::vector<Eigen::Vector3d> part_points;
      for (int k = 0; k < part.getNumPoints(); ++k) {
        part_points.push_back(toEigen(part.getUnscaledPoints()[k]));
      }
      try {
        out.contact_parts.push_back(ConvexPolytope::hullOf(part_points));
      } catch (const Error&) {
        // A flat sliver (HACD can return one): nothing a gel could press into.
      }
    }
    if (out.contact_parts.empty())
      throw Error("convex decomposition of the object mesh produced no solid part");
    out.collision.kind = "decomposition";
    out.collision.parts = static_cast<int>(out.contact_parts.size());
    return out;
  }
  out.shapes.push_back(bulletHull(points));
  out.contact_parts.push_back(std::move(hull));
  out.collision.kind = "hull";
  return out;
}

}  // namespace norm2tex
