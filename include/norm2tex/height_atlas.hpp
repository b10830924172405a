#pragma once

#include <opencv2/core.hpp>

namespace norm2tex {

/// What a UV outside [0, 1] means, as in OpenGL's texture wrap modes.
enum class UvWrap {
  kRepeat,  ///< tile: u and u + 1 are the same point (GL_REPEAT)
  kClamp,   ///< clamp to the edge texel (GL_CLAMP_TO_EDGE)
};

/// H_global: the baked pseudo-height map of a texture, with its validity mask and UV islands.
///
/// UV convention (OpenGL / glTF / OBJ): u runs along image columns left to right; v runs along
/// image rows *bottom to top*, so image row 0 is v = 1. Texel (row r, column c) has its centre
/// at u = (c + 0.5) / cols, v = 1 - (r + 0.5) / rows.
///
/// Sampling is bilinear between the four texels around (u, v), using only texels of the same
/// UV island as the nearest valid one: an island's border never blends with the invalid gap
/// (zeros) or a neighbouring island. A look-up whose four texels are all invalid reports
/// "not valid" and returns 0.
class HeightAtlas {
 public:
  HeightAtlas() = default;
  /// `heights` CV_32FC1, `valid` CV_8UC1 of the same size (non-zero = valid). Invalid texels
  /// of `heights` are set to 0. Throws Error on empty or mismatched input.
  HeightAtlas(cv::Mat1f heights, cv::Mat1b valid, UvWrap wrap = UvWrap::kRepeat);

  /// H_global at (u, v); `valid` (optional) tells whether any texel of an island was found.
  float sample(double u, double v, bool* valid = nullptr) const;

  bool empty() const { return heights_.empty(); }
  int rows() const { return heights_.rows; }
  int cols() const { return heights_.cols; }
  const cv::Mat1f& heights() const { return heights_; }
  const cv::Mat1b& valid() const { return valid_; }
  /// 0 outside islands, 1..islandCount() inside (4-connected, see findUvIslands).
  const cv::Mat1i& islandLabels() const { return labels_; }
  int islandCount() const { return island_count_; }
  UvWrap wrap() const { return wrap_; }
  void setWrap(UvWrap wrap) { wrap_ = wrap; }

 private:
  int wrapIndex(int index, int size) const;

  cv::Mat1f heights_;
  cv::Mat1b valid_;
  cv::Mat1i labels_;
  int island_count_ = 0;
  UvWrap wrap_ = UvWrap::kRepeat;
};

}  // namespace norm2tex
