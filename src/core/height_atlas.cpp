#include "norm2tex/height_atlas.hpp"

#include <cmath>

#include "norm2tex/error.hpp"
#include "norm2tex/uv_islands.hpp"

namespace norm2tex {

HeightAtlas::HeightAtlas(cv::Mat1f heights, cv::Mat1b valid, UvWrap wrap)
    : heights_(std::move(heights)), valid_(std::move(valid)), wrap_(wrap) {
  if (heights_.empty()) throw Error("HeightAtlas: empty height map");
  if (valid_.size() != heights_.size()) throw Error("HeightAtlas: mask and heights differ in size");
  heights_.setTo(0.0f, valid_ == 0);
  UvIslands islands = findUvIslands(valid_);
  labels_ = std::move(islands.labels);
  island_count_ = static_cast<int>(islands.islands.size());
}

int HeightAtlas::wrapIndex(int index, int size) const {
  if (wrap_ == UvWrap::kClamp) return index < 0 ? 0 : (index >= size ? size - 1 : index);
  const int wrapped = index % size;
  return wrapped < 0 ? wrapped + size : wrapped;
}

float HeightAtlas::sample(double u, double v, bool* valid) const {
  if (valid != nullptr) *valid = false;
  if (heights_.empty() || !std::isfinite(u) || !std::isfinite(v)) return 0.0f;
  if (wrap_ == UvWrap::kRepeat) {
    u -= std::floor(u);
    v -= std::floor(v);
  } else {
    u = u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u);
    v = v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
  }
  // Continuous texel coordinates with texel centres at integers; row 0 is v = 1.
  const double x = u * heights_.cols - 0.5;
  const double y = (1.0 - v) * heights_.rows - 0.5;
  const int x0 = static_cast<int>(std::floor(x));
  const int y0 = static_cast<int>(std::floor(y));
  const float fx = static_cast<float>(x - x0);
  const float fy = static_cast<float>(y - y0);

  const int cols[2] = {wrapIndex(x0, heights_.cols), wrapIndex(x0 + 1, heights_.cols)};
  const int rows[2] = {wrapIndex(y0, heights_.rows), wrapIndex(y0 + 1, heights_.rows)};
  const float weights[2][2] = {{(1 - fx) * (1 - fy), fx * (1 - fy)}, {(1 - fx) * fy, fx * fy}};

  // The island of the heaviest valid texel decides; other islands and gaps get no weight.
  int island = 0, best_i = 0, best_j = 0;
  float best = -1.0f;
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      const int label = labels_(rows[i], cols[j]);
      if (label != 0 && weights[i][j] > best) {
        best = weights[i][j];
        island = label;
        best_i = i;
        best_j = j;
      }
    }
  }
  if (island == 0) return 0.0f;
  float sum = 0.0f, weight_sum = 0.0f;
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      if (labels_(rows[i], cols[j]) != island) continue;
      sum += weights[i][j] * heights_(rows[i], cols[j]);
      weight_sum += weights[i][j];
    }
  }
  if (valid != nullptr) *valid = true;
  // Exactly on a texel line the only island texel may have zero weight: it is still the answer.
  return weight_sum > 0.0f ? sum / weight_sum : heights_(rows[best_i], cols[best_j]);
}

}  // namespace norm2tex
