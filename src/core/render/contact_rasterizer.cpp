#include "norm2tex/render/contact_rasterizer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "norm2tex/common/error.hpp"
#include "norm2tex/common/simd_dispatch.hpp"

namespace norm2tex {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

bool isFinite(const Eigen::Isometry3d& pose) { return pose.matrix().allFinite(); }

/// (Re)allocates the raster for `size`; otherwise clears only what the last frame touched.
void resetRaster(cv::Size size, bool want_uv, ContactRaster& out) {
  if (out.gap_mm.size() != size) {
    out.gap_mm.create(size);
    out.face.create(size);
    out.h_sensor_mm.create(size);
    out.gap_mm.setTo(kInfinity);
    out.face.setTo(-1);
    out.h_sensor_mm.setTo(0.0f);
    out.uv.release();
    out.covered_box = cv::Rect();
  } else if (!out.covered_box.empty()) {
    out.gap_mm(out.covered_box).setTo(kInfinity);
    out.face(out.covered_box).setTo(-1);
    out.h_sensor_mm(out.covered_box).setTo(0.0f);
  }
  if (want_uv) {
    if (out.uv.size() != size) {
      out.uv.create(size);
      out.uv.setTo(cv::Vec2f(0, 0));
    } else if (!out.covered_box.empty()) {
      out.uv(out.covered_box).setTo(cv::Vec2f(0, 0));
    }
  }
  out.covered_box = cv::Rect();
  out.triangles_rasterized = 0;
  out.pixel_hits = 0;
}

/// A triangle in continuous pixel coordinates (centres at integers), with its heights (mm)
/// and UVs at the corners.
struct ProjectedTriangle {
  float x[3], y[3], z[3];
  Eigen::Vector2f uv[3];
};

struct CoveredBox {
  int min_r, max_r, min_c, max_c;
};

/// Fixed point with 8 fractional bits: 1/256 pixel, as GPUs snap.
constexpr double kSubpixel = 256.0;
constexpr double kMaxFixedPixels = double(1 << 22);  // |products| < 2^62: no int64 overflow

/// Edge v_i -> v_j of a triangle with positive area (y down): the interior is where
/// E(p) = (x_j - x_i)(p_y - y_i) - (y_j - y_i)(p_x - x_i) > 0. A centre with E = 0 belongs to
/// the triangle when the edge is a top edge (horizontal, dx > 0) or a left edge (dy < 0): the
/// rule flips with the edge's direction, and a shared edge runs opposite ways in its two
/// triangles, so exactly one of them owns the centre.
template <typename T>
struct Edge {
  T dx, dy, x0, y0;
  bool owns_boundary;
  Edge(T xi, T yi, T xj, T yj)
      : dx(xj - xi), dy(yj - yi), x0(xi), y0(yi), owns_boundary(dy < 0 || (dy == 0 && dx > 0)) {}
  T at(T px, T py) const { return dx * (py - y0) - dy * (px - x0); }
  bool inside(T value) const { return value > 0 || (value == 0 && owns_boundary); }
};

struct PixelRange {
  int c_begin, c_end, r_begin, r_end;
};

template <typename T>
bool fillTriangle(const T* x, const T* y, T one_pixel, const ProjectedTriangle& triangle, int face,
                  float reach, bool want_uv, const PixelRange& range,
                  const cv::Mat1f& gel_surface_mm, ContactRaster& out, CoveredBox& covered);

/// One row's span of a wide triangle: its edge functions (exact integers, held in doubles, see
/// fillTriangle) at the span's first column and their steps per column, and what is written.
struct Span {
  double e0, e1, step0, step1, inverse_area;
  float z[3], u[3], v[3];
  float reach;
  int face;
};

/// Depth test and writes over columns [begin, n) of a span where every pixel centre is inside
/// the triangle, one pixel at a time: the same operations in the same order as the per-pixel
/// loop of fillTriangle. Widens [lo, hi] to the written columns.
template <bool kUv>
NORM2TEX_ALWAYS_INLINE void fillSpanScalar(int begin, int n, const Span& s, const float* gel,
                                           float* gap_row, int* face_row, float* uv_row, int& lo,
                                           int& hi) {
  for (int i = begin; i < n; ++i) {
    const double k = static_cast<double>(i);
    const float w0 = static_cast<float>((s.e0 + k * s.step0) * s.inverse_area);
    const float w1 = static_cast<float>((s.e1 + k * s.step1) * s.inverse_area);
    const float w2 = 1.0f - w0 - w1;
    const float gap = w0 * s.z[0] + w1 * s.z[1] + w2 * s.z[2] - gel[i];
    if (gap >= gap_row[i] || gap > s.reach) continue;
    gap_row[i] = gap;
    face_row[i] = s.face;
    if constexpr (kUv) {
      uv_row[2 * i] = w0 * s.u[0] + w1 * s.u[1] + w2 * s.u[2];
      uv_row[2 * i + 1] = w0 * s.v[0] + w1 * s.v[1] + w2 * s.v[2];
    }
    lo = std::min(lo, i);
    hi = std::max(hi, i);
  }
}

using FillSpan = void (*)(int, const Span&, const float*, float*, int*, float*, int&, int&);

void fillSpanBaseline(int n, const Span& s, const float* gel, float* gap_row, int* face_row,
                      float* uv_row, int& lo, int& hi) {
  if (uv_row != nullptr) {
    fillSpanScalar<true>(0, n, s, gel, gap_row, face_row, uv_row, lo, hi);
  } else {
    fillSpanScalar<false>(0, n, s, gel, gap_row, face_row, uv_row, lo, hi);
  }
}

#if NORM2TEX_HAS_AVX2_BUILD
/// Eight columns' barycentric weight: (e + k step) / area in doubles, rounded to float.
NORM2TEX_TARGET_AVX2 inline __m256 spanWeight(__m256d e, __m256d step, __m256d k_low,
                                              __m256d k_high, __m256d inverse_area) {
  const __m128 low =
      _mm256_cvtpd_ps(_mm256_mul_pd(_mm256_add_pd(e, _mm256_mul_pd(k_low, step)), inverse_area));
  const __m128 high =
      _mm256_cvtpd_ps(_mm256_mul_pd(_mm256_add_pd(e, _mm256_mul_pd(k_high, step)), inverse_area));
  return _mm256_set_m128(high, low);
}

/// w0 c0 + w1 c1 + w2 c2, in that order.
NORM2TEX_TARGET_AVX2 inline __m256 spanInterpolate(__m256 w0, __m256 w1, __m256 w2,
                                                   const float* corner) {
  return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(w0, _mm256_set1_ps(corner[0])),
                                     _mm256_mul_ps(w1, _mm256_set1_ps(corner[1]))),
                       _mm256_mul_ps(w2, _mm256_set1_ps(corner[2])));
}

