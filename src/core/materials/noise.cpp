#include "noise.hpp"

#include <cmath>

#include "norm2tex/common/simd_dispatch.hpp"

namespace norm2tex {
namespace noise {
namespace detail {

// cos / sin of (k + 0.5) * 22.5 deg, k = 0..15, as the closest doubles.
const double kGradients[16][2] = {
    {0.9807852804032304, 0.19509032201612825},   {0.8314696123025452, 0.5555702330196022},
    {0.5555702330196023, 0.8314696123025452},    {0.19509032201612833, 0.9807852804032304},
    {-0.19509032201612797, 0.9807852804032305},  {-0.5555702330196023, 0.8314696123025451},
    {-0.8314696123025453, 0.5555702330196022},   {-0.9807852804032304, 0.19509032201612816},
    {-0.9807852804032305, -0.19509032201612792}, {-0.8314696123025452, -0.5555702330196023},
    {-0.555570233019603, -0.8314696123025448},   {-0.19509032201612866, -0.9807852804032303},
    {0.1950903220161283, -0.9807852804032304},   {0.5555702330196018, -0.8314696123025455},
    {0.8314696123025452, -0.5555702330196022},   {0.9807852804032303, -0.19509032201612872},
};

namespace {

NORM2TEX_ALWAYS_INLINE void accumulateBody(int count, const double* __restrict fx,
                                           const double* __restrict fy, const double* __restrict g,
                                           double amplitude, double* __restrict sum) {
  const std::size_t n = static_cast<std::size_t>(count);
  const double* __restrict g00x = g;
  const double* __restrict g00y = g + n;
  const double* __restrict g10x = g + 2 * n;
  const double* __restrict g10y = g + 3 * n;
  const double* __restrict g01x = g + 4 * n;
  const double* __restrict g01y = g + 5 * n;
  const double* __restrict g11x = g + 6 * n;
  const double* __restrict g11y = g + 7 * n;
  for (int i = 0; i < count; ++i) {
    const double c00[2] = {g00x[i], g00y[i]}, c10[2] = {g10x[i], g10y[i]};
    const double c01[2] = {g01x[i], g01y[i]}, c11[2] = {g11x[i], g11y[i]};
    const double* const corners[4] = {c00, c10, c01, c11};
    sum[i] += amplitude * blendCorners(corners, fx[i], fy[i]);
  }
}
void accumulateBaseline(int count, const double* fx, const double* fy, const double* g,
                        double amplitude, double* sum) {
  accumulateBody(count, fx, fy, g, amplitude, sum);
}
#if NORM2TEX_HAS_AVX2_BUILD
NORM2TEX_TARGET_AVX2 void accumulateAvx2(int count, const double* fx, const double* fy,
                                         const double* g, double amplitude, double* sum) {
  accumulateBody(count, fx, fy, g, amplitude, sum);
}
using Accumulate = void (*)(int, const double*, const double*, const double*, double, double*);
const Accumulate accumulate = pickSimd<Accumulate>(accumulateAvx2, accumulateBaseline);
#else
const auto accumulate = accumulateBaseline;
#endif

}  // namespace

void accumulateBlendedCorners(int count, const double* fx, const double* fy, const double* g,
                              double amplitude, double* sum) {
  accumulate(count, fx, fy, g, amplitude, sum);
}

}  // namespace detail

std::uint64_t hashString(const std::string& text) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (const unsigned char c : text) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  return h;
}

int poisson(double lambda, double u) {
  if (!(lambda > 0.0)) return 0;
  // Walk the CDF: p_k = p_{k-1} * lambda / k (exp(-lambda) underflows beyond lambda ~ 700;
  // materials keep lambda far below that).
  double p = std::exp(-lambda), cdf = p;
  int k = 0;
  while (u >= cdf && k < 10000) {
    ++k;
    p *= lambda / k;
    cdf += p;
    if (p == 0.0 && static_cast<double>(k) > lambda) break;  // tail exhausted (rounding)
  }
  return k;
}

}  // namespace noise
}  // namespace norm2tex
