#pragma once
// Deterministic, seeded noise for the procedural materials: integer hashes, 1-D and 2-D
// gradient noise, fBm and Worley (cellular) noise. Every function is pure: the seed is an
// argument, there is no global RNG state, and results depend only on IEEE double arithmetic
// (+, *, correctly rounded sqrt; no other libm call), so the same inputs give the same bits.
//
// The hot functions are inline: materials call them millions of times per texture. Each has
// an overload taking a cache of the lattice cell it used last (GradientCell, FbmCache,
// WorleyCell, ...): a cache changes how often hashes are computed, never a result.

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace norm2tex {
namespace noise {

/// splitmix64's finaliser: a bijective 64-bit mix with full avalanche.
inline std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// A seed for an independent stream: mix of a parent seed and a stream number.
inline std::uint64_t derive(std::uint64_t seed, std::uint64_t stream) {
  return mix64(seed + 0x9E3779B97F4A7C15ull * (stream + 1));
}

/// Hash of an integer lattice point (any int, negatives included).
inline std::uint64_t hash2(std::uint64_t seed, std::int64_t ix, std::int64_t iy) {
  return mix64(seed ^ mix64(static_cast<std::uint64_t>(ix) * 0x9E3779B97F4A7C15ull +
                            static_cast<std::uint64_t>(iy) * 0xC2B2AE3D27D4EB4Full));
}
inline std::uint64_t hash1(std::uint64_t seed, std::int64_t i) {
  return hash2(seed, i, 0x5bd1e995);
}

/// Uniform in [0, 1) from the top 53 bits of a hash.
inline double unit(std::uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

/// floor() as an integer without a libm call (baseline x86-64 has no rounding instruction).
inline std::int64_t floorInt(double x) {
  const std::int64_t t = static_cast<std::int64_t>(x);
  return t - (x < static_cast<double>(t) ? 1 : 0);
}

/// Quintic fade 6t^5 - 15t^4 + 10t^3: C2-continuous blending between lattice cells.
inline double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

/// Hermite smoothstep of x between edges a < b, clamped to [0, 1].
inline double smoothstep(double a, double b, double x) {
  double t = (x - a) / (b - a);
  t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
  return t * t * (3.0 - 2.0 * t);
}

namespace detail {
/// 16 unit gradients at angles (k + 0.5) * 22.5 deg: no gradient along an axis, which keeps
/// the lattice's axis-aligned artefacts low.
extern const double kGradients[16][2];
}  // namespace detail

namespace detail {
/// One lattice corner's gradient: the hash's top 4 bits pick one of kGradients.
inline const double* cornerGradient(std::uint64_t seed, std::int64_t cx, std::int64_t cy) {
  return kGradients[hash2(seed, cx, cy) >> 60];
}

/// gradient2's blend of its cell's four corner gradients at (fx, fy) inside the cell.
inline double blendCorners(const double* const g[4], double fx, double fy) {
  const double n00 = g[0][0] * fx + g[0][1] * fy;
  const double n10 = g[1][0] * (fx - 1.0) + g[1][1] * fy;
  const double n01 = g[2][0] * fx + g[2][1] * (fy - 1.0);
  const double n11 = g[3][0] * (fx - 1.0) + g[3][1] * (fy - 1.0);
  const double u = fade(fx), v = fade(fy);
  const double a = n00 + u * (n10 - n00), b = n01 + u * (n11 - n01);
  return 1.4 * (a + v * (b - a));  // 1.4: scales the extreme values near +-1
}
}  // namespace detail

/// 2-D gradient (Perlin-style) noise, roughly in [-1, 1], zero at lattice points, C2.
inline double gradient2(std::uint64_t seed, double x, double y) {
  const std::int64_t ix = floorInt(x), iy = floorInt(y);
  const double* const g[4] = {
      detail::cornerGradient(seed, ix, iy), detail::cornerGradient(seed, ix + 1, iy),
      detail::cornerGradient(seed, ix, iy + 1), detail::cornerGradient(seed, ix + 1, iy + 1)};
  return detail::blendCorners(g, x - static_cast<double>(ix), y - static_cast<double>(iy));
}

/// The lattice cell one stream of gradient2 look-ups used last, with its corner gradients.
/// Neighbouring texels of a rendered grid mostly fall in the same cell, whose four hashes are
/// most of gradient2's cost: with a cache the result is the same, bit for bit, for less work.
/// One cache per stream and thread (it is not synchronised).
struct GradientCell {
  bool used = false;
  std::uint64_t seed = 0;
  std::int64_t ix = 0, iy = 0;
  const double* g[4] = {nullptr, nullptr, nullptr, nullptr};
};

namespace detail {
/// Makes `cell` hold cell (ix, iy) of `seed`'s lattice: hashes only when it holds another.
inline void enterCell(GradientCell& cell, std::uint64_t seed, std::int64_t ix, std::int64_t iy) {
  if (cell.used && cell.ix == ix && cell.iy == iy && cell.seed == seed) return;
  cell.g[0] = cornerGradient(seed, ix, iy);
  cell.g[1] = cornerGradient(seed, ix + 1, iy);
  cell.g[2] = cornerGradient(seed, ix, iy + 1);
  cell.g[3] = cornerGradient(seed, ix + 1, iy + 1);
  cell.used = true;
  cell.seed = seed;
  cell.ix = ix;
  cell.iy = iy;
}
}  // namespace detail

/// gradient2 through a cache of its last cell.
inline double gradient2(GradientCell& cell, std::uint64_t seed, double x, double y) {
  const std::int64_t ix = floorInt(x), iy = floorInt(y);
  detail::enterCell(cell, seed, ix, iy);
  return detail::blendCorners(cell.g, x - static_cast<double>(ix), y - static_cast<double>(iy));
}

/// 1-D gradient noise, roughly in [-1, 1], zero at integers, C2.
namespace detail {
inline double gradientAt(std::uint64_t seed, std::int64_t i) {
  return unit(hash1(seed, i)) * 2.0 - 1.0;
}
inline double blendEnds(double g0, double g1, double f) {
  const double n0 = g0 * f, n1 = g1 * (f - 1.0);
  return 2.0 * (n0 + fade(f) * (n1 - n0));
}
}  // namespace detail

inline double gradient1(std::uint64_t seed, double x) {
  const std::int64_t ix = floorInt(x);
  return detail::blendEnds(detail::gradientAt(seed, ix), detail::gradientAt(seed, ix + 1),
                           x - static_cast<double>(ix));
}

/// The interval one stream of gradient1 look-ups used last (see GradientCell).
struct GradientInterval {
  bool used = false;
  std::uint64_t seed = 0;
  std::int64_t ix = 0;
  double g0 = 0.0, g1 = 0.0;
};

namespace detail {
/// Makes `interval` hold interval ix of `seed`'s lattice: hashes only when it holds another.
inline void enterInterval(GradientInterval& interval, std::uint64_t seed, std::int64_t ix) {
  if (interval.used && interval.ix == ix && interval.seed == seed) return;
  interval.g0 = gradientAt(seed, ix);
  interval.g1 = gradientAt(seed, ix + 1);
  interval.used = true;
  interval.seed = seed;
  interval.ix = ix;
}
}  // namespace detail

/// gradient1 through a cache of its last interval.
inline double gradient1(GradientInterval& interval, std::uint64_t seed, double x) {
  const std::int64_t ix = floorInt(x);
  detail::enterInterval(interval, seed, ix);
  return detail::blendEnds(interval.g0, interval.g1, x - static_cast<double>(ix));
}

namespace detail {
/// The next fBm octave's coordinates: twice the frequency, turned by ~37 deg (cos / sin of a
/// 3-4-5 triangle: exact in binary, no libm call), offset so octaves share no zero at the origin.
inline void nextOctave(double& x, double& y) {
  constexpr double kC = 0.8, kS = 0.6;
  const double xr = 2.0 * (kC * x - kS * y), yr = 2.0 * (kS * x + kC * y);
  x = xr + 17.31;
  y = yr - 5.73;
}
}  // namespace detail

/// Fractal Brownian motion of 2-D gradient noise: `octaves` octaves, frequency x2 and
/// amplitude x`gain` per octave, each octave rotated by ~37 deg (hides the lattice's axes) and
/// seeded on its own. Normalised by the sum of amplitudes: roughly in [-1, 1].
/// `octave(o, seed_o, x_o, y_o)` evaluates one octave's gradient2; the seeds are given.
template <typename Octave, typename Seed>
inline double fbm2With(const Seed& octave_seed, const Octave& octave, double x, double y,
                       int octaves, double gain) {
  double sum = 0.0, norm = 0.0, amplitude = 1.0;
  for (int o = 0; o < octaves; ++o) {
    sum += amplitude * octave(o, octave_seed(o), x, y);
    norm += amplitude;
    amplitude *= gain;
    detail::nextOctave(x, y);
  }
  return norm > 0.0 ? sum / norm : 0.0;
}

inline double fbm2(std::uint64_t seed, double x, double y, int octaves, double gain = 0.5) {
  return fbm2With([seed](int o) { return derive(seed, o); },
                  [](int, std::uint64_t s, double xo, double yo) { return gradient2(s, xo, yo); },
                  x, y, octaves, gain);
}

/// Per-octave caches of one fbm2 stream (see GradientCell), with its octave seeds.
template <int kOctaves>
struct FbmCache {
  bool seeded = false;
  std::uint64_t seed = 0;
  std::uint64_t octave_seed[kOctaves] = {};
  GradientCell cell[kOctaves];
};

/// fbm2 through per-octave caches; the same bits as fbm2. Octaves beyond the cache's are
/// computed without one.
template <int kOctaves>
inline double fbm2(FbmCache<kOctaves>& cache, std::uint64_t seed, double x, double y, int octaves,
                   double gain = 0.5) {
  if (!cache.seeded || cache.seed != seed) {
    for (int o = 0; o < kOctaves; ++o) cache.octave_seed[o] = derive(seed, o);
    cache.seeded = true;
    cache.seed = seed;
  }
  return fbm2With(
      [&cache, seed](int o) { return o < kOctaves ? cache.octave_seed[o] : derive(seed, o); },
      [&cache](int o, std::uint64_t s, double xo, double yo) {
        return o < kOctaves ? gradient2(cache.cell[o], s, xo, yo) : gradient2(s, xo, yo);
      },
      x, y, octaves, gain);
}

/// Scratch arrays of fbm2Row, kept by the caller (one per thread).
struct FbmRowScratch {
  /// g: the points' corner gradients, component after component (00 x, 00 y, 10 x, 10 y, 01 x,
  /// 01 y, 11 x, 11 y), each an array of all points.
  std::vector<double> x, y, sum, fx, fy, g;
};

namespace detail {
/// sum[i] += amplitude * blendCorners(point i's corners, fx[i], fy[i]), with g[k count + i]
/// the k-th corner-gradient component of point i (FbmRowScratch::g's order).
/// Plain loops that vectorise (built for AVX2 and the baseline, noise.cpp); the same operations
/// as blendCorners, so the same bits.
void accumulateBlendedCorners(int count, const double* fx, const double* fy, const double* g,
                              double amplitude, double* sum);
}  // namespace detail

/// fbm2 of the points (x[i], y) through `cache`: out[i] is fbm2(cache, seed, x[i], y, octaves,
/// gain), bit for bit. Per octave, the cells and gradients are found point by point (hashes only
/// where the cell changes) and the blends are done a vector at a time.
template <int kOctaves>
void fbm2Row(FbmCache<kOctaves>& cache, std::uint64_t seed, const double* x, double y, int count,
             int octaves, double gain, double* out, FbmRowScratch& scratch) {
  if (!cache.seeded || cache.seed != seed) {
    for (int o = 0; o < kOctaves; ++o) cache.octave_seed[o] = derive(seed, o);
    cache.seeded = true;
    cache.seed = seed;
  }
  const auto n = static_cast<std::size_t>(count);
  scratch.x.assign(x, x + count);
  scratch.y.assign(n, y);
  scratch.sum.assign(n, 0.0);
  scratch.fx.resize(n);
  scratch.fy.resize(n);
  scratch.g.resize(8 * n);
  double norm = 0.0, amplitude = 1.0;
  for (int o = 0; o < octaves; ++o) {
    const std::uint64_t octave_seed = o < kOctaves ? cache.octave_seed[o] : derive(seed, o);
    GradientCell uncached;
    GradientCell& cell = o < kOctaves ? cache.cell[o] : uncached;
    double* xs = scratch.x.data();
    double* ys = scratch.y.data();
    double* fx = scratch.fx.data();
    double* fy = scratch.fy.data();
    double* g = scratch.g.data();
    // Run by run of points in one cell: the cell's gradients stay in registers while they are
    // written out (point by point they were reloaded through the cache for every point).
    for (int i = 0; i < count;) {
      const std::int64_t ix = floorInt(xs[i]), iy = floorInt(ys[i]);
      detail::enterCell(cell, octave_seed, ix, iy);
      const double corner[8] = {cell.g[0][0], cell.g[0][1], cell.g[1][0], cell.g[1][1],
                                cell.g[2][0], cell.g[2][1], cell.g[3][0], cell.g[3][1]};
      // floorInt(v) == i exactly when i <= v < i + 1: comparisons, not conversions, per point.
      const double cx = static_cast<double>(ix), cy = static_cast<double>(iy);
      const double cx_end = cx + 1.0, cy_end = cy + 1.0;
      do {
        fx[i] = xs[i] - cx;
        fy[i] = ys[i] - cy;
        for (int k = 0; k < 8; ++k) g[k * n + i] = corner[k];
        ++i;
      } while (i < count && xs[i] >= cx && xs[i] < cx_end && ys[i] >= cy && ys[i] < cy_end);
    }
    detail::accumulateBlendedCorners(count, scratch.fx.data(), scratch.fy.data(), scratch.g.data(),
                                     amplitude, scratch.sum.data());
    norm += amplitude;
    amplitude *= gain;
    for (int i = 0; i < count; ++i) detail::nextOctave(xs[i], ys[i]);
  }
  for (int i = 0; i < count; ++i) out[i] = norm > 0.0 ? scratch.sum[i] / norm : 0.0;
}

/// Worley (cellular) noise on a jittered unit lattice: distances to the nearest (f1) and
/// second-nearest (f2) feature point, and the nearest point's hash (a per-cell random id).
struct Worley {
  double f1, f2;
  std::uint64_t id;
};

namespace detail {
/// One neighbour cell's feature point, offset i, j from the looked-up cell: (i + 0.1 + 0.8 u,
/// j + 0.1 + 0.8 u') before the look-up's fraction is subtracted, and the cell's hash.
struct WorleyPoint {
  double x, y;
  std::uint64_t id;
};
inline WorleyPoint worleyPoint(std::uint64_t seed, std::int64_t ix, std::int64_t iy, int i, int j) {
  const std::uint64_t h = hash2(seed, ix + i, iy + j);
  // Jitter in [0.1, 0.9]: every point lies at least 0.1 inside its cell.
  return {i + 0.1 + 0.8 * unit(h), j + 0.1 + 0.8 * unit(mix64(h)), h};
}

/// worley2 given the 3 x 3 block of points around cell (ix, iy), row by row.
inline Worley worleyFrom(const WorleyPoint (&block)[9], std::uint64_t seed, std::int64_t ix,
                         std::int64_t iy, double fx, double fy) {
  double d1 = 1e30, d2 = 1e30;
  std::uint64_t id = 0;
  const auto visit = [&](const WorleyPoint& p) {
    const double px = p.x - fx, py = p.y - fy;
    const double d = px * px + py * py;
    if (d < d1) {
      d2 = d1;
      d1 = d;
      id = p.id;
    } else if (d < d2) {
      d2 = d;
    }
  };
  for (const WorleyPoint& p : block) visit(p);
  // Points two cells away are at least 1.1 away. Rarely the 3 x 3 block's second-nearest is
  // farther than that: then the outer ring decides, so f1 and f2 (and the relief) stay exact
  // and continuous.
  if (d2 > 1.21) {
    for (int j = -2; j <= 2; ++j) {
      for (int i = -2; i <= 2; ++i) {
        if (i == -2 || i == 2 || j == -2 || j == 2) visit(worleyPoint(seed, ix, iy, i, j));
      }
    }
  }
  return {std::sqrt(d1), std::sqrt(d2), id};
}

inline void worleyBlock(std::uint64_t seed, std::int64_t ix, std::int64_t iy,
                        WorleyPoint (&block)[9]) {
  int k = 0;
  for (int j = -1; j <= 1; ++j) {
    for (int i = -1; i <= 1; ++i) block[k++] = worleyPoint(seed, ix, iy, i, j);
  }
}
}  // namespace detail

inline Worley worley2(std::uint64_t seed, double x, double y) {
  const std::int64_t ix = floorInt(x), iy = floorInt(y);
  detail::WorleyPoint block[9];
  detail::worleyBlock(seed, ix, iy, block);
  return detail::worleyFrom(block, seed, ix, iy, x - static_cast<double>(ix),
                            y - static_cast<double>(iy));
}

/// The 3 x 3 block of feature points around the cell one stream of worley2 look-ups used
/// last (see GradientCell): 9 hashes saved whenever the next look-up is in the same cell.
struct WorleyCell {
  bool used = false;
  std::uint64_t seed = 0;
  std::int64_t ix = 0, iy = 0;
  detail::WorleyPoint block[9];
};

/// worley2 through a cache of its last cell's block; the same bits as worley2.
inline Worley worley2(WorleyCell& cell, std::uint64_t seed, double x, double y) {
  const std::int64_t ix = floorInt(x), iy = floorInt(y);
  if (!cell.used || cell.ix != ix || cell.iy != iy || cell.seed != seed) {
    detail::worleyBlock(seed, ix, iy, cell.block);
    cell.used = true;
    cell.seed = seed;
    cell.ix = ix;
    cell.iy = iy;
  }
  return detail::worleyFrom(cell.block, seed, ix, iy, x - static_cast<double>(ix),
                            y - static_cast<double>(iy));
}

/// A seed from text (FNV-1a): stable per parameter name, e.g. for variant draws.
std::uint64_t hashString(const std::string& text);

/// Poisson-distributed count with mean `lambda` (>= 0) from one uniform u in [0, 1), by
/// inverting the CDF. Exact for lambda up to ~700; counts are capped at 10000.
int poisson(double lambda, double u);

}  // namespace noise
}  // namespace norm2tex