/// fillSpanScalar, eight pixels a step (the compiler does not vectorise the depth test's
/// selective writes by itself). Identical floats: the same operations in the same order, each
/// correctly rounded, and no FMA.
template <bool kUv>
NORM2TEX_TARGET_AVX2 void fillSpanAvx2Body(int n, const Span& s, const float* gel, float* gap_row,
                                           int* face_row, float* uv_row, int& lo, int& hi) {
  const __m256d e0 = _mm256_set1_pd(s.e0), e1 = _mm256_set1_pd(s.e1);
  const __m256d step0 = _mm256_set1_pd(s.step0), step1 = _mm256_set1_pd(s.step1);
  const __m256d inverse_area = _mm256_set1_pd(s.inverse_area);
  const __m256d lanes_low = _mm256_setr_pd(0, 1, 2, 3), lanes_high = _mm256_setr_pd(4, 5, 6, 7);
  const __m256 one = _mm256_set1_ps(1.0f), reach = _mm256_set1_ps(s.reach);
  const __m256 z0 = _mm256_set1_ps(s.z[0]), z1 = _mm256_set1_ps(s.z[1]),
               z2 = _mm256_set1_ps(s.z[2]);
  const __m256 face = _mm256_castsi256_ps(_mm256_set1_epi32(s.face));
  int i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m256d first = _mm256_set1_pd(static_cast<double>(i));
    const __m256d k_low = _mm256_add_pd(first, lanes_low),
                  k_high = _mm256_add_pd(first, lanes_high);
    const __m256 w0 = spanWeight(e0, step0, k_low, k_high, inverse_area);
    const __m256 w1 = spanWeight(e1, step1, k_low, k_high, inverse_area);
    const __m256 w2 = _mm256_sub_ps(_mm256_sub_ps(one, w0), w1);
    const __m256 gap =
        _mm256_sub_ps(_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(w0, z0), _mm256_mul_ps(w1, z1)),
                                    _mm256_mul_ps(w2, z2)),
                      _mm256_loadu_ps(gel + i));
    const __m256 old_gap = _mm256_loadu_ps(gap_row + i);
    // Kept where the scalar loop skips: gap >= old gap, or gap > reach.
    const __m256 keep = _mm256_or_ps(_mm256_cmp_ps(gap, old_gap, _CMP_GE_OQ),
                                     _mm256_cmp_ps(gap, reach, _CMP_GT_OQ));
    const int written = ~_mm256_movemask_ps(keep) & 0xff;
    if (written == 0) continue;
    _mm256_storeu_ps(gap_row + i, _mm256_blendv_ps(gap, old_gap, keep));
    float* face_out = reinterpret_cast<float*>(face_row + i);
    _mm256_storeu_ps(face_out, _mm256_blendv_ps(face, _mm256_loadu_ps(face_out), keep));
    if constexpr (kUv) {
      const __m256 u = spanInterpolate(w0, w1, w2, s.u), v = spanInterpolate(w0, w1, w2, s.v);
      // Interleave to u0 v0 u1 v1 ...: unpack works within 128-bit halves, the permutes
      // put the halves in order.
      const __m256 mixed_low = _mm256_unpacklo_ps(u, v), mixed_high = _mm256_unpackhi_ps(u, v);
      const __m256 keep_low = _mm256_unpacklo_ps(keep, keep);
      const __m256 keep_high = _mm256_unpackhi_ps(keep, keep);
      const __m256 uv_first = _mm256_permute2f128_ps(mixed_low, mixed_high, 0x20);
      const __m256 uv_second = _mm256_permute2f128_ps(mixed_low, mixed_high, 0x31);
      const __m256 keep_first = _mm256_permute2f128_ps(keep_low, keep_high, 0x20);
      const __m256 keep_second = _mm256_permute2f128_ps(keep_low, keep_high, 0x31);
      float* uv_out = uv_row + 2 * i;
      _mm256_storeu_ps(uv_out, _mm256_blendv_ps(uv_first, _mm256_loadu_ps(uv_out), keep_first));
      _mm256_storeu_ps(uv_out + 8,
                       _mm256_blendv_ps(uv_second, _mm256_loadu_ps(uv_out + 8), keep_second));
    }
    lo = std::min(lo, i + __builtin_ctz(static_cast<unsigned>(written)));
    hi = std::max(hi, i + 31 - __builtin_clz(static_cast<unsigned>(written)));
  }
  fillSpanScalar<kUv>(i, n, s, gel, gap_row, face_row, uv_row, lo, hi);
}

