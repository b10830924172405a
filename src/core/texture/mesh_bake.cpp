#include "norm2tex/texture/mesh_bake.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <vector>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/mesh/uv_unwrap.hpp"
#include "texture/bake_stages.hpp"

namespace norm2tex {
namespace {

/// Integration islands: 4-connected valid texels of one chart. Charts that touch in the texture
/// stay apart; a chart cut by invalid texels falls into parts.
UvIslands splitCharts(const cv::Mat1i& charts, const cv::Mat1b& valid) {
  UvIslands result;
  result.labels = cv::Mat1i(charts.size(), 0);
  std::vector<cv::Point> stack;
  for (int r = 0; r < charts.rows; ++r) {
    for (int c = 0; c < charts.cols; ++c) {
      if (!valid(r, c) || result.labels(r, c) != 0) continue;
      UvIsland island;
      island.label = static_cast<int>(result.islands.size()) + 1;
      const int chart = charts(r, c);
      int min_x = c, max_x = c, min_y = r, max_y = r;
      stack.assign(1, cv::Point(c, r));
      result.labels(r, c) = island.label;
      while (!stack.empty()) {
        const cv::Point p = stack.back();
        stack.pop_back();
        ++island.texel_count;
        min_x = std::min(min_x, p.x);
        max_x = std::max(max_x, p.x);
        min_y = std::min(min_y, p.y);
        max_y = std::max(max_y, p.y);
        const cv::Point neighbours[4] = {
            {p.x + 1, p.y}, {p.x - 1, p.y}, {p.x, p.y + 1}, {p.x, p.y - 1}};
        for (const cv::Point& q : neighbours) {
          if (q.x < 0 || q.y < 0 || q.x >= charts.cols || q.y >= charts.rows) continue;
          if (!valid(q) || charts(q) != chart || result.labels(q) != 0) continue;
          result.labels(q) = island.label;
          stack.push_back(q);
        }
      }
      island.bounding_box = cv::Rect(min_x, min_y, max_x - min_x + 1, max_y - min_y + 1);
      result.islands.push_back(island);
    }
  }
  return result;
}

/// One sample across a seam: the same surface point at two UVs.
struct SeamSample {
  int island_a, island_b;
  float height_a, height_b;
  Eigen::Vector2f uv_a, uv_b;
  cv::Point texel_a, texel_b;  // the island texel each side's look-up leans on most
};

/// Edges of the mesh that are one edge in 3-D but two in UV (their triangles' corners share
/// positions, not UVs), sampled at both sides. Seam vertices are duplicates with bit-identical
/// positions (the loader joins only identical position + UV), so positions are matched exactly.
std::vector<SeamSample> sampleSeams(const TexturedMesh& mesh, const HeightAtlas& atlas,
                                    int& seam_edges) {
  using Point = std::array<float, 3>;
  struct Side {
    Eigen::Vector2f uv_first, uv_second;  // UVs at the key's first and second point
  };
  std::map<std::pair<Point, Point>, std::vector<Side>> edges;
  const auto& vertices = mesh.vertices();
  const auto& uvs = mesh.uvs();
  for (const Eigen::Vector3i& triangle : mesh.triangles()) {
    for (int k = 0; k < 3; ++k) {
      const int i = triangle[k], j = triangle[(k + 1) % 3];
      const Point p{vertices[i].x(), vertices[i].y(), vertices[i].z()};
      const Point q{vertices[j].x(), vertices[j].y(), vertices[j].z()};
      if (p < q) {
        edges[{p, q}].push_back({uvs[i], uvs[j]});
      } else if (q < p) {
        edges[{q, p}].push_back({uvs[j], uvs[i]});
      }
    }
  }
  std::vector<SeamSample> samples;
  seam_edges = 0;
  const cv::Mat1i& labels = atlas.islandLabels();
  // The island HeightAtlas::sample draws from: that of the heaviest valid texel of the four
  // around the point (a seam runs along a chart's border, between texel centres).
  const auto islandAt = [&](const Eigen::Vector2f& uv, cv::Point& texel) {
    const double u = uv.x() - std::floor(uv.x()), v = uv.y() - std::floor(uv.y());
    const double x = u * labels.cols - 0.5, y = (1.0 - v) * labels.rows - 0.5;
    const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    const double fx = x - x0, fy = y - y0;
    int best_label = 0;
    double best = -1.0;
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 2; ++j) {
        const int r = (y0 + i + labels.rows) % labels.rows;
        const int c = (x0 + j + labels.cols) % labels.cols;
        const double weight = (i ? fy : 1 - fy) * (j ? fx : 1 - fx);
        if (labels(r, c) != 0 && weight > best) {
          best = weight;
          best_label = labels(r, c);
          texel = cv::Point(c, r);
        }
      }
    }
    return best_label;
  };
  for (const auto& [key, sides] : edges) {
    if (sides.size() != 2) continue;  // a border, or a non-manifold edge: no seam to match
    const Side& a = sides[0];
    const Side& b = sides[1];
    if (a.uv_first == b.uv_first && a.uv_second == b.uv_second) continue;  // not a UV seam
    const double texels =
        std::max((a.uv_second - a.uv_first).norm(), (b.uv_second - b.uv_first).norm()) *
        std::max(labels.rows, labels.cols);
    const int count = std::clamp(static_cast<int>(std::ceil(2.0 * texels)), 2, 512);
    bool counted = false;
    for (int s = 0; s < count; ++s) {
      const float t = (s + 0.5f) / count;
      const Eigen::Vector2f uv_a = (1 - t) * a.uv_first + t * a.uv_second;
      const Eigen::Vector2f uv_b = (1 - t) * b.uv_first + t * b.uv_second;
      cv::Point texel_a, texel_b;
      const int island_a = islandAt(uv_a, texel_a), island_b = islandAt(uv_b, texel_b);
      if (island_a == 0 || island_b == 0 || island_a == island_b) continue;
      bool valid_a = false, valid_b = false;
      const float height_a = atlas.sample(uv_a.x(), uv_a.y(), &valid_a);
      const float height_b = atlas.sample(uv_b.x(), uv_b.y(), &valid_b);
      if (!valid_a || !valid_b) continue;
      samples.push_back({island_a, island_b, height_a, height_b, uv_a, uv_b, texel_a, texel_b});
      counted = true;
    }
    if (counted) ++seam_edges;
  }
  return samples;
}

