// unwrapUvs: chart grouping by normal direction, orthographic projection, overlap splitting
// and skyline packing at one common scale. See uv_unwrap.hpp for the contract.
#include "norm2tex/mesh/uv_unwrap.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>
#include <sstream>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

#include "common/error_messages.hpp"
#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;

constexpr double kPi = 3.14159265358979323846;
// Faces may be given any direction within this angle (1/cos(40 deg) = 1.31 stretch at worst)
// when that shortens the borders between charts: noisy normals (scans) would otherwise cut the
// surface into thousands of single-triangle charts.
constexpr double kMaxAngleDeg = 40.0;
// Weight of border length against foreshortening, times the RMS face size: a unit takes its
// neighbours' direction when the border it removes, times this weight, outweighs its
// foreshortening cost area * (cos t_own - cos t_new). 0.1 turns most single-face fragments of
// a noisy surface (vertex noise ~5 % of the edge length) into parts of their neighbours' charts.
constexpr double kSmoothness = 0.1;
// Only borders across edges with a dihedral angle below this cost anything in the smoothing.
constexpr double kSmoothEdgeDeg = 25.0;
// Edge-connected faces within this angle of a unit's first face form one planar unit, labelled
// as a whole: the smoothing never cuts a planar face into two charts.
constexpr double kPlanarAngleDeg = 0.1;
// Fragments (charts of a few faces that fit no neighbour's direction within kMaxAngleDeg: noise,
// jagged borders) join the neighbour they share the longest border with when every face stays
// within this angle of its direction: 1/cos(60 deg) = 2 stretch at worst, on a few faces, instead
// of one more seam and one more padded box.
constexpr double kMergeAngleDeg = 60.0;
// A fragment is < 1 % of the chart it joins and < 0.5 % of the mesh: small facets next to
// facets of their own size (a gear's teeth) stay charts of their own, undistorted.
constexpr double kFragmentOfNeighbour = 0.01;
constexpr double kFragmentOfMesh = 0.005;
// Texels kept in addition to the padding against float rounding of UVs (a chart edge exactly on
// a texel centre would otherwise claim that texel or not by luck).
constexpr double kMarginTexels = 0.01;
// A face whose |cross product| is below this times its longest edge squared has no usable
// normal (all three corners on a line, up to double rounding of exact float inputs).
constexpr double kDegenerateSine = 1e-10;
// Non-manifold edges shared by more faces than this are linked as a chain, not all pairs.
constexpr int kMaxEdgeFan = 8;
// Largest hull that gets every edge direction tried for its minimum-area rectangle.
constexpr int kMaxHullDirections = 256;

// The 26 directions of a cube's faces, edges and corners: every unit normal is within
// 27.6 deg of one of them (the spherical Voronoi cells' covering radius).
std::array<Vec3, 26> chartDirections() {
  std::array<Vec3, 26> result;
  int n = 0;
  for (int x = -1; x <= 1; ++x) {
    for (int y = -1; y <= 1; ++y) {
      for (int z = -1; z <= 1; ++z) {
        if (x != 0 || y != 0 || z != 0) result[n++] = Vec3(x, y, z).normalized();
      }
    }
  }
  return result;
}

struct Face {
  std::array<int, 3> v;        // welded vertex ids
  Vec3 normal = Vec3::Zero();  // unit, or zero when degenerate
  double area = 0.0;
  int cls = -1;  // index into chartDirections()
};

// Compressed adjacency: the faces sharing an edge with face f are
// neighbour[offset[f] .. offset[f + 1]), with the shared edge's 3-D length.
struct Adjacency {
  std::vector<int> offset;
  std::vector<int> neighbour;
  std::vector<double> length;
};

