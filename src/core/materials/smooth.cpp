// Smooth: acrylic, porcelain, moulded plastic. Nearly flat: a faint long-wavelength
// waviness, a trace of micro-roughness and sparse straight micro-scratches of V profile.

#include <algorithm>
#include <cmath>
#include <vector>

#include "materials.hpp"
#include "noise.hpp"
#include "norm2tex/common/huge_pages.hpp"

namespace norm2tex {
namespace materials {
namespace {

class Smooth final : public ProceduralMaterial {
 public:
  enum Index {
    kWaviness,
    kWavelength,
    kMicroRoughness,
    kScratchDensity,
    kScratchLength,
    kScratchWidth,
    kScratchDepth
  };

  Smooth()
      : ProceduralMaterial({
            {"waviness_mm", 0.002, 0.0, 0.02, "mm", "amplitude of the long-wavelength waviness"},
            {"waviness_wavelength_mm", 10.0, 1.0, 50.0, "mm", "wavelength of the waviness"},
            {"micro_roughness_mm", 0.0003, 0.0, 0.005, "mm",
             "amplitude of the fine isotropic roughness (0.25 mm wavelength and below)"},
            {"scratch_density_per_mm2", 0.08, 0.0, 2.0, "1/mm^2", "scratches per mm^2"},
            {"scratch_length_mm", 3.0, 0.2, 10.0, "mm", "mean scratch length (0.5x to 1.5x)"},
            {"scratch_width_mm", 0.05, 0.01, 0.3, "mm",
             "mean width of a scratch's V (0.7x to 1.3x)"},
            {"scratch_depth_mm", 0.002, 0.0, 0.02, "mm",
             "mean depth of a scratch at its middle (0.5x to 1.5x)"},
        }) {
    update();
  }

  std::string name() const override { return "smooth"; }

  double heightMm(double x_mm, double y_mm) const override {
    return base(x_mm, y_mm) + deepestScratch(x_mm, y_mm);
  }

  cv::Vec3b albedo(double x_mm, double y_mm) const override {
    // Off-white porcelain / acrylic; scratches scatter light and look a little lighter.
    const double scratch =
        scratch_depth_ > 0.0 ? -deepestScratch(x_mm, y_mm) / scratch_depth_ : 0.0;
    const double tone =
        1.0 + 0.02 * noise::fbm2(seed_wave_, x_mm / wavelength_, y_mm / wavelength_, 2);
    const cv::Vec3d base(228, 232, 236);
    cv::Vec3b colour;
    for (int k = 0; k < 3; ++k) {
      colour[k] = cv::saturate_cast<uchar>(base[k] * tone + 25.0 * std::min(scratch, 1.0));
    }
    return colour;
  }

  // Fast path: the base field per texel, then each scratch stamped only over its bounding box.
  // Scratches combine by minimum (the deepest wins), which does not depend on their order, so
  // the result is bit for bit the per-point one.
  cv::Mat1f renderHeightMm(cv::Size size, double mm_per_texel,
                           cv::Point2d origin_mm) const override {
    checkGrid(size, mm_per_texel);
    // Texture-sized buffers on huge pages (48 MB at 2048^2): see huge_pages.hpp.
    cv::Mat1d deepest;
    createWithHugePages(deepest, size.height, size.width);
    deepest.setTo(0.0);
    if (scratches_) {
      const double x0 = texelX(0, mm_per_texel, origin_mm);
      const double x1 = texelX(size.width - 1, mm_per_texel, origin_mm);
      const double y0 = texelY(0, mm_per_texel, origin_mm);
      const double y1 = texelY(size.height - 1, mm_per_texel, origin_mm);
      const std::int64_t cx0 = noise::floorInt(x0 / cell_) - 1,
                         cx1 = noise::floorInt(x1 / cell_) + 1;
      const std::int64_t cy0 = noise::floorInt(y0 / cell_) - 1,
                         cy1 = noise::floorInt(y1 / cell_) + 1;
      const auto texelRange = [&](double lo, double hi, double origin, int n, int& first,
                                  int& last) {
        // One texel of margin on each side: rounding never drops a texel the scratch touches.
        first = static_cast<int>(
            std::max<double>(0.0, std::floor((lo - origin) / mm_per_texel - 0.5) - 1.0));
        last = static_cast<int>(
            std::min<double>(n - 1, std::ceil((hi - origin) / mm_per_texel - 0.5) + 1.0));
      };
      for (std::int64_t cy = cy0; cy <= cy1; ++cy) {
        for (std::int64_t cx = cx0; cx <= cx1; ++cx) {
          forEachScratch(cx, cy, [&](const Scratch& s) {
            const double rx = s.half_length * std::abs(s.dx) + s.half_width * std::abs(s.dy);
            const double ry = s.half_length * std::abs(s.dy) + s.half_width * std::abs(s.dx);
            int c0, c1, r0, r1;
            texelRange(s.cx - rx, s.cx + rx, origin_mm.x, size.width, c0, c1);
            texelRange(s.cy - ry, s.cy + ry, origin_mm.y, size.height, r0, r1);
            for (int r = r0; r <= r1; ++r) {
              const double y = texelY(r, mm_per_texel, origin_mm);
              double* row = deepest.ptr<double>(r);
              for (int c = c0; c <= c1; ++c) {
                const double v = depthOf(s, texelX(c, mm_per_texel, origin_mm), y);
                if (v < row[c]) row[c] = v;
              }
            }
          });
        }
      }
    }
    cv::Mat1f height;
    createWithHugePages(height, size.height, size.width);
    // base() a row at a time: the same fbm2 values (noise::fbm2Row), blended a vector at once.
    thread_local noise::FbmCache<2> wave_cache, micro_cache;
    thread_local noise::FbmRowScratch fbm_scratch;
    std::vector<double> xw(size.width), xm(size.width), wave(size.width), micro(size.width);
    const double inv = 1.0 / wavelength_;
    for (int c = 0; c < size.width; ++c) {
      const double x = texelX(c, mm_per_texel, origin_mm);
      xw[c] = x * inv;
      xm[c] = x * kMicroPerMm;
    }
    for (int r = 0; r < size.height; ++r) {
      const double y = texelY(r, mm_per_texel, origin_mm);
      noise::fbm2Row(wave_cache, seed_wave_, xw.data(), y * inv, size.width, 2, 0.5, wave.data(),
                     fbm_scratch);
      noise::fbm2Row(micro_cache, seed_micro_, xm.data(), y * kMicroPerMm, size.width, 2, 0.5,
                     micro.data(), fbm_scratch);
      const double* scratch = deepest.ptr<double>(r);
      float* row = height.ptr<float>(r);
      for (int c = 0; c < size.width; ++c) {
        row[c] = static_cast<float>(waviness_ * wave[c] + micro_ * micro[c] + scratch[c]);
      }
    }
    return height;
  }

