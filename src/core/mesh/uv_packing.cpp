// unwrapUvs' pieces and packing (see uv_packing.hpp).
#include "mesh/uv_packing.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <string>
#include <utility>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace uv_unwrap_detail {
namespace {

// Largest hull that gets every edge direction tried for its minimum-area rectangle.
constexpr int kMaxHullDirections = 256;

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

}  // namespace

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

}  // namespace uv_unwrap_detail
}  // namespace norm2tex
