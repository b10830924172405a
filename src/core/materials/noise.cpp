#include "noise.hpp"

#include <cmath>

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
