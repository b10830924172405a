#include "norm2tex/sim/gel_contact.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <LinearMath/btConvexHullComputer.h>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

// Points closer than this are one point (clipping a face shared by two faces' loops yields
// each corner twice).
constexpr double kMergeDistance = 1e-7;

// Newell's normal of a face loop (not normalised): robust for polygons with nearly collinear
// corners.
Eigen::Vector3d faceNormal(const ConvexPolytope& p, const std::vector<int>& face) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < face.size(); ++i) {
    const Eigen::Vector3d& a = p.vertices[face[i]];
    const Eigen::Vector3d& b = p.vertices[face[(i + 1) % face.size()]];
    n += Eigen::Vector3d((a.y() - b.y()) * (a.z() + b.z()), (a.z() - b.z()) * (a.x() + b.x()),
                         (a.x() - b.x()) * (a.y() + b.y()));
  }
  return n;
}

// Keeps the part of `polygon` where sign * p[axis] <= limit (Sutherland-Hodgman, one plane).
void clipPolygon(std::vector<Eigen::Vector3d>& polygon, std::vector<Eigen::Vector3d>& scratch,
                 int axis, double sign, double limit) {
  scratch.clear();
  const size_t n = polygon.size();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& a = polygon[i];
    const Eigen::Vector3d& b = polygon[(i + 1) % n];
    const double da = sign * a[axis] - limit, db = sign * b[axis] - limit;
    if (da <= 0) scratch.push_back(a);
    if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
      scratch.push_back(a + (b - a) * (da / (da - db)));
    }
  }
  polygon.swap(scratch);
}

// Adds p unless a point from `first` on is within kMergeDistance of it.
void addMerged(std::vector<GelContactPoint>& points, size_t first, const Eigen::Vector3d& p) {
  for (size_t i = first; i < points.size(); ++i) {
    if ((points[i].position - p).squaredNorm() <= kMergeDistance * kMergeDistance) return;
  }
  points.push_back({p, -p.z()});
}

void addMerged(std::vector<GelContactPoint>& points, const Eigen::Vector3d& p) {
  addMerged(points, 0, p);
}

double cross2(const Eigen::Vector3d& o, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

}  // namespace

ConvexPolytope ConvexPolytope::hullOf(const std::vector<Eigen::Vector3d>& points) {
  if (points.size() < 4) throw Error("a convex hull needs at least 4 points");
  std::vector<double> coords;
  coords.reserve(3 * points.size());
  for (const Eigen::Vector3d& p : points) coords.insert(coords.end(), {p.x(), p.y(), p.z()});
  btConvexHullComputer computer;
  computer.compute(coords.data(), 3 * sizeof(double), static_cast<int>(points.size()), 0, 0);
  if (computer.faces.size() < 4) throw Error("the points span no volume: they have no convex hull");
  ConvexPolytope hull;
  for (int i = 0; i < computer.vertices.size(); ++i) {
    const btVector3& v = computer.vertices[i];
    hull.vertices.emplace_back(v.x(), v.y(), v.z());
    hull.radius = std::max(hull.radius, hull.vertices.back().norm());
  }
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& v : hull.vertices) centroid += v;
  centroid /= static_cast<double>(hull.vertices.size());
  for (int f = 0; f < computer.faces.size(); ++f) {
    const btConvexHullComputer::Edge* first = &computer.edges[computer.faces[f]];
    const btConvexHullComputer::Edge* edge = first;
    std::vector<int> face;
    do {
      face.push_back(edge->getSourceVertex());
      edge = edge->getNextEdgeOfFace();
    } while (edge != first);
    // Loops run counter-clockwise seen from outside; checked, since clipping does not care
    // but hullDeviation's normals do.
    if (faceNormal(hull, face).dot(hull.vertices[face[0]] - centroid) < 0) {
      std::reverse(face.begin(), face.end());
    }
    hull.faces.push_back(std::move(face));
  }
  hull.neighbours.resize(hull.vertices.size());
  hull.vertex_faces.resize(hull.vertices.size());
  for (size_t f = 0; f < hull.faces.size(); ++f) {
    const std::vector<int>& face = hull.faces[f];
    for (size_t i = 0; i < face.size(); ++i) {
      hull.vertex_faces[face[i]].push_back(static_cast<int>(f));
      // Each edge is in two faces' loops, once each way: record it from one side only.
      hull.neighbours[face[i]].push_back(face[(i + 1) % face.size()]);
    }
  }
  for (size_t v = 0; v < hull.vertices.size(); ++v) {
    for (int n : hull.neighbours[v]) {
      std::vector<int>& back = hull.neighbours[n];
      if (std::find(back.begin(), back.end(), static_cast<int>(v)) == back.end()) {
        back.push_back(static_cast<int>(v));
      }
    }
  }
  return hull;
}