NORM2TEX_TARGET_AVX2 void fillSpanAvx2(int n, const Span& s, const float* gel, float* gap_row,
                                       int* face_row, float* uv_row, int& lo, int& hi) {
  if (uv_row != nullptr) {
    fillSpanAvx2Body<true>(n, s, gel, gap_row, face_row, uv_row, lo, hi);
  } else {
    fillSpanAvx2Body<false>(n, s, gel, gap_row, face_row, uv_row, lo, hi);
  }
}
const FillSpan fillSpan = pickSimd<FillSpan>(fillSpanAvx2, fillSpanBaseline);
#else
const FillSpan fillSpan = fillSpanBaseline;
#endif

/// Integers below this are exact in a double, and so are their sums below 2^53.
constexpr double kExactInDouble = 4503599627370496.0;  // 2^52

/// Smallest integer >= value / unit (unit > 0), for integers and doubles alike.
std::int64_t ceilDiv(std::int64_t value, std::int64_t unit) {
  return value >= 0 ? (value + unit - 1) / unit : -((-value) / unit);
}
std::int64_t floorDiv(std::int64_t value, std::int64_t unit) {
  return value >= 0 ? value / unit : -((-value + unit - 1) / unit);
}
std::int64_t ceilDiv(double value, double unit) {
  return static_cast<std::int64_t>(std::ceil(value / unit));
}
std::int64_t floorDiv(double value, double unit) {
  return static_cast<std::int64_t>(std::floor(value / unit));
}

