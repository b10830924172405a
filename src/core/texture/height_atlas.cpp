#include "norm2tex/texture/height_atlas.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include <opencv2/core/hal/intrin.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/common/huge_pages.hpp"
#include "norm2tex/common/simd_dispatch.hpp"
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

#if NORM2TEX_HAS_AVX2_BUILD
/// a0 b0 a1 b1 a2 b2 a3 b3 | a4 b4 ... a7 b7 (as two vectors, low then high) -> a0 ... a7: the
/// shuffle works within 128-bit halves, the permute puts the halves' pairs in order.
NORM2TEX_TARGET_AVX2 inline __m256 deinterleaveEven(__m256 low, __m256 high) {
  return _mm256_castpd_ps(_mm256_permute4x64_pd(
      _mm256_castps_pd(_mm256_shuffle_ps(low, high, _MM_SHUFFLE(2, 0, 2, 0))), 0xd8));
}
/// ... -> b0 ... b7.
NORM2TEX_TARGET_AVX2 inline __m256 deinterleaveOdd(__m256 low, __m256 high) {
  return _mm256_castpd_ps(_mm256_permute4x64_pd(
      _mm256_castps_pd(_mm256_shuffle_ps(low, high, _MM_SHUFFLE(3, 1, 3, 1))), 0xd8));
}

/// What the eight-lane look-up reads of an atlas.
struct AtlasTexels {
  const float* heights;
  int heights_step;  // floats per row
  const unsigned char* interior;
  int interior_step;  // bytes per row
  int cols, rows;
  bool repeat;
};

/// HeightAtlas::sampleFiniteRow eight UVs a step, texels gathered: the same operations in the
/// same order as sampleFinite(), so the same floats. Lanes whose four texels are not one
/// island's interior neighbours are listed in `slow` (for sampleFinite); unwanted lanes get 0.
/// Returns the number of UVs done (a multiple of 8). kAllInterior: every texel is an interior
/// one (atlas.interior unused), so no flag is gathered: a quarter fewer cache lines to load.
template <bool kAllInterior>
NORM2TEX_TARGET_AVX2 int sampleInteriorLanesAvx2(const AtlasTexels& atlas, const cv::Vec2f* uv,
                                                 const unsigned char* wanted, int count, float* out,
                                                 int* slow, int& slow_count) {
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
  const __m256 half = _mm256_set1_ps(0.5f);
  const __m256 cols = _mm256_set1_ps(static_cast<float>(atlas.cols));
  const __m256 rows = _mm256_set1_ps(static_cast<float>(atlas.rows));
  const __m256i last_x0 = _mm256_set1_epi32(atlas.cols - 2),
                last_y0 = _mm256_set1_epi32(atlas.rows - 2);
  const __m256i zero_int = _mm256_setzero_si256(), byte = _mm256_set1_epi32(0xff);
  const __m256i heights_step = _mm256_set1_epi32(atlas.heights_step);
  const __m256i interior_step = _mm256_set1_epi32(atlas.interior_step);
  const float* below = atlas.heights + atlas.heights_step;
  int i = 0;
  for (; i + 8 <= count; i += 8) {
    const __m256 first = _mm256_loadu_ps(reinterpret_cast<const float*>(uv + i));
    const __m256 second = _mm256_loadu_ps(reinterpret_cast<const float*>(uv + i + 4));
    __m256 u = deinterleaveEven(first, second), v = deinterleaveOdd(first, second);
    if (atlas.repeat) {
      u = _mm256_sub_ps(u, _mm256_floor_ps(u));
      v = _mm256_sub_ps(v, _mm256_floor_ps(v));
    } else {
      u = _mm256_min_ps(_mm256_max_ps(u, zero), one);
      v = _mm256_min_ps(_mm256_max_ps(v, zero), one);
    }
    const __m256 x = _mm256_sub_ps(_mm256_mul_ps(u, cols), half);
    const __m256 y = _mm256_sub_ps(_mm256_mul_ps(_mm256_sub_ps(one, v), rows), half);
    const __m256 x_floor = _mm256_floor_ps(x), y_floor = _mm256_floor_ps(y);
    const __m256i x0 = _mm256_cvttps_epi32(x_floor), y0 = _mm256_cvttps_epi32(y_floor);
    const __m256 fx = _mm256_sub_ps(x, x_floor), fy = _mm256_sub_ps(y, y_floor);
    const __m256i want = _mm256_cmpgt_epi32(
        _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(wanted + i))),
        _mm256_setzero_si256());
    // 0 <= x0 <= cols - 2 and 0 <= y0 <= rows - 2.
    const __m256i inside = _mm256_andnot_si256(
        _mm256_or_si256(
            _mm256_or_si256(_mm256_cmpgt_epi32(zero_int, x0), _mm256_cmpgt_epi32(x0, last_x0)),
            _mm256_or_si256(_mm256_cmpgt_epi32(zero_int, y0), _mm256_cmpgt_epi32(y0, last_y0))),
        want);
    __m256i fast = inside;
    if (!kAllInterior) {
      // The interior flag: a byte, gathered as 32 bits (in bounds: a whole row follows it).
      const __m256i flag_index = _mm256_add_epi32(_mm256_mullo_epi32(y0, interior_step), x0);
      const __m256i flags =
          _mm256_and_si256(_mm256_mask_i32gather_epi32(_mm256_setzero_si256(),
                                                       reinterpret_cast<const int*>(atlas.interior),
                                                       flag_index, inside, 1),
                           byte);
      fast = _mm256_andnot_si256(_mm256_cmpeq_epi32(flags, _mm256_setzero_si256()), inside);
    }
    const __m256 fast_mask = _mm256_castsi256_ps(fast);
    // Each lane's two neighbours in a row are one 64-bit load: four gathers of four pairs.
    const __m256i index = _mm256_add_epi32(_mm256_mullo_epi32(y0, heights_step), x0);
    const __m128i index_low = _mm256_castsi256_si128(index);
    const __m128i index_high = _mm256_extracti128_si256(index, 1);
    const __m256i mask_low = _mm256_cvtepi32_epi64(_mm256_castsi256_si128(fast));
    const __m256i mask_high = _mm256_cvtepi32_epi64(_mm256_extracti128_si256(fast, 1));
    const auto* top = reinterpret_cast<const long long*>(atlas.heights);
    const auto* bottom = reinterpret_cast<const long long*>(below);
    const __m256i none = _mm256_setzero_si256();
    const __m256 top_low =
        _mm256_castsi256_ps(_mm256_mask_i32gather_epi64(none, top, index_low, mask_low, 4));
    const __m256 top_high =
        _mm256_castsi256_ps(_mm256_mask_i32gather_epi64(none, top, index_high, mask_high, 4));
    const __m256 bottom_low =
        _mm256_castsi256_ps(_mm256_mask_i32gather_epi64(none, bottom, index_low, mask_low, 4));
    const __m256 bottom_high =
        _mm256_castsi256_ps(_mm256_mask_i32gather_epi64(none, bottom, index_high, mask_high, 4));
    const __m256 t00 = deinterleaveEven(top_low, top_high);
    const __m256 t01 = deinterleaveOdd(top_low, top_high);
    const __m256 t10 = deinterleaveEven(bottom_low, bottom_high);
    const __m256 t11 = deinterleaveOdd(bottom_low, bottom_high);
    const __m256 gx = _mm256_sub_ps(one, fx), gy = _mm256_sub_ps(one, fy);
    const __m256 result = _mm256_add_ps(
        _mm256_mul_ps(gy, _mm256_add_ps(_mm256_mul_ps(gx, t00), _mm256_mul_ps(fx, t01))),
        _mm256_mul_ps(fy, _mm256_add_ps(_mm256_mul_ps(gx, t10), _mm256_mul_ps(fx, t11))));
    _mm256_storeu_ps(out + i, _mm256_and_ps(result, fast_mask));
    unsigned pending = static_cast<unsigned>(
        _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_andnot_si256(fast, want))));
    while (pending != 0) {
      slow[slow_count++] = i + __builtin_ctz(pending);
      pending &= pending - 1;
    }
  }
  return i;
}
#endif
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

