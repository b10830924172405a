// unwrapUvs' segmentation into charts (see uv_charts.hpp).
#include "mesh/uv_charts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <tuple>
#include <utility>

namespace norm2tex {
namespace uv_unwrap_detail {
namespace {

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

}  // namespace

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

double borderWeight(const std::vector<Face>& faces, double total_area) {
  int non_degenerate = 0;
  for (const Face& face : faces) non_degenerate += face.area > 0.0;
  return kSmoothness * std::sqrt(total_area / non_degenerate);
}

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

Segmentation segmentCharts(std::vector<Face>& faces, const Adjacency& adjacency,
                           const std::array<Vec3, 26>& directions, double total_area) {
  // Labels: nearest direction, smoothed over planar units.
  classifyDegenerateFaces(faces, adjacency);
  Segmentation segmentation;
  segmentation.units = findPlanarUnits(faces, adjacency);
  smoothLabels(faces, adjacency, segmentation.units, directions, borderWeight(faces, total_area));
  // Charts: edge-connected faces of one label, fragments merged into their neighbours.
  segmentation.charts = findCharts(faces, adjacency);
  mergeFragments(segmentation.charts, faces, adjacency, directions, total_area);
  return segmentation;
}

}  // namespace uv_unwrap_detail
}  // namespace norm2tex
