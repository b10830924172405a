// Fabric: woven warp and weft threads (plain, twill or satin) with rounded cross-sections that
// rise over and dip under each other, slight irregularity and fine fuzz.
//
// Periodicity (for tests and users): threads of each family are thread_spacing_mm apart. The
// weave repeats every 2 threads for plain (0), 4 for twill (1) and 5 for satin (2), so plain
// weave's exact period is 2 x thread_spacing_mm along both thread directions, while the
// strongest spectral line is the thread pitch itself (1 / thread_spacing_mm).

#include <cmath>

#include "materials.hpp"
#include "noise.hpp"

namespace norm2tex {
namespace materials {
namespace {

class Fabric final : public ProceduralMaterial {
 public:
  enum Index { kWeave, kSpacing, kWidthRatio, kThreadHeight, kAngle, kFuzz, kIrregularity };

  Fabric()
      : ProceduralMaterial({
            {"weave", 0.0, 0.0, 2.0, "", "weave pattern: 0 = plain, 1 = 2/2 twill, 2 = 5-end satin",
             true},
            {"thread_spacing_mm", 0.5, 0.1, 3.0, "mm",
             "distance between neighbouring parallel threads (the thread pitch)"},
            {"thread_width_ratio", 0.85, 0.3, 1.0, "", "thread width / thread spacing"},
            {"thread_height_mm", 0.05, 0.0, 0.3, "mm",
             "relief of a thread on top of a crossing above the gaps"},
            {"angle_deg", 0.0, -180.0, 180.0, "deg",
             "weave rotation: 0 = warp threads along y (image columns), weft along x"},
            {"fuzz_mm", 0.003, 0.0, 0.02, "mm", "amplitude of the fine fibre fuzz"},
            {"irregularity", 0.08, 0.0, 0.3, "",
             "wobble of thread centres and widths, in thread spacings"},
        }) {
    update();
  }

  std::string name() const override { return "fabric"; }

  double heightMm(double x_mm, double y_mm) const override { return evaluate(x_mm, y_mm).height; }

  cv::Vec3b albedo(double x_mm, double y_mm) const override {
    const Sample s = evaluate(x_mm, y_mm);
    // Denim-like: indigo warp, off-white weft, dark gaps; threads shaded by their roundness.
    static const cv::Vec3d kWarp(150, 85, 45), kWeft(205, 210, 212), kGap(40, 35, 35);
    const cv::Vec3d thread = s.family == 1 ? kWarp : kWeft;
    const double shade = s.family == 0 ? 0.0 : 0.35 + 0.65 * s.profile;
    const double fuzz = 1.0 + 0.1 * s.fuzz;
    cv::Vec3b colour;
    for (int k = 0; k < 3; ++k) {
      colour[k] = cv::saturate_cast<uchar>((kGap[k] + (thread[k] - kGap[k]) * shade) * fuzz);
    }
    return colour;
  }

 private:
  struct Sample {
    double height;
    int family;      ///< on top: 0 gap, 1 warp, 2 weft
    double profile;  ///< cross-section of the top thread, 0 at its edge, 1 on its axis
    double fuzz;     ///< fuzz noise, about [-1, 1]
  };

  void update() override {
    weave_ = static_cast<int>(value(kWeave));
    spacing_ = value(kSpacing);
    half_width_ = 0.5 * value(kWidthRatio) * spacing_;
    height_ = value(kThreadHeight);
    const double angle = value(kAngle) * kDegToRad;
    cos_ = std::cos(angle);
    sin_ = std::sin(angle);
    fuzz_ = value(kFuzz);
    irregularity_ = value(kIrregularity);
    seed_warp_ = noise::derive(seed(), 1);
    seed_weft_ = noise::derive(seed(), 2);
    seed_fuzz_ = noise::derive(seed(), 3);
  }