 private:
  struct Scratch {
    double cx, cy;  ///< centre, mm
    double dx, dy;  ///< unit direction
    double half_length, half_width, depth;
  };

  void update() override {
    waviness_ = value(kWaviness);
    wavelength_ = value(kWavelength);
    micro_ = value(kMicroRoughness);
    density_ = value(kScratchDensity);
    length_ = value(kScratchLength);
    width_ = value(kScratchWidth);
    scratch_depth_ = value(kScratchDepth);
    scratches_ = density_ > 0.0 && scratch_depth_ > 0.0;
    // A scratch reaches at most 0.75 L + 0.65 w from its centre, so with cells that large
    // every scratch touching a point has its centre in the point's cell or a neighbour.
    cell_ = 0.75 * length_ + 0.65 * width_;
    seed_wave_ = noise::derive(seed(), 1);
    seed_micro_ = noise::derive(seed(), 2);
    seed_scratch_ = noise::derive(seed(), 3);
  }

  /// The micro-roughness noise's lattice cells per mm (its base wavelength 0.25 mm); shared by
  /// base() and the row render, which must give the same bits.
  static constexpr double kMicroPerMm = 4.0;

  double base(double x, double y) const {
    // Noise look-ups of one thread's last texels (see noise.hpp): same bits, fewer hashes.
    thread_local noise::FbmCache<2> wave, micro;
    const double inv = 1.0 / wavelength_;
    return waviness_ * noise::fbm2(wave, seed_wave_, x * inv, y * inv, 2) +
           micro_ * noise::fbm2(micro, seed_micro_, x * kMicroPerMm, y * kMicroPerMm, 2);
  }

  /// Calls f(scratch) for every scratch centred in cell (ix, iy): a Poisson number of them.
  template <typename F>
  void forEachScratch(std::int64_t ix, std::int64_t iy, const F& f) const {
    const std::uint64_t h = noise::hash2(seed_scratch_, ix, iy);
    const int count = noise::poisson(density_ * cell_ * cell_, noise::unit(h));
    for (int k = 0; k < count; ++k) {
      std::uint64_t r = noise::hash2(h, k, 1);
      const auto next = [&r]() {
        r = noise::mix64(r + 0x9E3779B97F4A7C15ull);
        return noise::unit(r);
      };
      Scratch s;
      s.cx = cell_ * (static_cast<double>(ix) + next());
      s.cy = cell_ * (static_cast<double>(iy) + next());
      const double angle = 3.14159265358979323846 * next();
      s.dx = std::cos(angle);
      s.dy = std::sin(angle);
      s.half_length = 0.5 * length_ * (0.5 + next());
      s.half_width = 0.5 * width_ * (0.7 + 0.6 * next());
      s.depth = scratch_depth_ * (0.5 + next());
      f(s);
    }
  }

  /// Height of one scratch at (x, y), <= 0: a V across it, tapering to 0 at its ends.
  static double depthOf(const Scratch& s, double x, double y) {
    const double rx = x - s.cx, ry = y - s.cy;
    const double t = (rx * s.dx + ry * s.dy) / s.half_length;
    if (t <= -1.0 || t >= 1.0) return 0.0;
    const double across = std::abs(ry * s.dx - rx * s.dy) / s.half_width;
    if (across >= 1.0) return 0.0;
    const double t2 = t * t;
    return -s.depth * (1.0 - t2 * t2) * (1.0 - across);
  }

  double deepestScratch(double x, double y) const {
    double deepest = 0.0;
    if (!scratches_) return deepest;
    const std::int64_t ix = noise::floorInt(x / cell_), iy = noise::floorInt(y / cell_);
    for (std::int64_t cy = iy - 1; cy <= iy + 1; ++cy) {
      for (std::int64_t cx = ix - 1; cx <= ix + 1; ++cx) {
        forEachScratch(cx, cy, [&](const Scratch& s) {
          const double v = depthOf(s, x, y);
          if (v < deepest) deepest = v;
        });
      }
    }
    return deepest;
  }

  double waviness_ = 0, wavelength_ = 10, micro_ = 0, density_ = 0, length_ = 1, width_ = 0.1;
  double scratch_depth_ = 0, cell_ = 1;
  bool scratches_ = false;
  std::uint64_t seed_wave_ = 0, seed_micro_ = 0, seed_scratch_ = 0;
};

}  // namespace

std::unique_ptr<ProceduralMaterial> makeSmooth() { return std::make_unique<Smooth>(); }

}  // namespace materials
}  // namespace norm2tex
