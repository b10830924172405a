#include "norm2tex/texture/height_atlas.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "norm2tex/common/error.hpp"
#include "norm2tex/texture/uv_islands.hpp"

namespace norm2tex {
namespace {

/// The matrix itself when nobody else holds its data, else a copy: the atlas owns its texels.
template <typename T>
cv::Mat_<T> owned(cv::Mat_<T> matrix) {
  const bool sole_owner = matrix.u != nullptr && matrix.u->refcount == 1 && matrix.isContinuous() &&
                          !matrix.isSubmatrix();
  return sole_owner ? matrix : cv::Mat_<T>(matrix.clone());
}

}  // namespace

HeightAtlas::HeightAtlas(cv::Mat1f heights, cv::Mat1b valid, UvWrap wrap)
    : heights_(owned(std::move(heights))), valid_(owned(std::move(valid))), wrap_(wrap) {
  if (heights_.empty()) throw Error("HeightAtlas: empty height map");
  if (valid_.size() != heights_.size()) throw Error("HeightAtlas: mask and heights differ in size");
  // Non-finite heights are invalid before the islands are found, so they split islands.
  for (int r = 0; r < heights_.rows; ++r) {
    const float* h = heights_.ptr<float>(r);
    uchar* ok = valid_.ptr<uchar>(r);
    for (int c = 0; c < heights_.cols; ++c) {
      if (!std::isfinite(h[c])) ok[c] = 0;
    }
  }
  labels_ = findUvIslands(valid_).labels;
  finish();
}

HeightAtlas::HeightAtlas(cv::Mat1f heights, cv::Mat1b valid, cv::Mat1i island_labels, UvWrap wrap)
    : heights_(owned(std::move(heights))),
      valid_(owned(std::move(valid))),
      labels_(owned(std::move(island_labels))),
      wrap_(wrap) {
  if (heights_.empty()) throw Error("HeightAtlas: empty height map");
  if (valid_.size() != heights_.size() || labels_.size() != heights_.size()) {
    throw Error("HeightAtlas: heights, mask and island labels differ in size");
  }
  for (int r = 0; r < heights_.rows; ++r) {
    const uchar* ok = valid_.ptr<uchar>(r);
    const int* label = labels_.ptr<int>(r);
    for (int c = 0; c < heights_.cols; ++c) {
      if (label[c] < 0 || (label[c] != 0) != (ok[c] != 0)) {
        throw Error("HeightAtlas: island label " + std::to_string(label[c]) + " at texel (" +
                    std::to_string(r) + ", " + std::to_string(c) +
                    ") disagrees with the validity mask (labels must be > 0 exactly where valid)");
      }
    }
  }
  finish();
}

void HeightAtlas::finish() {
  island_count_ = 0;
  for (int r = 0; r < heights_.rows; ++r) {
    float* h = heights_.ptr<float>(r);
    uchar* ok = valid_.ptr<uchar>(r);
    int* label = labels_.ptr<int>(r);
    for (int c = 0; c < heights_.cols; ++c) {
      if (!std::isfinite(h[c])) ok[c] = 0;
      if (!ok[c]) {
        h[c] = 0.0f;
        label[c] = 0;
      }
      island_count_ = std::max(island_count_, label[c]);
    }
  }
  interior_.create(labels_.size());
  for (int r = 0; r < labels_.rows; ++r) {
    const int* row = labels_.ptr<int>(r);
    const int* next = labels_.ptr<int>((r + 1) % labels_.rows);
    uchar* out = interior_.ptr<uchar>(r);
    for (int c = 0; c < labels_.cols; ++c) {
      const int c1 = (c + 1) % labels_.cols;
      out[c] = row[c] != 0 && row[c1] == row[c] && next[c] == row[c] && next[c1] == row[c];
    }
  }
}
float HeightAtlas::sampleAcrossBorder(int x0, int y0, float fx, float fy, bool* valid) const {
  if (valid != nullptr) *valid = false;
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
