#pragma once
// Deterministic, seeded noise for the procedural materials: integer hashes, 1-D and 2-D
// gradient noise, fBm and Worley (cellular) noise. Every function is pure: the seed is an
// argument, there is no global RNG state, and results depend only on IEEE double arithmetic
// (+, *, correctly rounded sqrt; no other libm call), so the same inputs give the same bits.
//
// The hot functions are inline: materials call them millions of times per texture.

#include <cmath>
#include <cstdint>
#include <string>

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

/// 2-D gradient (Perlin-style) noise, roughly in [-1, 1], zero at lattice points, C2.
inline double gradient2(std::uint64_t seed, double x, double y) {
  const std::int64_t ix = floorInt(x), iy = floorInt(y);
  const double fx = x - static_cast<double>(ix), fy = y - static_cast<double>(iy);
  const auto corner = [&](std::int64_t cx, std::int64_t cy, double dx, double dy) {
    const double* g = detail::kGradients[hash2(seed, cx, cy) >> 60];
    return g[0] * dx + g[1] * dy;
  };
  const double n00 = corner(ix, iy, fx, fy);
  const double n10 = corner(ix + 1, iy, fx - 1.0, fy);
  const double n01 = corner(ix, iy + 1, fx, fy - 1.0);
  const double n11 = corner(ix + 1, iy + 1, fx - 1.0, fy - 1.0);
  const double u = fade(fx), v = fade(fy);
  const double a = n00 + u * (n10 - n00), b = n01 + u * (n11 - n01);
  return 1.4 * (a + v * (b - a));  // 1.4: scales the extreme values near +-1
}

/// 1-D gradient noise, roughly in [-1, 1], zero at integers, C2.
inline double gradient1(std::uint64_t seed, double x) {
  const std::int64_t ix = floorInt(x);
  const double f = x - static_cast<double>(ix);
  const double g0 = unit(hash1(seed, ix)) * 2.0 - 1.0, g1 = unit(hash1(seed, ix + 1)) * 2.0 - 1.0;
  const double n0 = g0 * f, n1 = g1 * (f - 1.0);
  return 2.0 * (n0 + fade(f) * (n1 - n0));
}

/// Fractal Brownian motion of 2-D gradient noise: `octaves` octaves, frequency x2 and
/// amplitude x`gain` per octave, each octave rotated by ~37 deg (hides the lattice's axes) and
/// seeded on its own. Normalised by the sum of amplitudes: roughly in [-1, 1].
inline double fbm2(std::uint64_t seed, double x, double y, int octaves, double gain = 0.5) {
  // cos / sin of 36.87 deg (a 3-4-5 triangle): exact in binary, no libm call.
  constexpr double kC = 0.8, kS = 0.6;
  double sum = 0.0, norm = 0.0, amplitude = 1.0;
  for (int o = 0; o < octaves; ++o) {
    sum += amplitude * gradient2(derive(seed, o), x, y);
    norm += amplitude;
    amplitude *= gain;
    const double xr = 2.0 * (kC * x - kS * y), yr = 2.0 * (kS * x + kC * y);
    x = xr + 17.31;  // offset: octaves do not share a zero at the origin
    y = yr - 5.73;
  }
  return norm > 0.0 ? sum / norm : 0.0;
}

/// Worley (cellular) noise on a jittered unit lattice: distances to the nearest (f1) and
/// second-nearest (f2) feature point, and the nearest point's hash (a per-cell random id).
struct Worley {
  double f1, f2;
  std::uint64_t id;
};
inline Worley worley2(std::uint64_t seed, double x, double y) {
  const std::int64_t ix = floorInt(x), iy = floorInt(y);
  const double fx = x - static_cast<double>(ix), fy = y - static_cast<double>(iy);
  double d1 = 1e30, d2 = 1e30;
  std::uint64_t id = 0;
  const auto visit = [&](int i, int j) {
    const std::uint64_t h = hash2(seed, ix + i, iy + j);
    // Jitter in [0.1, 0.9]: every point lies at least 0.1 inside its cell.
    const double px = i + 0.1 + 0.8 * unit(h) - fx;
    const double py = j + 0.1 + 0.8 * unit(mix64(h)) - fy;
    const double d = px * px + py * py;
    if (d < d1) {
      d2 = d1;
      d1 = d;
      id = h;
    } else if (d < d2) {
      d2 = d;
    }
  };
  for (int j = -1; j <= 1; ++j) {
    for (int i = -1; i <= 1; ++i) visit(i, j);
  }
  // Points two cells away are at least 1.1 away. Rarely the 3 x 3 block's second-nearest is
  // farther than that: then the outer ring decides, so f1 and f2 (and the relief) stay exact
  // and continuous.
  if (d2 > 1.21) {
    for (int j = -2; j <= 2; ++j) {
      for (int i = -2; i <= 2; ++i) {
        if (i == -2 || i == 2 || j == -2 || j == 2) visit(i, j);
      }
    }
  }
  return {std::sqrt(d1), std::sqrt(d2), id};
}

/// A seed from text (FNV-1a): stable per parameter name, e.g. for variant draws.
std::uint64_t hashString(const std::string& text);

/// Poisson-distributed count with mean `lambda` (>= 0) from one uniform u in [0, 1), by
/// inverting the CDF. Exact for lambda up to ~700; counts are capped at 10000.
int poisson(double lambda, double u);

}  // namespace noise
}  // namespace norm2tex