std::vector<GelContactPoint> gelContactPoints(const ConvexPolytope& polytope,
                                              const Eigen::Isometry3d& body_in_gel,
                                              const GelPad& pad) {
  std::vector<GelContactPoint> points;
  const Eigen::Vector3d origin = body_in_gel.translation();
  if (origin.z() - polytope.radius >= 0.0 ||
      std::abs(origin.x()) - polytope.radius > pad.half_width_m ||
      std::abs(origin.y()) - polytope.radius > pad.half_height_m) {
    return points;
  }
  // Vertices mapped into the gel frame on demand; faces to clip: every face of a small
  // polytope, else those around the vertices below the surface. Those are connected (on a
  // convex polytope the vertices below any plane are), and their deepest is found by walking
  // downhill from any vertex, so a 10k-vertex hull pressed 1 mm visits a few hundred.
  const size_t count = polytope.vertices.size();
  thread_local std::vector<Eigen::Vector3d> in_gel;
  thread_local std::vector<std::uint32_t> mapped, visited_face;
  thread_local std::uint32_t generation = 0;
  if (mapped.size() < count) mapped.assign(count, 0), in_gel.resize(count);
  if (visited_face.size() < polytope.faces.size()) visited_face.assign(polytope.faces.size(), 0);
  if (++generation == 0) {  // wrapped: forget every stamp
    std::fill(mapped.begin(), mapped.end(), 0);
    std::fill(visited_face.begin(), visited_face.end(), 0);
    generation = 1;
  }
  const auto vertex = [&](int i) -> const Eigen::Vector3d& {
    if (mapped[i] != generation) {
      in_gel[i] = body_in_gel * polytope.vertices[i];
      mapped[i] = generation;
    }
    return in_gel[i];
  };
  thread_local std::vector<int> faces, below;  // below: the vertices under the surface
  faces.clear();
  below.clear();
  constexpr size_t kSmall = 64;
  if (count <= kSmall || polytope.neighbours.size() != count) {
    for (size_t f = 0; f < polytope.faces.size(); ++f) faces.push_back(static_cast<int>(f));
    for (size_t v = 0; v < count; ++v) {
      if (vertex(static_cast<int>(v)).z() < 0.0) below.push_back(static_cast<int>(v));
    }
  } else {
    int lowest = 0;
    for (bool moved = true; moved;) {
      moved = false;
      for (int n : polytope.neighbours[lowest]) {
        if (vertex(n).z() < vertex(lowest).z()) lowest = n, moved = true;
      }
    }
    if (vertex(lowest).z() >= 0.0) return points;
    thread_local std::vector<int> queue;
    thread_local std::vector<std::uint32_t> queued;
    if (queued.size() < count) queued.assign(count, 0);
    if (generation == 1) std::fill(queued.begin(), queued.end(), 0);
    queue.assign(1, lowest);
    queued[lowest] = generation;
    for (size_t q = 0; q < queue.size(); ++q) {
      const int v = queue[q];
      below.push_back(v);
      for (int f : polytope.vertex_faces[v]) {
        if (visited_face[f] != generation) visited_face[f] = generation, faces.push_back(f);
      }
      for (int n : polytope.neighbours[v]) {
        if (queued[n] != generation && vertex(n).z() < 0.0) {
          queued[n] = generation;
          queue.push_back(n);
        }
      }
    }
  }
  // The region's corners: the polytope's own vertices under the surface over the pad, once
  // each, and where faces crossing the pad's rim are cut by it (clipping faces that lie inside
  // the rim would only give their own corners again, and the surface's crossings are 0 deep).
  const auto overPad = [&](const Eigen::Vector3d& p) {
    return std::abs(p.x()) <= pad.half_width_m && std::abs(p.y()) <= pad.half_height_m;
  };
  for (int v : below) {
    if (overPad(vertex(v))) points.push_back({vertex(v), -vertex(v).z()});
  }
  const size_t own_corners = points.size();
  thread_local std::vector<Eigen::Vector3d> polygon, scratch;
  for (int f : faces) {
    const std::vector<int>& face = polytope.faces[f];
    double min_z = std::numeric_limits<double>::infinity();
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(min_z), hi = -lo;
    for (int i : face) {
      const Eigen::Vector3d& p = vertex(i);
      min_z = std::min(min_z, p.z());
      lo = lo.cwiseMin(p.head<2>());
      hi = hi.cwiseMax(p.head<2>());
    }
    const bool inside_rim = lo.x() >= -pad.half_width_m && hi.x() <= pad.half_width_m &&
                            lo.y() >= -pad.half_height_m && hi.y() <= pad.half_height_m;
    if (min_z >= 0.0 || inside_rim || lo.x() > pad.half_width_m || hi.x() < -pad.half_width_m ||
        lo.y() > pad.half_height_m || hi.y() < -pad.half_height_m) {
      continue;
    }
    polygon.clear();
    for (int i : face) polygon.push_back(vertex(i));
    clipPolygon(polygon, scratch, 2, 1.0, 0.0);
    clipPolygon(polygon, scratch, 0, 1.0, pad.half_width_m);
    clipPolygon(polygon, scratch, 0, -1.0, pad.half_width_m);
    clipPolygon(polygon, scratch, 1, 1.0, pad.half_height_m);
    clipPolygon(polygon, scratch, 1, -1.0, pad.half_height_m);
    for (const Eigen::Vector3d& p : polygon) {
      if (!(p.z() < 0.0)) continue;
      const bool own = std::any_of(face.begin(), face.end(),
                                   [&](int i) { return vertex(i) == p; });
      if (!own) addMerged(points, own_corners, p);
    }
  }
  return points;
}