struct PositionKey {
  uint32_t x, y, z;
  bool operator==(const PositionKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct PositionKeyHash {
  size_t operator()(const PositionKey& k) const {
    uint64_t h = k.x * 0x9E3779B97F4A7C15ull;
    h ^= (k.y + 0x7F4A7C15ull + (h << 6) + (h >> 2)) * 0xBF58476D1CE4E5B9ull;
    h ^= (k.z + 0x94D049BBull + (h << 6) + (h >> 2)) * 0x94D049BB133111EBull;
    return static_cast<size_t>(h ^ (h >> 31));
  }
};

uint32_t floatBits(float f) {
  f += 0.0f;  // -0 -> +0: the same position
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  return bits;
}

// Joins vertices with identical positions: seams duplicated for the old UVs (the UV sphere's
// column, a box's corners) must not split charts. Returns the welded id of every vertex and,
// per welded id, one original vertex.
std::vector<int> weldVertices(const std::vector<Eigen::Vector3f>& vertices,
                              std::vector<int>& representative) {
  std::unordered_map<PositionKey, int, PositionKeyHash> ids;
  ids.reserve(vertices.size());
  std::vector<int> welded(vertices.size());
  representative.clear();
  for (size_t i = 0; i < vertices.size(); ++i) {
    const Eigen::Vector3f& p = vertices[i];
    const auto inserted =
        ids.emplace(PositionKey{floatBits(p.x()), floatBits(p.y()), floatBits(p.z())},
                    static_cast<int>(representative.size()));
    if (inserted.second) representative.push_back(static_cast<int>(i));
    welded[i] = inserted.first->second;
  }
  return welded;
}

Adjacency buildAdjacency(const std::vector<Face>& faces, const std::vector<Vec3>& positions) {
  std::vector<std::pair<uint64_t, int>> edges;
  edges.reserve(3 * faces.size());
  for (size_t f = 0; f < faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = faces[f].v[k], b = faces[f].v[(k + 1) % 3];
      if (a == b) continue;
      const uint64_t key = (static_cast<uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
      edges.emplace_back(key, static_cast<int>(f));
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<std::array<int, 2>> pairs;
  std::vector<double> pair_length;
  for (size_t i = 0; i < edges.size();) {
    size_t j = i + 1;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    const int a = static_cast<int>(edges[i].first >> 32);
    const int b = static_cast<int>(edges[i].first & 0xFFFFFFFFu);
    const double length = (positions[a] - positions[b]).norm();
    const size_t fan = j - i;
    for (size_t p = i; p < j; ++p) {
      // All pairs for ordinary edges; a chain for large non-manifold fans (still connected).
      const size_t last = fan <= static_cast<size_t>(kMaxEdgeFan) ? j : std::min(j, p + 2);
      for (size_t q = p + 1; q < last; ++q) {
        if (edges[p].second == edges[q].second) continue;  // a face folded onto itself
        pairs.push_back({edges[p].second, edges[q].second});
        pair_length.push_back(length);
      }
    }
    i = j;
  }
  Adjacency adjacency;
  adjacency.offset.assign(faces.size() + 1, 0);
  for (const auto& p : pairs) {
    ++adjacency.offset[p[0] + 1];
    ++adjacency.offset[p[1] + 1];
  }
  std::partial_sum(adjacency.offset.begin(), adjacency.offset.end(), adjacency.offset.begin());
  adjacency.neighbour.resize(2 * pairs.size());
  adjacency.length.resize(2 * pairs.size());
  std::vector<int> fill(adjacency.offset.begin(), adjacency.offset.end() - 1);
  for (size_t i = 0; i < pairs.size(); ++i) {
    for (int s = 0; s < 2; ++s) {
      const int slot = fill[pairs[i][s]]++;
      adjacency.neighbour[slot] = pairs[i][1 - s];
      adjacency.length[slot] = pair_length[i];
    }
  }
  return adjacency;
}

// The orthonormal basis (e1, e2) with e1 x e2 = d: a surface seen from the side
// its normal points to keeps u to the right and v up (no mirroring).
void projectionBasis(const Vec3& d, Vec3& e1, Vec3& e2) {
  const Vec3 a = std::abs(d.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  e1 = (a - a.dot(d) * d).normalized();
  e2 = d.cross(e1);
}

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// True when the interiors of two 2-D triangles overlap by more than eps (separating axis test
// over the six edge normals; touching along an edge or at a corner is no overlap).
bool interiorsOverlap(const std::array<Vec2, 3>& a, const std::array<Vec2, 3>& b, double eps) {
  for (const std::array<Vec2, 3>* t : {&a, &b}) {
    for (int k = 0; k < 3; ++k) {
      const Vec2 edge = (*t)[(k + 1) % 3] - (*t)[k];
      const double length = edge.norm();
      if (!(length > 0.0)) continue;
      const Vec2 axis(-edge.y() / length, edge.x() / length);
      double min_a = std::numeric_limits<double>::infinity(), max_a = -min_a;
      double min_b = min_a, max_b = -min_a;
      for (int i = 0; i < 3; ++i) {
        const double pa = axis.dot(a[i]), pb = axis.dot(b[i]);
        min_a = std::min(min_a, pa);
        max_a = std::max(max_a, pa);
        min_b = std::min(min_b, pb);
        max_b = std::max(max_b, pb);
      }
      if (max_a <= min_b + eps || max_b <= min_a + eps) return false;
    }
  }
  return true;
}

// Uniform grid of accepted 2-D triangles for the overlap test; linked lists in flat arrays.
class TriangleGrid {
 public:
  TriangleGrid(const Vec2& min, const Vec2& max, size_t triangle_count) : min_(min) {
    const Vec2 extent = (max - min).cwiseMax(1e-300);
    // About one triangle per cell for a chart that fills its bounding box.
    double cell = std::sqrt(extent.x() * extent.y() / std::max<size_t>(triangle_count, 1));
    cell = std::max({cell, extent.x() / 2048.0, extent.y() / 2048.0});
    if (!(cell > 0.0)) cell = 1.0;
    inverse_cell_ = 1.0 / cell;
    nx_ = std::clamp(static_cast<int>(extent.x() * inverse_cell_) + 1, 1, 2048);
    ny_ = std::clamp(static_cast<int>(extent.y() * inverse_cell_) + 1, 1, 2048);
    head_.assign(static_cast<size_t>(nx_) * ny_, -1);
  }

  void clear() {
    for (int cell : touched_) head_[cell] = -1;
    touched_.clear();
    next_.clear();
    item_.clear();
  }

  template <typename Visit>
  bool anyInBox(const Vec2& lo, const Vec2& hi, Visit visit) const {
    int x0, y0, x1, y1;
    cells(lo, hi, x0, y0, x1, y1);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        for (int e = head_[static_cast<size_t>(y) * nx_ + x]; e >= 0; e = next_[e]) {
          if (visit(item_[e])) return true;
        }
      }
    }
    return false;
  }

  void insert(const Vec2& lo, const Vec2& hi, int item) {
    int x0, y0, x1, y1;
    cells(lo, hi, x0, y0, x1, y1);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const int cell = y * nx_ + x;
        if (head_[cell] < 0) touched_.push_back(cell);
        next_.push_back(head_[cell]);
        item_.push_back(item);
        head_[cell] = static_cast<int>(item_.size()) - 1;
      }
    }
  }

 private:
  void cells(const Vec2& lo, const Vec2& hi, int& x0, int& y0, int& x1, int& y1) const {
    auto index = [&](double value, double origin, int count) {
      return std::clamp(static_cast<int>(std::floor((value - origin) * inverse_cell_)), 0,
                        count - 1);
    };
    x0 = index(lo.x(), min_.x(), nx_);
    x1 = index(hi.x(), min_.x(), nx_);
    y0 = index(lo.y(), min_.y(), ny_);
    y1 = index(hi.y(), min_.y(), ny_);
  }

  Vec2 min_;
  double inverse_cell_ = 1.0;
  int nx_ = 1, ny_ = 1;
  std::vector<int> head_, next_, item_, touched_;
};

// A chart ready for packing: its faces, its welded vertices and their coordinates in metres in
// [0, size.x] x [0, size.y] (u right, v up).
struct Piece {
  std::vector<int> faces;
  std::vector<int> vertices;
  std::vector<Vec2> local;
  Vec2 size = Vec2::Zero();
};

// Convex hull (Andrew's monotone chain), counter-clockwise, no repeated end point.
std::vector<Vec2> convexHull(std::vector<Vec2> points) {
  std::sort(points.begin(), points.end(), [](const Vec2& a, const Vec2& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  points.erase(std::unique(points.begin(), points.end()), points.end());
  if (points.size() < 3) return points;
  std::vector<Vec2> hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross2(hull[k - 1] - hull[k - 2], points[i] - hull[k - 2]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross2(hull[k - 1] - hull[k - 2], points[i] - hull[k - 2]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

// Turns the piece so its minimum-area bounding rectangle is axis-aligned (the optimum has a
// side on a hull edge), then moves it to the origin.
void alignPiece(Piece& piece) {
  const std::vector<Vec2> hull = convexHull(piece.local);
  Vec2 best_axis = Vec2::UnitX();
  double best_area = std::numeric_limits<double>::infinity();
  const size_t n = hull.size();
  const size_t step = std::max<size_t>(1, n / kMaxHullDirections);
  for (size_t i = 0; n >= 3 && i < n; i += step) {
    const Vec2 edge = hull[(i + 1) % n] - hull[i];
    const double length = edge.norm();
    if (!(length > 0.0)) continue;
    const Vec2 axis = edge / length;
    double min_a = std::numeric_limits<double>::infinity(), max_a = -min_a;
    double min_b = min_a, max_b = -min_a;
    for (const Vec2& p : hull) {
      const double a = axis.dot(p), b = cross2(axis, p);
      min_a = std::min(min_a, a);
      max_a = std::max(max_a, a);
      min_b = std::min(min_b, b);
      max_b = std::max(max_b, b);
    }
    const double area = (max_a - min_a) * (max_b - min_b);
    // Ties keep the earlier direction: exact 0 / 90 deg turns stay exact.
    if (area < best_area * (1.0 - 1e-9)) {
      best_area = area;
      best_axis = axis;
    }
  }
  // Rotation by -angle(best_axis): (a, b) = (axis . p, axis x p); a rotation, no mirroring.
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity());
  Vec2 hi = -lo;
  for (Vec2& p : piece.local) {
    p = Vec2(best_axis.dot(p), cross2(best_axis, p));
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  for (Vec2& p : piece.local) p -= lo;
  piece.size = (hi - lo).cwiseMax(0.0);
}

struct Placement {
  double x = 0, y = 0;  // top-left corner of the box in texels, image coordinates (row down)
  bool rotated = false;
};

// Skyline bottom-left packing of boxes (already including their trailing gap) into
// width x height, in the given order, each tried in both orientations. False when one does not
// fit.
bool packSkyline(const std::vector<Vec2>& boxes, const std::vector<int>& order, double width,
                 double height, std::vector<Placement>& placements) {
  struct Segment {
    double x, y, width;
  };
  std::vector<Segment> skyline{{0.0, 0.0, width}};
  placements.assign(boxes.size(), Placement());
  const double tolerance = 1e-9 * std::max(width, height);
  for (int index : order) {
    double best_top = std::numeric_limits<double>::infinity(), best_x = 0, best_y = 0;
    size_t best_segment = 0;
    bool best_rotated = false;
    for (int turn = 0; turn < 2; ++turn) {
      const double w = turn ? boxes[index].y() : boxes[index].x();
      const double h = turn ? boxes[index].x() : boxes[index].y();
      if (turn == 1 && boxes[index].x() == boxes[index].y()) break;
      for (size_t s = 0; s < skyline.size(); ++s) {
        const double x = skyline[s].x;
        if (x + w > width + tolerance) break;
        double y = 0.0, covered = 0.0;
        for (size_t t = s; t < skyline.size() && covered < w - tolerance; ++t) {
          y = std::max(y, skyline[t].y);
          covered = skyline[t].x + skyline[t].width - x;
        }
        if (y + h > height + tolerance) continue;
        if (y + h < best_top || (y + h == best_top && x < best_x)) {
          best_top = y + h;
          best_x = x;
          best_y = y;
          best_segment = s;
          best_rotated = turn == 1;
        }
      }
    }
    if (!std::isfinite(best_top)) return false;
    placements[index] = Placement{best_x, best_y, best_rotated};
    const double w = best_rotated ? boxes[index].y() : boxes[index].x();
    // New segment on top of the box; the segments it covers shrink or go.
    const Segment added{best_x, best_top, w};
    const double end = best_x + w;
    size_t s = best_segment;
    while (s < skyline.size() && skyline[s].x + skyline[s].width <= end) {
      skyline.erase(skyline.begin() + s);
    }
    if (s < skyline.size() && skyline[s].x < end) {
      skyline[s].width -= end - skyline[s].x;
      skyline[s].x = end;
    }
    skyline.insert(skyline.begin() + s, added);
    // Merge neighbours of equal height so later boxes see one wide segment.
    for (size_t t = 0; t + 1 < skyline.size();) {
      if (skyline[t].y == skyline[t + 1].y) {
        skyline[t].width += skyline[t + 1].width;
        skyline.erase(skyline.begin() + t + 1);
      } else {
        ++t;
      }
    }
  }
  return true;
}

// Coplanar, edge-connected faces: the units the labelling moves as a whole.
struct PlanarUnits {
  std::vector<int> unit_of;  // per face
  std::vector<int> offset;   // faces of unit u: faces[offset[u] .. offset[u + 1])
  std::vector<int> faces;
  std::vector<double> area;      // per unit
  std::vector<Vec3> normal_sum;  // per unit: sum of area * normal
};

PlanarUnits findPlanarUnits(const std::vector<Face>& faces, const Adjacency& adjacency) {
  const double cos_planar = std::cos(kPlanarAngleDeg * kPi / 180.0);
  const int face_count = static_cast<int>(faces.size());
  PlanarUnits units;
  units.unit_of.assign(face_count, -1);
  units.offset.push_back(0);
  for (int seed = 0; seed < face_count; ++seed) {
    if (units.unit_of[seed] >= 0) continue;
    const int id = static_cast<int>(units.area.size());
    const size_t first = units.faces.size();
    units.unit_of[seed] = id;
    units.faces.push_back(seed);
    double area = 0.0;
    Vec3 normal_sum = Vec3::Zero();
    for (size_t q = first; q < units.faces.size(); ++q) {
      const int f = units.faces[q];
      area += faces[f].area;
      normal_sum += faces[f].area * faces[f].normal;
      if (faces[seed].area <= 0.0) break;  // a degenerate face is a unit of its own
      for (int e = adjacency.offset[f]; e < adjacency.offset[f + 1]; ++e) {
        const int g = adjacency.neighbour[e];
        if (units.unit_of[g] < 0 && faces[g].area > 0.0 &&
            faces[g].normal.dot(faces[seed].normal) >= cos_planar) {
          units.unit_of[g] = id;
          units.faces.push_back(g);
        }
      }
    }
    units.offset.push_back(static_cast<int>(units.faces.size()));
    units.area.push_back(area);
    units.normal_sum.push_back(normal_sum);
  }
  return units;
}

// Smooths the faces' labels (cls): iterated conditional modes over planar units minimising
//   sum over faces of area (1 - n . d_label) + lambda * length of borders between labels,
// each unit restricted to directions within kMaxAngleDeg of all its faces. Starts from the
// nearest direction, so clean meshes keep their nearest-direction charts except along jagged
// borders.
void smoothLabels(std::vector<Face>& faces, const Adjacency& adjacency, const PlanarUnits& units,
                  const std::array<Vec3, 26>& directions, double lambda) {
  const int unit_count = static_cast<int>(units.area.size());
  const double cos_max = std::cos(kMaxAngleDeg * kPi / 180.0);
  std::vector<uint32_t> allowed(unit_count, 0);
  std::vector<int> label(unit_count);
  for (int u = 0; u < unit_count; ++u) {
    const int first = units.faces[units.offset[u]];
    if (units.area[u] <= 0.0) {
      allowed[u] = (1u << 26) - 1;  // no normal: any direction, data cost 0
      label[u] = faces[first].cls;
      continue;
    }
    double best = -std::numeric_limits<double>::infinity();
    for (int c = 0; c < 26; ++c) {
      double min_dot = 1.0;
      for (int i = units.offset[u]; i < units.offset[u + 1]; ++i) {
        const Face& face = faces[units.faces[i]];
        if (face.area > 0.0) min_dot = std::min(min_dot, face.normal.dot(directions[c]));
      }
      if (min_dot >= cos_max) allowed[u] |= 1u << c;
      const double score = units.normal_sum[u].dot(directions[c]);
      if (score > best) {
        best = score;
        label[u] = c;
      }
    }
    allowed[u] |= 1u << label[u];
  }

  // Unit adjacency with border lengths, from the face adjacency (each edge seen from both sides).
  // Only smooth edges count: a sharp edge is a natural seam, and a planar face meeting its
  // neighbours at sharp edges (a chamfer) must keep its own chart, unstretched.
  const double cos_smooth = std::cos(kSmoothEdgeDeg * kPi / 180.0);
  std::vector<std::tuple<int, int, double>> links;
  for (size_t f = 0; f < faces.size(); ++f) {
    const int u = units.unit_of[f];
    for (int e = adjacency.offset[f]; e < adjacency.offset[f + 1]; ++e) {
      const int g = adjacency.neighbour[e];
      const int v = units.unit_of[g];
      if (u != v && faces[f].normal.dot(faces[g].normal) >= cos_smooth) {
        links.emplace_back(u, v, adjacency.length[e]);
      }
    }
  }
  std::sort(links.begin(), links.end());
  std::vector<int> offset(unit_count + 1, 0), neighbour;
  std::vector<double> length;
  for (size_t i = 0; i < links.size();) {
    const int u = std::get<0>(links[i]), v = std::get<1>(links[i]);
    double sum = 0.0;
    for (; i < links.size() && std::get<0>(links[i]) == u && std::get<1>(links[i]) == v; ++i) {
      sum += std::get<2>(links[i]);
    }
    neighbour.push_back(v);
    length.push_back(sum);
    ++offset[u + 1];
  }
  std::partial_sum(offset.begin(), offset.end(), offset.begin());

  std::array<double, 26> agree{};
  for (int sweep = 0; sweep < 50; ++sweep) {
    int changes = 0;
    for (int u = 0; u < unit_count; ++u) {
      if (offset[u] == offset[u + 1]) continue;
      for (int e = offset[u]; e < offset[u + 1]; ++e) agree[label[neighbour[e]]] += length[e];
      auto energy = [&](int c) {
        return -units.normal_sum[u].dot(directions[c]) - lambda * agree[c];
      };
      int best = label[u];
      double best_energy = energy(best);
      for (int c = 0; c < 26; ++c) {
        if (!(allowed[u] >> c & 1u) || c == best) continue;
        const double candidate = energy(c);
        if (candidate < best_energy - 1e-12 * (units.area[u] + 1e-300)) {
          best_energy = candidate;
          best = c;
        }
      }
      for (int e = offset[u]; e < offset[u + 1]; ++e) agree[label[neighbour[e]]] = 0.0;
      if (best != label[u]) {
        label[u] = best;
        ++changes;
      }
    }
    if (changes == 0) break;
  }
  for (size_t f = 0; f < faces.size(); ++f) faces[f].cls = label[units.unit_of[f]];
}

// Checks the options' ranges and that the mesh has triangles at all.
void checkInputs(const TexturedMesh& mesh, const UnwrapOptions& options) {
  detail::requireParameter(options.texture_size >= 8 && options.texture_size <= 65536,
                           "unwrapUvs: texture_size", options.texture_size, "8..65536");
  detail::requireParameter(
      options.padding_texels >= 0 && options.padding_texels <= options.texture_size / 4,
      "unwrapUvs: padding_texels", options.padding_texels, "0..texture_size / 4");
  if (mesh.triangles().empty()) throw Error("unwrapUvs: the mesh is empty (no triangles)");
}

// Positions of the welded vertices in double: the charts are built on these.
std::vector<Vec3> weldedPositions(const std::vector<Eigen::Vector3f>& vertices,
                                  const std::vector<int>& representative) {
  std::vector<Vec3> positions(representative.size());
  for (size_t i = 0; i < representative.size(); ++i) {
    positions[i] = vertices[representative[i]].cast<double>();
  }
  return positions;
}

// Faces on welded vertices with their unit normal (from the winding), area and nearest of the
// 26 directions as class; degenerate faces keep a zero normal, zero area and class -1. Adds up
// the mesh's area in total_area and throws when every face is degenerate.
std::vector<Face> makeFaces(const std::vector<Eigen::Vector3i>& triangles,
                            const std::vector<int>& welded, const std::vector<Vec3>& positions,
                            const std::array<Vec3, 26>& directions, double& total_area) {
  const int face_count = static_cast<int>(triangles.size());
  std::vector<Face> faces(face_count);
  total_area = 0.0;
  for (int f = 0; f < face_count; ++f) {
    Face& face = faces[f];
    for (int k = 0; k < 3; ++k) face.v[k] = welded[triangles[f][k]];
    const Vec3& a = positions[face.v[0]];
    const Vec3& b = positions[face.v[1]];
    const Vec3& c = positions[face.v[2]];
    const Vec3 cross = (b - a).cross(c - a);
    const double longest =
        std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    const double norm = cross.norm();
    if (!(norm > kDegenerateSine * longest) || !(norm > 0.0)) continue;
    face.normal = cross / norm;
    face.area = 0.5 * norm;
    total_area += face.area;
    double best = -2.0;
    for (int d = 0; d < 26; ++d) {
      const double dot = face.normal.dot(directions[d]);
      if (dot > best) {
        best = dot;
        face.cls = d;
      }
    }
  }
  if (!(total_area > 0.0)) {
    throw Error("unwrapUvs: all " + std::to_string(face_count) +
                " triangles of the mesh are degenerate (zero area)");
  }
  return faces;
}

// Degenerate faces take a neighbour's class, so they join its chart (their own projection is
// a segment and claims no texel); isolated ones form their own tiny charts.
void classifyDegenerateFaces(std::vector<Face>& faces, const Adjacency& adjacency) {
  const int face_count = static_cast<int>(faces.size());
  std::vector<int> queue;
  for (int f = 0; f < face_count; ++f) {
    if (faces[f].cls >= 0) queue.push_back(f);
  }
  for (size_t q = 0; q < queue.size(); ++q) {
    const int f = queue[q];
    for (int e = adjacency.offset[f]; e < adjacency.offset[f + 1]; ++e) {
      const int g = adjacency.neighbour[e];
      if (faces[g].cls < 0) {
        faces[g].cls = faces[f].cls;
        queue.push_back(g);
      }
    }
  }
  for (Face& face : faces) {
    if (face.cls < 0) face.cls = 0;
  }
}

// Weight lambda of the border length in smoothLabels: kSmoothness times the root of the mean
// area of the non-degenerate faces, so the smoothing does not depend on the mesh's resolution.
double borderWeight(const std::vector<Face>& faces, double total_area) {
  int non_degenerate = 0;
  for (const Face& face : faces) non_degenerate += face.area > 0.0;
  return kSmoothness * std::sqrt(total_area / non_degenerate);
}

// Charts: edge-connected components of faces with one label.
struct Charts {
  std::vector<int> chart_of;            // per face
  std::vector<std::vector<int>> faces;  // per chart; emptied when merged into another
  std::vector<double> area;             // per chart
  std::vector<int> cls;                 // per chart: index into chartDirections()
};

// Splits the labelled faces into edge-connected components of one label, in the order of
// their first face.
Charts findCharts(const std::vector<Face>& faces, const Adjacency& adjacency) {
  const int face_count = static_cast<int>(faces.size());
  Charts charts;
  charts.chart_of.assign(face_count, -1);
  for (int seed = 0; seed < face_count; ++seed) {
    if (charts.chart_of[seed] >= 0) continue;
    const int id = static_cast<int>(charts.faces.size());
    std::vector<int> members{seed};
    charts.chart_of[seed] = id;
    double area = 0.0;
    for (size_t q = 0; q < members.size(); ++q) {
      const int f = members[q];
      area += faces[f].area;
      for (int e = adjacency.offset[f]; e < adjacency.offset[f + 1]; ++e) {
        const int g = adjacency.neighbour[e];
        if (charts.chart_of[g] < 0 && faces[g].cls == faces[seed].cls) {
          charts.chart_of[g] = id;
          members.push_back(g);
        }
      }
    }
    charts.faces.push_back(std::move(members));
    charts.area.push_back(area);
    charts.cls.push_back(faces[seed].cls);
  }
  return charts;
}

// Fragments (smallest first) join the neighbour they share the longest border with, when they
// are small enough next to it and all their faces are within kMergeAngleDeg of its direction.
void mergeFragments(Charts& charts, const std::vector<Face>& faces, const Adjacency& adjacency,
                    const std::array<Vec3, 26>& directions, double total_area) {
  const double cos_merge = std::cos(kMergeAngleDeg * kPi / 180.0);
  std::vector<int> order(charts.faces.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return charts.area[a] < charts.area[b]; });
  std::vector<double> shared(charts.faces.size(), 0.0);
  std::vector<int> touched;
  for (int c : order) {
    if (charts.area[c] >= kFragmentOfMesh * total_area) break;
    for (int f : charts.faces[c]) {
      for (int e = adjacency.offset[f]; e < adjacency.offset[f + 1]; ++e) {
        const int n = charts.chart_of[adjacency.neighbour[e]];
        if (n == c) continue;
        if (shared[n] == 0.0) touched.push_back(n);
        shared[n] += adjacency.length[e] + 1e-300;
      }
    }
    int best = -1;
    for (int n : touched) {
      if (best >= 0 && shared[n] <= shared[best]) continue;
      if (!(charts.area[c] < kFragmentOfNeighbour * charts.area[n])) continue;
      const Vec3& d = directions[charts.cls[n]];
      bool fits = true;
      for (int f : charts.faces[c]) {
        if (faces[f].area > 0.0 && faces[f].normal.dot(d) < cos_merge) {
          fits = false;
          break;
        }
      }
      if (fits) best = n;
    }
    for (int n : touched) shared[n] = 0.0;
    touched.clear();
    if (best < 0) continue;
    for (int f : charts.faces[c]) charts.chart_of[f] = best;
    charts.faces[best].insert(charts.faces[best].end(), charts.faces[c].begin(),
                              charts.faces[c].end());
    charts.area[best] += charts.area[c];
    charts.faces[c].clear();
    charts.area[c] = 0.0;
  }
}

// Direction to project a chart along: the normal of the chart's largest planar unit when that
// is most of the chart (planar faces stay exact), else the class's or the mean normal,
// whichever is closer to the chart's worst face.
Vec3 projectionDirection(const std::vector<int>& members, double chart_area,
                         const Vec3& class_direction, const std::vector<Face>& faces,
                         const PlanarUnits& units) {
  const double cos_max = std::cos(kMaxAngleDeg * kPi / 180.0);
  auto worstDot = [&](const Vec3& d) {
    double worst = 2.0;
    for (int f : members) {
      if (faces[f].area > 0.0) worst = std::min(worst, faces[f].normal.dot(d));
    }
    return worst;
  };
  Vec3 direction = class_direction;
  int largest = units.unit_of[members.front()];
  Vec3 mean = Vec3::Zero();
  for (int f : members) {
    mean += faces[f].area * faces[f].normal;
    if (units.area[units.unit_of[f]] > units.area[largest]) largest = units.unit_of[f];
  }
  const Vec3 planar = units.normal_sum[largest].normalized();
  if (units.area[largest] >= 0.5 * chart_area && units.area[largest] > 0.0 &&
      worstDot(planar) >= cos_max) {
    direction = planar;
  } else if (mean.norm() > 0.0) {
    mean.normalize();
    if (worstDot(mean) > worstDot(class_direction) + 1e-12) direction = mean;
  }
  return direction;
}

// Projects the chart's faces orthographically onto the plane normal to `direction` (flat[f],
// in metres, u right and v up seen from the front) and returns their bounding box in lo, hi.
void projectChart(const std::vector<int>& members, const Vec3& direction,
                  const std::vector<Face>& faces, const std::vector<Vec3>& positions,
                  std::vector<std::array<Vec2, 3>>& flat, Vec2& lo, Vec2& hi) {
  Vec3 e1, e2;
  projectionBasis(direction, e1, e2);
  lo = Vec2::Constant(std::numeric_limits<double>::infinity());
  hi = -lo;
  for (int f : members) {
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = positions[faces[f].v[k]];
      flat[f][k] = Vec2(p.dot(e1), p.dot(e2));
      lo = lo.cwiseMin(flat[f][k]);
      hi = hi.cwiseMax(flat[f][k]);
    }
  }
}

// Per-face and per-vertex scratch state for splitting charts into pieces, shared by all charts
// (the round and query counters only grow, so stale marks never match).
struct SplitState {
  // Per face: the chart's current round when pending, -1 when accepted, -2 when rejected in the
  // current round.
  std::vector<int> round_of;
  std::vector<int> tested_by;    // per face: the last overlap query that tested it
  std::vector<int> local_index;  // per welded vertex: its index in the current piece, or -1
  std::vector<std::array<Vec2, 3>> flat;  // per face: its projected corners
  int round = 0, query = 0;
};

// One splitting round: grows a piece from the first pending face through edges; a face whose
// projection would overlap the piece's accepted faces stays pending and seeds a later piece of
// the same chart. Returns the piece (faces only) and removes its faces from `pending`.
Piece growPiece(std::vector<int>& pending, const std::vector<Face>& faces,
                const Adjacency& adjacency, double eps, TriangleGrid& grid, SplitState& state) {
  const int round = ++state.round;
  for (int f : pending) state.round_of[f] = round;
  Piece piece;
  std::vector<int>& accepted = piece.faces;
  auto tryAccept = [&](int f) {
    const std::array<Vec2, 3>& t = state.flat[f];
    const Vec2 t_lo = t[0].cwiseMin(t[1]).cwiseMin(t[2]);
    const Vec2 t_hi = t[0].cwiseMax(t[1]).cwiseMax(t[2]);
    const bool flat_face =
        faces[f].area <= 0.0 || std::abs(cross2(t[1] - t[0], t[2] - t[0])) <= eps * eps;
    if (!flat_face) {
      const int query = ++state.query;
      const bool overlaps = grid.anyInBox(t_lo, t_hi, [&](int g) {
        if (state.tested_by[g] == query) return false;
        state.tested_by[g] = query;
        return interiorsOverlap(t, state.flat[g], eps);
      });
      if (overlaps) return false;
      grid.insert(t_lo, t_hi, f);
    }
    state.round_of[f] = -1;
    accepted.push_back(f);
    return true;
  };
  tryAccept(pending.front());
  for (size_t q = 0; q < accepted.size(); ++q) {
    const int f = accepted[q];
    for (int e = adjacency.offset[f]; e < adjacency.offset[f + 1]; ++e) {
      const int g = adjacency.neighbour[e];
      // Tested once per round: rejected faces are marked -2 until the next round.
      if (state.round_of[g] == round && !tryAccept(g)) state.round_of[g] = -2;
    }
  }
  std::vector<int> rest;
  for (int f : pending) {
    if (state.round_of[f] != -1) rest.push_back(f);
  }
  pending.swap(rest);
  grid.clear();
  return piece;
}

// Gives the piece its welded vertices (in order of first use by its faces) and their projected
// coordinates.
void collectPieceVertices(Piece& piece, const std::vector<Face>& faces, SplitState& state) {
  for (int f : piece.faces) {
    for (int k = 0; k < 3; ++k) {
      const int v = faces[f].v[k];
      if (state.local_index[v] >= 0) continue;
      state.local_index[v] = static_cast<int>(piece.vertices.size());
      piece.vertices.push_back(v);
      piece.local.push_back(state.flat[f][k]);
    }
  }
  for (int v : piece.vertices) state.local_index[v] = -1;
}

// Projects every chart onto its plane and splits it where its projection would overlap itself:
// the pieces to pack, each turned to its minimum-area bounding rectangle.
std::vector<Piece> makePieces(const Charts& charts, const std::vector<Face>& faces,
                              const Adjacency& adjacency, const PlanarUnits& units,
                              const std::vector<Vec3>& positions,
                              const std::array<Vec3, 26>& directions) {
  const int face_count = static_cast<int>(faces.size());
  std::vector<Piece> pieces;
  SplitState state;
  state.round_of.assign(face_count, -1);
  state.tested_by.assign(face_count, -1);
  state.local_index.assign(positions.size(), -1);
  state.flat.resize(face_count);
  for (size_t c = 0; c < charts.faces.size(); ++c) {
    const std::vector<int>& members = charts.faces[c];
    if (members.empty()) continue;
    const Vec3 direction =
        projectionDirection(members, charts.area[c], directions[charts.cls[c]], faces, units);
    Vec2 lo, hi;
    projectChart(members, direction, faces, positions, state.flat, lo, hi);
    const double eps = 1e-9 * (hi - lo).norm();
    TriangleGrid grid(lo, hi, members.size());
    std::vector<int> pending = members;
    while (!pending.empty()) {
      Piece piece = growPiece(pending, faces, adjacency, eps, grid, state);
      collectPieceVertices(piece, faces, state);
      alignPiece(piece);
      pieces.push_back(std::move(piece));
    }
  }
  return pieces;
}

// Where the packed pieces go in the texture.
struct Packing {
  double scale = 0.0;                 // texels per metre, common to all pieces
  double border = 0.0;                // texels kept empty along the texture's border
  std::vector<Placement> placements;  // per piece
};

// Packing order: largest pieces first (by longer side, then shorter side), ties kept in order.
std::vector<int> packingOrder(const std::vector<Piece>& pieces) {
  std::vector<int> order(pieces.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    const double max_a = pieces[a].size.maxCoeff(), max_b = pieces[b].size.maxCoeff();
    if (max_a != max_b) return max_a > max_b;
    return pieces[a].size.minCoeff() > pieces[b].size.minCoeff();
  });
  return order;
}

// Upper bound of the scale that fits: the pieces' total area may not exceed the container's,
// nor may the longest piece (plus its gap) exceed its side. Infinite without any extent.
double scaleUpperBound(const std::vector<Piece>& pieces, double container, double gap) {
  double area_sum = 0.0, longest = 0.0;
  for (const Piece& piece : pieces) {
    area_sum += piece.size.x() * piece.size.y();
    longest = std::max(longest, piece.size.maxCoeff());
  }
  return std::min(
      area_sum > 0.0 ? container / std::sqrt(area_sum) : std::numeric_limits<double>::infinity(),
      longest > 0.0 ? (container - gap) / longest : std::numeric_limits<double>::infinity());
}

// Packs all pieces at one scale, with padding between them and to the border: the largest
// texels-per-metre that fits, by bisection. Throws when not even their padding fits.
Packing packPieces(const std::vector<Piece>& pieces, const UnwrapOptions& options) {
  const double texture = options.texture_size;
  const double padding = options.padding_texels;
  const double gap = padding + 1.0 + kMarginTexels;  // texel centres: padding empty between
  const double border = padding + kMarginTexels;
  const double container = texture + 1.0 - border;  // boxes carry their trailing gap
  const int piece_count = static_cast<int>(pieces.size());
  const std::vector<int> order = packingOrder(pieces);
  std::vector<Vec2> boxes(piece_count);
  std::vector<Placement> placements;
  Packing packing;
  packing.border = border;
  auto fits = [&](double scale) {
    for (int i = 0; i < piece_count; ++i) {
      boxes[i] = pieces[i].size * scale + Vec2::Constant(gap);
    }
    return packSkyline(boxes, order, container, container, placements);
  };
  if (container - gap <= 0.0 || !fits(0.0)) {
    std::ostringstream message;
    message << "unwrapUvs: " << piece_count << " charts do not fit a " << options.texture_size
            << " x " << options.texture_size
            << " texture with padding_texels = " << options.padding_texels
            << ": their padding alone (" << gap
            << " texels per chart and side) needs more room; use a larger texture_size or fewer "
               "padding_texels";
    throw Error(message.str());
  }
  packing.placements = placements;
  double low = 0.0;
  double high = scaleUpperBound(pieces, container, gap);
  if (!std::isfinite(high)) throw Error("unwrapUvs: the mesh has no extent to unwrap");
  if (fits(high)) {
    low = high;
    packing.placements = placements;
  } else {
    for (int iteration = 0; iteration < 48 && high - low > 1e-7 * high; ++iteration) {
      const double middle = 0.5 * (low + high);
      if (fits(middle)) {
        low = middle;
        packing.placements = placements;
      } else {
        high = middle;
      }
    }
  }
  packing.scale = low;
  if (!(packing.scale > 0.0)) {
    throw Error("unwrapUvs: the charts do not fit a " + std::to_string(options.texture_size) +
                " texture at any scale; use a larger texture_size or fewer padding_texels");
  }
  return packing;
}

// Writes the result mesh: per piece its own vertices (the original positions) with their UVs in
// the packed texture; triangles keep their index and corner order.
UnwrapResult makeResult(const TexturedMesh& mesh, const std::vector<int>& representative,
                        const std::vector<Face>& faces, const std::vector<Piece>& pieces,
                        const Packing& packing, const UnwrapOptions& options) {
  const double texture = options.texture_size;
  const double scale = packing.scale;
  const int piece_count = static_cast<int>(pieces.size());
  std::vector<int> local_index(representative.size(), -1);
  std::vector<Eigen::Vector3f> out_vertices;
  std::vector<Eigen::Vector2f> out_uvs;
  std::vector<Eigen::Vector3i> out_triangles(faces.size());
  for (int i = 0; i < piece_count; ++i) {
    const Piece& piece = pieces[i];
    const Placement& placement = packing.placements[i];
    const int base = static_cast<int>(out_vertices.size());
    const Vec2 size = placement.rotated ? Vec2(piece.size.y(), piece.size.x()) : piece.size;
    const double left = packing.border + placement.x;
    const double top = packing.border + placement.y;
    for (size_t k = 0; k < piece.vertices.size(); ++k) {
      const Vec2& p = piece.local[k];
      // A quarter turn (a, b) -> (h - b, a) keeps the orientation.
      const Vec2 q = placement.rotated ? Vec2(piece.size.y() - p.y(), p.x()) : p;
      const double column = left + q.x() * scale;
      const double row = top + (size.y() - q.y()) * scale;  // v up, rows down
      out_vertices.push_back(mesh.vertices()[representative[piece.vertices[k]]]);
      out_uvs.emplace_back(static_cast<float>(column / texture),
                           static_cast<float>(1.0 - row / texture));
      local_index[piece.vertices[k]] = base + static_cast<int>(k);
    }
    for (int f : piece.faces) {
      for (int k = 0; k < 3; ++k) out_triangles[f][k] = local_index[faces[f].v[k]];
    }
    for (int v : piece.vertices) local_index[v] = -1;
  }

  UnwrapResult result;
  result.mesh = TexturedMesh(std::move(out_vertices), std::move(out_triangles), std::move(out_uvs));
  result.metres_per_uv = texture / scale;
  result.chart_count = piece_count;
  return result;
}

}  // namespace

UnwrapResult unwrapUvs(const TexturedMesh& mesh, const UnwrapOptions& options) {
  checkInputs(mesh, options);

  // Faces on welded vertices, their normals and nearest directions.
  std::vector<int> representative;
  const std::vector<int> welded = weldVertices(mesh.vertices(), representative);
  const std::vector<Vec3> positions = weldedPositions(mesh.vertices(), representative);
  const std::array<Vec3, 26> directions = chartDirections();
  double total_area = 0.0;
  std::vector<Face> faces = makeFaces(mesh.triangles(), welded, positions, directions, total_area);
  const Adjacency adjacency = buildAdjacency(faces, positions);

  // Labels: nearest direction, smoothed over planar units.
  classifyDegenerateFaces(faces, adjacency);
  const PlanarUnits units = findPlanarUnits(faces, adjacency);
  smoothLabels(faces, adjacency, units, directions, borderWeight(faces, total_area));

  // Charts, projected and split into non-overlapping pieces, packed and written out.
  Charts charts = findCharts(faces, adjacency);
  mergeFragments(charts, faces, adjacency, directions, total_area);
  const std::vector<Piece> pieces =
      makePieces(charts, faces, adjacency, units, positions, directions);
  const Packing packing = packPieces(pieces, options);
  return makeResult(mesh, representative, faces, pieces, packing, options);
}

}  // namespace norm2tex