cv::Mat1f HeightAtlas::takeHeightsInvalidAsNaN() && {
  cv::Mat1f heights = std::move(heights_);
  heights.setTo(std::numeric_limits<float>::quiet_NaN(), valid_ == 0);
  *this = HeightAtlas();
  return heights;
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
  createWithHugePages(interior_, labels_.rows, labels_.cols);  // see huge_pages.hpp
  for (int r = 0; r < labels_.rows; ++r) {
    const int* row = labels_.ptr<int>(r);
    const int* next = labels_.ptr<int>((r + 1) % labels_.rows);
    uchar* out = interior_.ptr<uchar>(r);
    const int last = labels_.cols - 1;  // its right neighbour wraps to column 0
    for (int c = 0; c < last; ++c) {
      out[c] = row[c] != 0 && row[c + 1] == row[c] && next[c] == row[c] && next[c + 1] == row[c];
    }
    out[last] =
        row[last] != 0 && row[0] == row[last] && next[last] == row[last] && next[0] == row[last];
  }
  all_interior_ = cv::countNonZero(interior_) == static_cast<int>(interior_.total());
}
void HeightAtlas::sampleFiniteRow(const cv::Vec2f* uv, const unsigned char* wanted, int count,
                                  float* out) const {
  using cv::v_float32x4;
  using cv::v_int32x4;
  const v_float32x4 zero = cv::v_setzero_f32(), one = cv::v_setall_f32(1.0f);
  const v_float32x4 half = cv::v_setall_f32(0.5f);
  const v_float32x4 cols = cv::v_setall_f32(static_cast<float>(heights_.cols));
  const v_float32x4 rows = cv::v_setall_f32(static_cast<float>(heights_.rows));
  const bool repeat = wrap_ == UvWrap::kRepeat;
  const std::size_t row_step = heights_.step1();
  alignas(16) int x0[4], y0[4];
  alignas(16) float fx[4], fy[4];
  float t00[4], t01[4], t10[4], t11[4];
  int i = 0;
#if NORM2TEX_HAS_AVX2_BUILD
  static const bool avx2 = cpuHasAvx2();
  if (avx2) {
    const AtlasTexels texels{heights_.ptr<float>(),
                             static_cast<int>(row_step),
                             interior_.ptr<unsigned char>(),
                             static_cast<int>(interior_.step1()),
                             heights_.cols,
                             heights_.rows,
                             repeat};
    thread_local std::vector<int> slow;
    slow.resize(static_cast<std::size_t>(count));
    int slow_count = 0;
    i = all_interior_
            ? sampleInteriorLanesAvx2<true>(texels, uv, wanted, count, out, slow.data(), slow_count)
            : sampleInteriorLanesAvx2<false>(texels, uv, wanted, count, out, slow.data(),
                                             slow_count);
    for (int k = 0; k < slow_count; ++k) {
      out[slow[k]] = sampleFinite(uv[slow[k]][0], uv[slow[k]][1]);
    }
  }
#endif
  for (; i + 4 <= count; i += 4) {
    v_float32x4 u, v;
    cv::v_load_deinterleave(reinterpret_cast<const float*>(uv + i), u, v);
    // The same operations in the same order as sampleFinite(), so the results are equal.
    if (repeat) {
      u = u - cv::v_cvt_f32(cv::v_floor(u));
      v = v - cv::v_cvt_f32(cv::v_floor(v));
    } else {
      u = cv::v_min(cv::v_max(u, zero), one);
      v = cv::v_min(cv::v_max(v, zero), one);
    }
    const v_float32x4 x = u * cols - half;
    const v_float32x4 y = (one - v) * rows - half;
    const v_int32x4 xi = cv::v_floor(x), yi = cv::v_floor(y);
    cv::v_store(x0, xi);
    cv::v_store(y0, yi);
    const v_float32x4 wx = x - cv::v_cvt_f32(xi), wy = y - cv::v_cvt_f32(yi);
    cv::v_store(fx, wx);
    cv::v_store(fy, wy);
    unsigned slow = 0;  // lanes off the fast path: bit k
    for (int k = 0; k < 4; ++k) {
      if (wanted[i + k] && x0[k] >= 0 && y0[k] >= 0 && x0[k] + 1 < heights_.cols &&
          y0[k] + 1 < heights_.rows && interior_(y0[k], x0[k])) {
        const float* top = heights_.ptr<float>(y0[k]) + x0[k];
        t00[k] = top[0];
        t01[k] = top[1];
        t10[k] = top[row_step];
        t11[k] = top[row_step + 1];
      } else {
        t00[k] = t01[k] = t10[k] = t11[k] = 0.0f;
        slow |= 1u << k;
      }
    }
    // Built from the scalars, not loaded from the arrays just written (a vector load of four
    // scalar stores stalls on store forwarding).
    const auto lanes = [](const float* t) { return v_float32x4(t[0], t[1], t[2], t[3]); };
    const v_float32x4 result = (one - wy) * ((one - wx) * lanes(t00) + wx * lanes(t01)) +
                               wy * ((one - wx) * lanes(t10) + wx * lanes(t11));
    cv::v_store(out + i, result);
    for (int k = 0; slow != 0; ++k, slow >>= 1) {
      if (slow & 1u) {
        out[i + k] = wanted[i + k] ? sampleAcrossBorder(x0[k], y0[k], fx[k], fy[k], nullptr) : 0.0f;
      }
    }
  }
  for (; i < count; ++i) out[i] = wanted[i] ? sampleFinite(uv[i][0], uv[i][1]) : 0.0f;
}

void HeightAtlas::prefetchRow(const cv::Vec2f* uv, int count) const {
  if (heights_.cols < 2 || heights_.rows < 2) return;  // nothing worth it, and no clamp range
  const bool repeat = wrap_ == UvWrap::kRepeat;
  for (int i = 0; i < count; i += 8) {
    float u = uv[i][0], v = uv[i][1];
    if (!std::isfinite(u) || !std::isfinite(v)) continue;
    if (repeat) {
      u -= std::floor(u);
      v -= std::floor(v);
    }
    const int x0 = std::clamp(static_cast<int>(u * heights_.cols), 0, heights_.cols - 2);
    const int y0 = std::clamp(static_cast<int>((1.0f - v) * heights_.rows), 0, heights_.rows - 2);
    const float* top = heights_.ptr<float>(y0) + x0;
    __builtin_prefetch(top);
    __builtin_prefetch(top + heights_.step1());
    if (!all_interior_) __builtin_prefetch(interior_.ptr<unsigned char>(y0) + x0);
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