/// The pixel centres inside the (snapped) corners' bounding box, clipped to the image.
template <typename T>
bool pixelRange(const T* x, const T* y, T one_pixel, cv::Size image, PixelRange& range) {
  range.c_begin =
      static_cast<int>(std::max<std::int64_t>(0, ceilDiv(std::min({x[0], x[1], x[2]}), one_pixel)));
  range.c_end = static_cast<int>(
      std::min<std::int64_t>(image.width - 1, floorDiv(std::max({x[0], x[1], x[2]}), one_pixel)));
  range.r_begin =
      static_cast<int>(std::max<std::int64_t>(0, ceilDiv(std::min({y[0], y[1], y[2]}), one_pixel)));
  range.r_end = static_cast<int>(
      std::min<std::int64_t>(image.height - 1, floorDiv(std::max({y[0], y[1], y[2]}), one_pixel)));
  return range.c_begin <= range.c_end && range.r_begin <= range.r_end;
}

/// Depth-tests and writes the pixels whose centres the triangle covers. False when it covers
/// no pixel range at all (off the image or of zero area).
bool drawTriangle(const ProjectedTriangle& triangle, int face, float reach, bool want_uv,
                  const cv::Mat1f& gel_surface_mm, ContactRaster& out, CoveredBox& covered) {
  const float* x = triangle.x;
  const float* y = triangle.y;
  // Quick rejection with a pixel of margin (snapping moves corners by 1/512 pixel at most).
  const float min_x = std::min({x[0], x[1], x[2]}), max_x = std::max({x[0], x[1], x[2]});
  const float min_y = std::min({y[0], y[1], y[2]}), max_y = std::max({y[0], y[1], y[2]});
  if (max_x < -1.0f || max_y < -1.0f || min_x > gel_surface_mm.cols ||
      min_y > gel_surface_mm.rows) {
    return false;
  }
  const bool fixed_point = std::max({std::fabs(min_x), std::fabs(max_x), std::fabs(min_y),
                                     std::fabs(max_y)}) < kMaxFixedPixels;
  PixelRange range;
  if (fixed_point) {
    std::int64_t fx[3], fy[3];
    for (int k = 0; k < 3; ++k) {
      fx[k] = std::llround(x[k] * kSubpixel);
      fy[k] = std::llround(y[k] * kSubpixel);
    }
    const auto one = static_cast<std::int64_t>(kSubpixel);
    if (!pixelRange<std::int64_t>(fx, fy, one, gel_surface_mm.size(), range)) return false;
    return fillTriangle<std::int64_t>(fx, fy, one, triangle, face, reach, want_uv, range,
                                      gel_surface_mm, out, covered);
  }
  double dx[3], dy[3];
  for (int k = 0; k < 3; ++k) {
    dx[k] = x[k];
    dy[k] = y[k];
  }
  if (!pixelRange<double>(dx, dy, 1.0, gel_surface_mm.size(), range)) return false;
  return fillTriangle<double>(dx, dy, 1.0, triangle, face, reach, want_uv, range, gel_surface_mm,
                              out, covered);
}