std::vector<GelContactPoint> gelContactPoints(const Capsule& capsule,
                                              const Eigen::Isometry3d& body_in_gel,
                                              const GelPad& pad) {
  std::vector<GelContactPoint> points;
  const Eigen::Vector3d a = body_in_gel * capsule.a, b = body_in_gel * capsule.b;
  const double r = capsule.radius;
  if (std::min(a.z(), b.z()) - r >= 0.0) return points;
  // The spine's part over the pad (Liang-Barsky): there the lowest point of the capsule lies
  // straight below the spine, r under it; the spine is straight, so its ends are the deepest.
  double t0 = 0.0, t1 = 1.0;
  const Eigen::Vector3d d = b - a;
  const double limits[2] = {pad.half_width_m, pad.half_height_m};
  for (int axis = 0; axis < 2 && t0 <= t1; ++axis) {
    for (double sign : {1.0, -1.0}) {
      // sign * (a + t d)[axis] <= limit
      const double q = sign * d[axis], s = limits[axis] - sign * a[axis];
      if (q == 0.0) {
        if (s < 0.0) t0 = 2.0, t1 = -1.0;
      } else if (q > 0.0) {
        t1 = std::min(t1, s / q);
      } else {
        t0 = std::max(t0, s / q);
      }
    }
  }
  if (t0 <= t1) {
    for (double t : {t0, t1}) {
      const Eigen::Vector3d spine = a + t * d;
      if (spine.z() - r < 0.0) addMerged(points, spine - Eigen::Vector3d(0, 0, r));
    }
    return points;
  }
  // The spine passes outside the pad: the capsule can still reach over the pad's edge. Its
  // deepest point over the pad lies on the pad's rim, nearest the spine.
  double best = std::numeric_limits<double>::infinity();
  Eigen::Vector3d best_point = Eigen::Vector3d::Zero();
  constexpr int kSamples = 64;  // along the spine: the rim point nearest each, keep the deepest
  for (int i = 0; i <= kSamples; ++i) {
    const Eigen::Vector3d spine = a + d * (static_cast<double>(i) / kSamples);
    const Eigen::Vector2d rim(std::clamp(spine.x(), -pad.half_width_m, pad.half_width_m),
                              std::clamp(spine.y(), -pad.half_height_m, pad.half_height_m));
    const double rho2 = (rim - spine.head<2>()).squaredNorm();
    if (rho2 >= r * r) continue;
    const double z = spine.z() - std::sqrt(r * r - rho2);
    if (z < best) {
      best = z;
      best_point = Eigen::Vector3d(rim.x(), rim.y(), z);
    }
  }
  if (best < 0.0) addMerged(points, best_point);
  return points;
}