/// Island constants c minimising sum over samples (h_a + c_a - h_b - c_b)^2, plus a tiny pull
/// of every constant to 0 that fixes the free common offset (and leaves islands without a seam
/// at zero mean).
std::vector<double> seamOffsets(const std::vector<SeamSample>& samples, int island_count) {
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(island_count);
  for (const SeamSample& s : samples) {
    const int a = s.island_a - 1, b = s.island_b - 1;
    entries.emplace_back(a, a, 1.0);
    entries.emplace_back(b, b, 1.0);
    entries.emplace_back(a, b, -1.0);
    entries.emplace_back(b, a, -1.0);
    const double step = static_cast<double>(s.height_b) - s.height_a;  // wanted c_a - c_b
    rhs[a] += step;
    rhs[b] -= step;
  }
  for (int i = 0; i < island_count; ++i) entries.emplace_back(i, i, 1e-6);
  Eigen::SparseMatrix<double> normal(island_count, island_count);
  normal.setFromTriplets(entries.begin(), entries.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
  if (solver.info() != Eigen::Success) throw Error("seam offsets: the island system is singular");
  const Eigen::VectorXd offsets = solver.solve(rhs);
  return std::vector<double>(offsets.data(), offsets.data() + island_count);
}

double rmsStep(const std::vector<SeamSample>& samples, const std::vector<double>& offsets) {
  if (samples.empty()) return 0.0;
  double sum = 0.0;
  for (const SeamSample& s : samples) {
    const double a = s.height_a + (offsets.empty() ? 0.0 : offsets[s.island_a - 1]);
    const double b = s.height_b + (offsets.empty() ? 0.0 : offsets[s.island_b - 1]);
    sum += (a - b) * (a - b);
  }
  return std::sqrt(sum / samples.size());
}

/// Heights at both sides of every sample, looked up again in `atlas` (after corrections).
void resample(std::vector<SeamSample>& samples, const HeightAtlas& atlas) {
  for (SeamSample& sample : samples) {
    sample.height_a = atlas.sample(sample.uv_a.x(), sample.uv_a.y());
    sample.height_b = atlas.sample(sample.uv_b.x(), sample.uv_b.y());
  }
}

/// Seam feathering: each island filters its relief on its own, so near a seam the two sides'
/// low-passes differ in shape, a smooth mismatch no constant can remove. Each side takes half
/// of the remaining difference at the seam, spread along the seam (normalised Gaussian of the
/// seam samples) and fading with the distance from the seam (Gaussian of `sigma` texels, the
/// high-pass's own scale, so only wavelengths the high-pass removes anyway are touched).
void featherSeams(const std::vector<SeamSample>& samples, const UvIslands& islands, double sigma,
                  cv::Mat1f& global) {
  std::vector<std::vector<std::pair<cv::Point, float>>> per_island(islands.islands.size());
  for (const SeamSample& s : samples) {
    const float half = 0.5f * (s.height_a - s.height_b);
    per_island[s.island_a - 1].emplace_back(s.texel_a, -half);
    per_island[s.island_b - 1].emplace_back(s.texel_b, half);
  }
  const int radius = static_cast<int>(std::ceil(3.0 * sigma));
  for (size_t i = 0; i < per_island.size(); ++i) {
    if (per_island[i].empty()) continue;
    const cv::Rect box = islands.islands[i].bounding_box;
    cv::Mat1f value(box.size(), 0.0f), weight(box.size(), 0.0f);
    cv::Mat1b off_seam(box.size(), uchar(255));
    for (const auto& [texel, correction] : per_island[i]) {
      const cv::Point p = texel - box.tl();
      if (!box.contains(texel)) continue;
      value(p) += correction;
      weight(p) += 1.0f;
      off_seam(p) = 0;
    }
    // Along the seam: the corrections' local mean (narrower, so it follows the seam).
    const double along = std::max(0.5, 0.5 * sigma);
    const cv::Size kernel(2 * static_cast<int>(std::ceil(3.0 * along)) + 1,
                          2 * static_cast<int>(std::ceil(3.0 * along)) + 1);
    cv::GaussianBlur(value, value, kernel, along, along, cv::BORDER_CONSTANT);
    cv::GaussianBlur(weight, weight, kernel, along, along, cv::BORDER_CONSTANT);
    cv::Mat1f distance;
    cv::distanceTransform(off_seam, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    // Away from the seam: carry the nearest seam correction, faded by distance. The blurred
    // correction is extended by normalised convolution at the fading scale.
    cv::Mat1f wide_value, wide_weight;
    const cv::Size wide(2 * radius + 1, 2 * radius + 1);
    cv::GaussianBlur(value, wide_value, wide, sigma, sigma, cv::BORDER_CONSTANT);
    cv::GaussianBlur(weight, wide_weight, wide, sigma, sigma, cv::BORDER_CONSTANT);
    const int label = islands.islands[i].label;
    for (int r = 0; r < box.height; ++r) {
      const int* labels = islands.labels.ptr<int>(box.y + r);
      float* h = global.ptr<float>(box.y + r);
      for (int c = 0; c < box.width; ++c) {
        if (labels[box.x + c] != label) continue;
        const float d = distance(r, c);
        const float fade = std::exp(static_cast<float>(-0.5 * d * d / (sigma * sigma)));
        if (fade < 1e-4f) continue;
        const float w = weight(r, c) > 1e-6f ? weight(r, c) : wide_weight(r, c);
        const float v = weight(r, c) > 1e-6f ? value(r, c) : wide_value(r, c);
        if (!(w > 1e-12f)) continue;
        h[box.x + c] += fade * v / w;
      }
    }
  }
}

}  // namespace

HeightAtlas bakeHeightAtlasForMesh(const NormalMap& normal_map, const TexturedMesh& mesh,
                                   BakeOptions options, const BakeProgress& progress,
                                   MeshBakeReport* report) {
  if (!mesh.hasUvs()) throw Error("bakeHeightAtlasForMesh: the mesh has no UVs");
  const cv::Size size(normal_map.cols(), normal_map.rows());
  const UvLayout layout = computeUvLayout(mesh, size);
  MeshBakeReport summary;
  summary.chart_count = static_cast<int>(layout.metres_per_uv.size()) - 1;

  // The surface's scale: charts weighted by their texel counts.
  if (!(options.mm_per_texel > 0.0)) {
    std::vector<long> texels(layout.metres_per_uv.size(), 0);
    for (int r = 0; r < layout.island.rows; ++r)
      for (int c = 0; c < layout.island.cols; ++c) ++texels[layout.island(r, c)];
    double weighted = 0.0;
    long counted = 0;
    for (size_t k = 1; k < texels.size(); ++k) {
      if (layout.metres_per_uv[k] <= 0.0) continue;
      weighted += texels[k] * layout.metres_per_uv[k];
      counted += texels[k];
    }
    if (counted > 0) {
      options.mm_per_texel = weighted / counted * 1e3 / std::sqrt(double(size.area()));
    }
  }
  summary.mm_per_texel = options.mm_per_texel;

  cv::Mat1b valid = normal_map.valid() & (layout.island > 0);
  UvIslands islands = splitCharts(layout.island, valid);
  if (islands.islands.empty()) {
    throw Error("no UV chart of the mesh covers a valid texel of the normal map");
  }
  cv::Mat1f global = detail::integrateIslands(normal_map, islands, options, progress, summary.bake);

  // Offsets across seams, from heights sampled island-aware at both UVs of each seam edge.
  const HeightAtlas unmatched(global.clone(), valid.clone(), islands.labels.clone());
  const std::vector<SeamSample> samples = sampleSeams(mesh, unmatched, summary.seams.seam_edges);
  summary.seams.samples = static_cast<int>(samples.size());
  const cv::Vec2f range_before =
      maskedPercentiles(global, valid, options.percentile_low, options.percentile_high);
  summary.seams.step_before =
      rmsStep(samples, {}) / std::max(1e-12f, range_before[1] - range_before[0]);
  if (!samples.empty()) {
    const std::vector<double> offsets =
        seamOffsets(samples, static_cast<int>(islands.islands.size()));
    for (int r = 0; r < global.rows; ++r) {
      const int* label = islands.labels.ptr<int>(r);
      float* h = global.ptr<float>(r);
      for (int c = 0; c < global.cols; ++c) {
        if (label[c] > 0) h[c] += static_cast<float>(offsets[label[c] - 1]);
      }
    }
    std::vector<SeamSample> matched = samples;
    for (SeamSample& s : matched) {
      s.height_a += static_cast<float>(offsets[s.island_a - 1]);
      s.height_b += static_cast<float>(offsets[s.island_b - 1]);
    }
    const double cutoff = reliefCutoffTexels(options);
    if (cutoff > 0.0) {
      featherSeams(matched, islands, std::sqrt(std::log(2.0) / 2.0) / CV_PI * cutoff, global);
      resample(matched, HeightAtlas(global.clone(), valid.clone(), islands.labels.clone()));
    }
    const cv::Vec2f range_after =
        maskedPercentiles(global, valid, options.percentile_low, options.percentile_high);
    summary.seams.step_after =
        rmsStep(matched, {}) / std::max(1e-12f, range_after[1] - range_after[0]);
  }
  HeightAtlas atlas = detail::finishAtlas(std::move(global), std::move(valid),
                                          std::move(islands.labels), options, summary.bake);
  if (report != nullptr) *report = summary;
  return atlas;
}

}  // namespace norm2tex