template <typename T>
bool fillTriangle(const T* x, const T* y, T one_pixel, const ProjectedTriangle& triangle, int face,
                  float reach, bool want_uv, const PixelRange& range,
                  const cv::Mat1f& gel_surface_mm, ContactRaster& out, CoveredBox& covered) {
  // Orient to positive area; a triangle of zero area covers no centre.
  int order[3] = {0, 1, 2};
  T area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
  if (area == 0) return false;
  if (area < 0) {
    std::swap(order[1], order[2]);
    area = -area;
  }
  const int i0 = order[0], i1 = order[1], i2 = order[2];
  // Edge k is opposite corner k: its function is corner k's barycentric weight times the area.
  const Edge<T> edges[3] = {Edge<T>(x[i1], y[i1], x[i2], y[i2]),
                            Edge<T>(x[i2], y[i2], x[i0], y[i0]),
                            Edge<T>(x[i0], y[i0], x[i1], y[i1])};
  const float z[3] = {triangle.z[i0], triangle.z[i1], triangle.z[i2]};
  const Eigen::Vector2f uv[3] = {triangle.uv[i0], triangle.uv[i1], triangle.uv[i2]};
  const double inverse_area = 1.0 / static_cast<double>(area);
  // Wide triangles get each row's span in closed form (three integer divisions per row, then no
  // test per pixel); narrow ones, a few pixels a row (a fine mesh), are cheaper tested per
  // pixel. Doubles (corners beyond the fixed-point range) are always tested per pixel.
  constexpr int kMinSpanColumns = 12;
  const bool test_each_pixel =
      !std::is_integral_v<T> || range.c_end - range.c_begin + 1 < kMinSpanColumns;
  for (int r = range.r_begin; r <= range.r_end; ++r) {
    float* gap_row = out.gap_mm.ptr<float>(r);
    int* face_row = out.face.ptr<int>(r);
    const float* gel_row = gel_surface_mm.ptr<float>(r);
    cv::Vec2f* uv_row = want_uv ? out.uv.ptr<cv::Vec2f>(r) : nullptr;
    const T py = static_cast<T>(r) * one_pixel;
    // Edge functions step by -dy per column: exact in integers.
    T e[3], step[3];
    for (int k = 0; k < 3; ++k) {
      e[k] = edges[k].at(static_cast<T>(range.c_begin) * one_pixel, py);
      step[k] = -edges[k].dy * one_pixel;
    }
    int c_first = range.c_begin, c_last = range.c_end;
    if (!test_each_pixel) {
      // The row's covered columns in closed form, exactly those the per-pixel test accepts: each
      // edge function is linear in the column, so it bounds the span from one side.
      for (int k = 0; k < 3 && c_first <= c_last; ++k) {
        const T e0 = e[k], s = step[k];
        const bool owns = edges[k].owns_boundary;
        if (s == 0) {
          if (!edges[k].inside(e0)) c_first = c_last + 1;
        } else if (s > 0) {  // inside from some column on
          const T n = edges[k].inside(e0) ? 0 : owns ? ceilDiv(-e0, s) : floorDiv(-e0, s) + 1;
          c_first = static_cast<int>(
              std::min<T>(std::max<T>(c_first, range.c_begin + n), static_cast<T>(c_last) + 1));
        } else {  // inside up to some column
          const T n = owns ? floorDiv(e0, -s) : ceilDiv(e0, -s) - 1;
          c_last = static_cast<int>(
              std::max<T>(std::min<T>(c_last, range.c_begin + n), static_cast<T>(c_first) - 1));
        }
      }
      if (c_first > c_last) continue;
      for (int k = 0; k < 3; ++k) e[k] += static_cast<T>(c_first - range.c_begin) * step[k];
      // Every centre of the span is inside: the vectorised span fill, when the edge functions
      // along it stay exact in doubles (always, short of corners millions of pixels away).
      const int n = c_last - c_first + 1;
      const auto exact = [n](T e_k, T s_k) {
        return std::abs(static_cast<double>(e_k)) < kExactInDouble &&
               std::abs(static_cast<double>(s_k)) * n < kExactInDouble;
      };
      if (exact(e[0], step[0]) && exact(e[1], step[1])) {
        const Span span{static_cast<double>(e[0]),
                        static_cast<double>(e[1]),
                        static_cast<double>(step[0]),
                        static_cast<double>(step[1]),
                        inverse_area,
                        {z[0], z[1], z[2]},
                        {uv[0].x(), uv[1].x(), uv[2].x()},
                        {uv[0].y(), uv[1].y(), uv[2].y()},
                        reach,
                        face};
        int lo = n, hi = -1;
        fillSpan(n, span, gel_row + c_first, gap_row + c_first, face_row + c_first,
                 uv_row != nullptr ? &uv_row[c_first][0] : nullptr, lo, hi);
        out.pixel_hits += n;
        if (lo <= hi) {
          covered.min_r = std::min(covered.min_r, r);
          covered.max_r = std::max(covered.max_r, r);
          covered.min_c = std::min(covered.min_c, c_first + lo);
          covered.max_c = std::max(covered.max_c, c_first + hi);
        }
        continue;
      }
    }
    for (int col = c_first; col <= c_last;
         ++col, e[0] += step[0], e[1] += step[1], e[2] += step[2]) {
      if (test_each_pixel &&
          (!edges[0].inside(e[0]) || !edges[1].inside(e[1]) || !edges[2].inside(e[2]))) {
        continue;
      }
      ++out.pixel_hits;
      const float w0 = static_cast<float>(static_cast<double>(e[0]) * inverse_area);
      const float w1 = static_cast<float>(static_cast<double>(e[1]) * inverse_area);
      const float w2 = 1.0f - w0 - w1;
      const float gap = w0 * z[0] + w1 * z[1] + w2 * z[2] - gel_row[col];
      if (gap >= gap_row[col] || gap > reach) continue;
      gap_row[col] = gap;
      face_row[col] = face;
      if (uv_row != nullptr) {
        const Eigen::Vector2f q = w0 * uv[0] + w1 * uv[1] + w2 * uv[2];
        uv_row[col] = cv::Vec2f(q.x(), q.y());
      }
      covered.min_r = std::min(covered.min_r, r);
      covered.max_r = std::max(covered.max_r, r);
      covered.min_c = std::min(covered.min_c, col);
      covered.max_c = std::max(covered.max_c, col);
    }
  }
  return true;
}

}  // namespace

