#include "norm2tex/render/digit_shader_noise.hpp"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

// Inverse-CDF table of the standard normal at 2^12 equally likely quantiles; one 64-bit draw
// gives five 12-bit indices, so a QVGA frame needs ~46k draws and L1 lookups instead of 230k
// Box-Muller evaluations. Truncation at the extreme quantiles (+-3.7 sigma) is invisible at
// grey-level noise; the table is rescaled to unit variance.
constexpr int kTableBits = 12;
constexpr int kTableSize = 1 << kTableBits;
constexpr int kSamplesPerDraw = 64 / kTableBits;

std::uint64_t splitMix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// xoshiro256** (Blackman and Vigna): fast, well distributed in all bits.
class Xoshiro256 {
 public:
  explicit Xoshiro256(std::uint64_t seed) {
    for (std::uint64_t& word : s_) word = splitMix64(seed);
  }
  std::uint64_t next() {
    const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  std::uint64_t s_[4];
};

// Standard normal quantile by Newton's method on the CDF, started at 0: the CDF is convex
// below 0 and concave above, so the iteration approaches monotonically.
double normalQuantile(double p) {
  double x = 0.0;
  for (int i = 0; i < 100; ++i) {
    const double cdf = 0.5 * std::erfc(-x / std::sqrt(2.0));
    const double pdf = std::exp(-0.5 * x * x) / std::sqrt(2.0 * 3.14159265358979323846);
    const double step = (cdf - p) / pdf;
    x -= step;
    if (std::abs(step) < 1e-12) break;
  }
  return x;
}

std::vector<float> makeUnitNormalTable() {
  std::vector<double> z(kTableSize);
  for (int k = 0; k < kTableSize / 2; ++k) {
    z[k] = normalQuantile((k + 0.5) / kTableSize);
    z[kTableSize - 1 - k] = -z[k];  // exactly symmetric: zero mean
  }
  double variance = 0.0;
  for (double value : z) variance += value * value;
  variance /= kTableSize;
  std::vector<float> table(kTableSize);
  for (int k = 0; k < kTableSize; ++k) table[k] = static_cast<float>(z[k] / std::sqrt(variance));
  return table;
}

}  // namespace

DigitShaderNoise::DigitShaderNoise(const NoiseOptions& o) {
  enabled_ = o.sigma_bgr[0] > 0.0 || o.sigma_bgr[1] > 0.0 || o.sigma_bgr[2] > 0.0;
  if (!enabled_) return;
  table_ = makeUnitNormalTable();
  // [a, 1, a] with 2a / (1 + 2a^2) = rho: the smaller root.
  const double rho = o.neighbour_correlation;
  const double a = rho > 0.0 ? (1.0 - std::sqrt(1.0 - 2.0 * rho * rho)) / (2.0 * rho) : 0.0;
  const double norm = std::sqrt(1.0 + 2.0 * a * a);
  kernel_ = (cv::Mat1f(3, 1) << a / norm, 1.0 / norm, a / norm);
  // Channel covariance (B, G, R) and its Cholesky factor L (cov = L L^T).
  const cv::Vec3d s = o.sigma_bgr;
  const cv::Matx33d cov(s[0] * s[0], o.correlation_bg * s[0] * s[1], o.correlation_br * s[0] * s[2],
                        o.correlation_bg * s[0] * s[1], s[1] * s[1], o.correlation_gr * s[1] * s[2],
                        o.correlation_br * s[0] * s[2], o.correlation_gr * s[1] * s[2],
                        s[2] * s[2]);
  cv::Matx33d l = cv::Matx33d::zeros();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j <= i; ++j) {
      double sum = cov(i, j);
      for (int k = 0; k < j; ++k) sum -= l(i, k) * l(j, k);
      // A zero sigma makes its row 0; validate() guarantees the rest is positive definite.
      l(i, j) = i == j ? std::sqrt(std::max(sum, 0.0)) : (l(j, j) > 0.0 ? sum / l(j, j) : 0.0);
    }
  }
  mixing_ = cv::Matx33f(l);
}

void DigitShaderNoise::generate(cv::Size size, std::uint64_t seed, cv::Mat3f& noise) const {
  noise.create(size);
  if (!enabled_) {
    noise.setTo(cv::Scalar::all(0.0));
    return;
  }
  // Reused per thread: fresh pages cost ~13 us each on these VMs.
  thread_local cv::Mat3f white, smooth;
  white.create(size);
  Xoshiro256 generator(seed);
  const float* table = table_.data();
  const int row_samples = 3 * size.width;
  for (int r = 0; r < size.height; ++r) {
    float* out = white.ptr<float>(r);
    for (int k = 0; k < row_samples; k += kSamplesPerDraw) {
      std::uint64_t bits = generator.next();
      const int count = std::min(kSamplesPerDraw, row_samples - k);
      for (int j = 0; j < count; ++j, bits >>= kTableBits)
        out[k + j] = table[bits & (kTableSize - 1)];
    }
  }
  cv::sepFilter2D(white, smooth, CV_32F, kernel_, kernel_, cv::Point(-1, -1), 0.0,
                  cv::BORDER_REFLECT_101);
  const cv::Matx33f& m = mixing_;
  for (int r = 0; r < size.height; ++r) {
    const cv::Vec3f* in = smooth.ptr<cv::Vec3f>(r);
    cv::Vec3f* out = noise.ptr<cv::Vec3f>(r);
    for (int c = 0; c < size.width; ++c) {
      const cv::Vec3f& w = in[c];
      out[c] = cv::Vec3f(m(0, 0) * w[0], m(1, 0) * w[0] + m(1, 1) * w[1],
                         m(2, 0) * w[0] + m(2, 1) * w[1] + m(2, 2) * w[2]);
    }
  }
}

}  // namespace norm2tex
