#pragma once

#include <vector>

#include <Eigen/Geometry>

namespace norm2tex {

/// A convex polytope: its vertices and its faces, each a loop of vertex indices.
struct ConvexPolytope {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::vector<int>> faces;
  /// Largest distance of a vertex from the origin: a bounding sphere for quick rejection.
  double radius = 0.0;
  /// Per vertex: the vertices it shares an edge with, and the faces it is a corner of (so a
  /// big hull is searched from its deepest vertex instead of face by face).
  std::vector<std::vector<int>> neighbours;
  std::vector<std::vector<int>> vertex_faces;

  /// The convex hull of `points` (coplanar faces merged into polygons). Throws Error for fewer
  /// than 4 points or points that span no volume.
  static ConvexPolytope hullOf(const std::vector<Eigen::Vector3d>& points);
};

/// A sphere swept along the segment a-b (a sphere when a == b), in the object's body frame.
struct Capsule {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

/// The gel pad in its own frame (the renderer's gel frame): the undeformed surface is z = 0,
/// the gel lies at z < 0, and the pad covers |x| <= half_width, |y| <= half_height.
struct GelPad {
  double half_width_m = 0.0;
  double half_height_m = 0.0;
};

/// A point of the object below the undeformed gel surface, in the gel frame: position.z() is
/// -depth.
struct GelContactPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double depth = 0.0;
};

/// The corners of the part of the object that reaches into the gel: the polytope (its vertices
/// mapped into the gel frame by `body_in_gel`) clipped to z < 0 and to the pad's rectangle.
/// Exact for any convex polytope: every vertex of that region deeper than zero is returned
/// (duplicates merged), so the deepest one is the object's indentation over the pad, the same
/// geometry the renderer rasterises. Empty when nothing reaches into the pad. Its cost grows
/// with the part of a big polytope below the surface, not with the polytope.
std::vector<GelContactPoint> gelContactPoints(const ConvexPolytope& polytope,
                                              const Eigen::Isometry3d& body_in_gel,
                                              const GelPad& pad);

/// The same for a capsule or sphere: the deepest points of its spine's clipped part (a
/// capsule lying along the gel gives its two ends, a sphere its one lowest point), each at
/// its exact depth over the pad.
std::vector<GelContactPoint> gelContactPoints(const Capsule& capsule,
                                              const Eigen::Isometry3d& body_in_gel,
                                              const GelPad& pad);

/// At most `max_points` (1 ... 4) of `points` that span the contact as widely as possible, each
/// spread weighted by the point's depth: the deepest, the farthest from it, the one making the
/// largest triangle with those two, and the largest on the other side of their line (what a
/// 4-point contact manifold keeps).
std::vector<GelContactPoint> spanningContactPoints(const std::vector<GelContactPoint>& points,
                                                   int max_points = 4);

/// How far the hull's surface lies from the mesh vertices it was made of, at most (0 for a
/// convex mesh). Without `axis`: each vertex's distance to the surface. With one: the depth of
/// the hollows a flat gel pressing along +-axis meets, at most `reach` deep, where the hull
/// bridges them: for each vertex within `reach` of the hull's extreme on that side, how far the
/// hull's surface lies beyond it along the axis.
double hullDeviation(const ConvexPolytope& hull, const std::vector<Eigen::Vector3d>& vertices,
                     const Eigen::Vector3d& axis = Eigen::Vector3d::Zero(),
                     double reach = 0.0);

}  // namespace norm2tex