ContactRasterizer::ContactRasterizer(const SensorModel& model) : model_(model) {
  validate(model_);
  gel_surface_mm_.create(model_.rows, model_.cols);
  const double radius = model_.gel_curvature_radius_mm;
  for (int r = 0; r < model_.rows; ++r) {
    for (int c = 0; c < model_.cols; ++c) {
      if (radius <= 0.0) {
        gel_surface_mm_(r, c) = 0.0f;
        continue;
      }
      const cv::Point2d p = model_.pixelToGelMm(r, c);
      const double r2 = std::min(p.x * p.x + p.y * p.y, radius * radius);
      gel_surface_mm_(r, c) = static_cast<float>(std::sqrt(radius * radius - r2) - radius);
    }
  }
}

void ContactRasterizer::rasterize(const TexturedMesh& mesh, const Eigen::Isometry3d& object_in_gel,
                                  double reach_mm, bool want_uv, ContactRaster& out) const {
  if (!isFinite(object_in_gel)) throw Error("object pose is not finite (NaN or infinity)");
  if (!(reach_mm >= 0.0) || !std::isfinite(reach_mm)) throw Error("reach_mm must be >= 0");
  want_uv = want_uv && mesh.hasUvs();
  resetRaster(model_.imageSize(), want_uv, out);

  // Cull in metres, in the gel frame: the gel's footprint (plus a pixel), up to reach_mm above.
  const double half_w = 0.5e-3 * (model_.gelWidthMm() + 2.0 * model_.mm_per_pixel);
  const double half_h = 0.5e-3 * (model_.gelHeightMm() + 2.0 * model_.mm_per_pixel);
  const Eigen::AlignedBox3f region(
      Eigen::Vector3f(static_cast<float>(-half_w), static_cast<float>(-half_h), -1e6f),
      Eigen::Vector3f(static_cast<float>(half_w), static_cast<float>(half_h),
                      static_cast<float>(1e-3 * reach_mm)));
  const Eigen::Isometry3f pose = object_in_gel.cast<float>();
  out.candidates.clear();
  mesh.queryTriangles(pose, region, out.candidates);

  // Gel-frame mm -> continuous pixel coordinates with pixel centres at integers.
  const float px_per_m = static_cast<float>(1e3 / model_.mm_per_pixel);
  const float col0 = 0.5f * model_.cols - 0.5f, row0 = 0.5f * model_.rows - 0.5f;
  const float reach = static_cast<float>(reach_mm);
  const auto& vertices = mesh.vertices();
  const auto& uvs = mesh.uvs();
  CoveredBox covered{model_.rows, -1, model_.cols, -1};

  for (const int t : out.candidates) {
    const Eigen::Vector3i& tri = mesh.triangles()[t];
    ProjectedTriangle triangle;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f p = pose * vertices[tri[k]];
      triangle.x[k] = p.x() * px_per_m + col0;
      triangle.y[k] = p.y() * px_per_m + row0;
      triangle.z[k] = p.z() * 1e3f;
      triangle.uv[k] = want_uv ? uvs[tri[k]] : Eigen::Vector2f::Zero();
    }
    if (std::min({triangle.z[0], triangle.z[1], triangle.z[2]}) > reach) continue;
    if (drawTriangle(triangle, t, reach, want_uv, gel_surface_mm_, out, covered)) {
      ++out.triangles_rasterized;
    }
  }
  const int min_r = covered.min_r, max_r = covered.max_r;
  const int min_c = covered.min_c, max_c = covered.max_c;
  if (max_r < 0) return;
  out.covered_box = cv::Rect(min_c, min_r, max_c - min_c + 1, max_r - min_r + 1);

  const float thickness = static_cast<float>(model_.gel_thickness_mm);
  for (int r = min_r; r <= max_r; ++r) {
    const float* gap_row = out.gap_mm.ptr<float>(r);
    float* h_row = out.h_sensor_mm.ptr<float>(r);
    for (int col = min_c; col <= max_c; ++col) {
      h_row[col] = gap_row[col] < 0.0f ? std::min(-gap_row[col], thickness) : 0.0f;
    }
  }
}

}  // namespace norm2tex
