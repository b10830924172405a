#pragma once

#include <cmath>

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
  /// `heights` CV_32FC1, `valid` CV_8UC1 of the same size (non-zero = valid). Texels whose
  /// height is NaN or infinite are invalid, whatever `valid` says; invalid texels are 0. The
  /// islands are the 4-connected components of the valid texels. The atlas owns its data: a
  /// matrix still shared with the caller is copied (move it in to avoid the copy), so a later
  /// write by the caller never changes the atlas. Throws Error on empty or mismatched input.
  HeightAtlas(cv::Mat1f heights, cv::Mat1b valid, UvWrap wrap = UvWrap::kRepeat);
  /// As above with the islands given (the bake's, or a mesh's UV charts): `island_labels`
  /// CV_32SC1, 0 outside every island, 1..N inside; non-zero exactly on the valid texels.
  HeightAtlas(cv::Mat1f heights, cv::Mat1b valid, cv::Mat1i island_labels,
              UvWrap wrap = UvWrap::kRepeat);

  /// H_global at (u, v); `valid` (optional) tells whether any texel of an island was found.
  float sample(double u, double v, bool* valid = nullptr) const {
    if (heights_.empty() || !std::isfinite(u) || !std::isfinite(v)) {
      if (valid != nullptr) *valid = false;
      return 0.0f;
    }
    return sampleFinite(static_cast<float>(u), static_cast<float>(v), valid);
  }

  /// sample() for a non-empty atlas and finite u, v, in float: the renderer's per-pixel
  /// look-up (mesh UVs are checked to be finite when the mesh is built). Inline on purpose.
  float sampleFinite(float u, float v, bool* valid = nullptr) const {
    if (wrap_ == UvWrap::kRepeat) {
      u -= static_cast<float>(floorToInt(u));
      v -= static_cast<float>(floorToInt(v));
    } else {
      u = u < 0.0f ? 0.0f : (u > 1.0f ? 1.0f : u);
      v = v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
    }
    // Continuous texel coordinates with texel centres at integers; row 0 is v = 1.
    const float x = u * heights_.cols - 0.5f;
    const float y = (1.0f - v) * heights_.rows - 0.5f;
    const int x0 = floorToInt(x), y0 = floorToInt(y);
    const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
    // Fast path: the four texels are neighbours inside one island, away from the map's edge.
    if (x0 >= 0 && y0 >= 0 && x0 + 1 < heights_.cols && y0 + 1 < heights_.rows &&
        interior_(y0, x0)) {
      if (valid != nullptr) *valid = true;
      const float* top = heights_.ptr<float>(y0) + x0;
      const float* bottom = top + heights_.step1();
      return (1 - fy) * ((1 - fx) * top[0] + fx * top[1]) +
             fy * ((1 - fx) * bottom[0] + fx * bottom[1]);
    }
    return sampleAcrossBorder(x0, y0, fx, fy, valid);
  }

  /// sampleFinite() at `count` UVs (finite, as there): out[i] is bit for bit
  /// sampleFinite(uv[i]) where wanted[i] != 0, and 0 where it is 0 (not looked up). The
  /// overlay's per-row look-up for a whole contact: eight UVs a step with gathered texel pairs
  /// where the CPU has AVX2, else four with the arithmetic in SIMD lanes and scalar texel loads;
  /// look-ups across an island's border go one at a time. Needs a non-empty atlas.
  void sampleFiniteRow(const cv::Vec2f* uv, const unsigned char* wanted, int count,
                       float* out) const;

  /// Asks the CPU to start loading what sampleFiniteRow() reads at these UVs (every 8th one:
  /// neighbours share cache lines), without waiting. The overlay calls it a row ahead: a frame
  /// reads ~0.4 MB of an atlas scattered over 4+ MB, and with the texels still in memory each
  /// gather waits for them (the look-up took 425 instead of 252 us at 60 Hz).
  void prefetchRow(const cv::Vec2f* uv, int count) const;

  bool empty() const { return heights_.empty(); }
  int rows() const { return heights_.rows; }
  int cols() const { return heights_.cols; }
  const cv::Mat1f& heights() const { return heights_; }
  const cv::Mat1b& valid() const { return valid_; }
  /// 0 outside islands, 1..islandCount() inside.
  const cv::Mat1i& islandLabels() const { return labels_; }
  int islandCount() const { return island_count_; }
  UvWrap wrap() const { return wrap_; }
  void setWrap(UvWrap wrap) { wrap_ = wrap; }

  /// The heights with NaN at the invalid texels (H_global's float TIFF form, whose NaN
  /// `norm2tex_render --atlas` reads back as invalid), taken out of the atlas without a copy
  /// (a copy would be 64 MB of fresh memory at 4096^2); the atlas is empty afterwards.
  cv::Mat1f takeHeightsInvalidAsNaN() &&;

 private:
  /// `index` in [-1, size]: one texel off either edge at most.
  int wrapIndex(int index, int size) const {
    if (index < 0) return wrap_ == UvWrap::kClamp ? 0 : size - 1;
    if (index >= size) return wrap_ == UvWrap::kClamp ? size - 1 : 0;
    return index;
  }
  /// floor() without a libm call (baseline x86-64 has no rounding instruction); |x| < 2^31.
  static int floorToInt(float x) {
    const int truncated = static_cast<int>(x);
    return truncated - (x < static_cast<float>(truncated) ? 1 : 0);
  }
  /// Bilinear look-up near an island's border or the map's edge (x0, y0 in [-1, size - 1]).
  float sampleAcrossBorder(int x0, int y0, float fx, float fy, bool* valid) const;
  /// Checks sizes, masks non-finite heights, zeroes invalid texels, builds interior_.
  void finish();

  cv::Mat1f heights_;
  cv::Mat1b valid_;
  cv::Mat1i labels_;
  /// 1 where texel (r, c) and its right, lower and lower-right neighbours are all in one
  /// island: there a look-up is a plain bilinear blend, the common case.
  cv::Mat1b interior_;
  /// interior_ is 1 everywhere (one island filling the map: a tiling material's texture), so
  /// look-ups need not read it.
  bool all_interior_ = false;
  int island_count_ = 0;
  UvWrap wrap_ = UvWrap::kRepeat;
};

}  // namespace norm2tex