  /// Whether warp thread i lies over weft thread j at their crossing.
  bool warpOver(std::int64_t i, std::int64_t j) const {
    const auto mod = [](std::int64_t a, std::int64_t m) { return ((a % m) + m) % m; };
    switch (weave_) {
      case 1:  // 2/2 twill: over two, under two, shifted by one each weft -> diagonal ribs
        return mod(i + j, 4) < 2;
      case 2:  // 5-end warp satin, step 2: each warp goes under one weft in five
        return mod(2 * i + j, 5) != 0;
      default:  // plain: alternate
        return mod(i + j, 2) == 0;
    }
  }

  /// Top height of thread `index` of one family at `across` (distance across the threads) and
  /// `along` (position along the thread), or -1 when the point is off the thread. `crossing`
  /// says whether the thread is on top at its k-th crossing.
  template <typename Crossing>
  double thread(std::uint64_t family_seed, std::int64_t index, double across, double along,
                const Crossing& on_top, double* profile) const {
    const double nominal = (static_cast<double>(index) + 0.5) * spacing_;
    const double wobble = irregularity_ * spacing_;
    const double max_half = half_width_ * (1.0 + irregularity_);
    if (std::abs(across - nominal) >= wobble + max_half) return -1.0;  // cannot reach
    const std::uint64_t s = noise::hash1(family_seed, index);
    const double centre = nominal + wobble * noise::gradient1(s, along / (4.0 * spacing_));
    const double half =
        half_width_ *
        (1.0 + irregularity_ * noise::gradient1(noise::mix64(s), along / (2.0 * spacing_)));
    const double q = (across - centre) / half;
    if (q * q >= 1.0) return -1.0;
    // Level +1 over a crossing, -1 under it, eased between crossings (C2).
    const double t = along / spacing_ - 0.5;
    const std::int64_t k = noise::floorInt(t);
    const double l0 = on_top(k) ? 1.0 : -1.0, l1 = on_top(k + 1) ? 1.0 : -1.0;
    const double level = l0 + (l1 - l0) * noise::fade(t - static_cast<double>(k));
    const double amplitude =
        height_ * (1.0 + irregularity_ * (noise::unit(noise::mix64(s + 1)) - 0.5));
    // Rounded cross-section, 1 on the axis, 0 with a finite slope at the edge (close to
    // cos(pi q / 2)).
    *profile = (1.0 - q * q) * (1.0 - 0.23 * q * q);
    return amplitude * (0.7 + 0.3 * level) * *profile;
  }

  Sample evaluate(double x, double y) const {
    const double a = cos_ * x + sin_ * y;   // across the warp threads (along the weft)
    const double b = -sin_ * x + cos_ * y;  // along the warp threads (across the weft)
    Sample s{0.0, 0, 0.0, 0.0};
    const std::int64_t i0 = noise::floorInt(a / spacing_), j0 = noise::floorInt(b / spacing_);
    double profile = 0.0;
    for (std::int64_t i = i0 - 1; i <= i0 + 1; ++i) {
      const double h = thread(
          seed_warp_, i, a, b, [&](std::int64_t j) { return warpOver(i, j); }, &profile);
      if (h > s.height) s = {h, 1, profile, 0.0};
    }
    for (std::int64_t j = j0 - 1; j <= j0 + 1; ++j) {
      const double h = thread(
          seed_weft_, j, b, a, [&](std::int64_t i) { return !warpOver(i, j); }, &profile);
      if (h > s.height) s = {h, 2, profile, 0.0};
    }
    const double f = 3.0 / spacing_;       // fuzz at a third of the thread pitch and finer
    thread_local noise::FbmCache<3> fuzz;  // see noise.hpp: same bits, fewer hashes
    s.fuzz = noise::fbm2(fuzz, seed_fuzz_, x * f, y * f, 3);
    s.height += fuzz_ * s.fuzz;
    return s;
  }

  int weave_ = 0;
  double spacing_ = 1, half_width_ = 0.4, height_ = 0, cos_ = 1, sin_ = 0, fuzz_ = 0;
  double irregularity_ = 0;
  std::uint64_t seed_warp_ = 0, seed_weft_ = 0, seed_fuzz_ = 0;
};

}  // namespace

std::unique_ptr<ProceduralMaterial> makeFabric() { return std::make_unique<Fabric>(); }

}  // namespace materials
}  // namespace norm2tex