std::vector<GelContactPoint> spanningContactPoints(const std::vector<GelContactPoint>& points,
                                                   int max_points) {
  if (static_cast<int>(points.size()) <= max_points) return points;
  std::vector<GelContactPoint> kept;
  const auto take = [&](auto score) {
    int best = -1;
    double best_score = 0.0;
    for (size_t i = 0; i < points.size(); ++i) {
      const double s = score(points[i]);
      if (s > best_score) best = static_cast<int>(i), best_score = s;
    }
    if (best >= 0) kept.push_back(points[best]);
    return best >= 0;
  };
  // Spread weighted by depth: a long, thin contact (a cylinder's side) keeps both ends of its
  // deep line before any of the barely touching points beside it.
  take([](const GelContactPoint& p) { return p.depth; });
  if (kept.size() == static_cast<size_t>(max_points)) return kept;
  const Eigen::Vector3d p0 = kept[0].position;
  if (!take([&](const GelContactPoint& p) {
        return p.depth * (p.position - p0).head<2>().norm();
      }) ||
      kept.size() == static_cast<size_t>(max_points)) {
    return kept;
  }
  const Eigen::Vector3d p1 = kept[1].position;
  if (!take([&](const GelContactPoint& p) {
        return p.depth * std::abs(cross2(p0, p1, p.position));
      }) ||
      kept.size() == static_cast<size_t>(max_points)) {
    return kept;
  }
  const double side = cross2(p0, p1, kept[2].position) > 0 ? 1.0 : -1.0;
  take([&](const GelContactPoint& p) { return -side * p.depth * cross2(p0, p1, p.position); });
  return kept;
}

double hullDeviation(const ConvexPolytope& hull, const std::vector<Eigen::Vector3d>& vertices,
                     const Eigen::Vector3d& axis, double reach) {
  std::vector<Eigen::Vector3d> normals;
  std::vector<double> offsets;
  for (const std::vector<int>& face : hull.faces) {
    normals.push_back(faceNormal(hull, face).normalized());
    offsets.push_back(normals.back().dot(hull.vertices[face[0]]));
  }
  const bool along_axis = axis.squaredNorm() > 0;
  const Eigen::Vector3d u = along_axis ? axis.normalized() : Eigen::Vector3d::Zero();
  double high = -std::numeric_limits<double>::infinity(), low = -high;
  for (const Eigen::Vector3d& v : hull.vertices) {
    high = std::max(high, v.dot(u));
    low = std::min(low, v.dot(u));
  }
  double deviation = 0.0;
  for (const Eigen::Vector3d& v : vertices) {
    double gap = std::numeric_limits<double>::infinity();
    if (!along_axis) {
      // Distance to the surface: to the nearest face plane (the point is inside every one).
      for (size_t f = 0; f < normals.size(); ++f) gap = std::min(gap, offsets[f] - normals[f].dot(v));
    } else {
      // How far the hull's surface lies beyond the vertex, seen by a gel pressing along the
      // axis onto the side the vertex is near: a ray from it leaves the hull there.
      const double sign = v.dot(u) >= high - reach ? 1.0 : v.dot(u) <= low + reach ? -1.0 : 0.0;
      if (sign == 0.0) continue;
      for (size_t f = 0; f < normals.size(); ++f) {
        const double along = sign * normals[f].dot(u);
        if (along > 1e-12) gap = std::min(gap, (offsets[f] - normals[f].dot(v)) / along);
      }
    }
    deviation = std::max(deviation, gap);
  }
  return deviation;
}

}  // namespace norm2tex
