// Wood: growth rings (latewood ridges between softer, worn-down earlywood) warped by noise,
// fine fibre streaks and elongated pores, all running along the grain direction.

#include <algorithm>
#include <cmath>

#include "materials.hpp"
#include "noise.hpp"

namespace norm2tex {
namespace materials {
namespace {

class Wood final : public ProceduralMaterial {
 public:
  enum Index {
    kGrainAngle,
    kRingSpacing,
    kRingIrregularity,
    kRingDepth,
    kLatewoodFraction,
    kLatewoodContrast,
    kPoreDensity,
    kPoreSize,
    kPoreElongation,
    kPoreDepth,
    kFibreDepth,
  };

  Wood()
      : ProceduralMaterial({
            {"grain_angle_deg", 0.0, -180.0, 180.0, "deg",
             "direction of the fibres and growth rings, from +x towards +y"},
            {"ring_spacing_mm", 1.6, 0.3, 10.0, "mm", "mean distance between growth rings"},
            {"ring_irregularity", 0.35, 0.0, 1.0, "",
             "noise warp of the rings, in ring spacings (0 = straight, even rings)"},
            {"ring_depth_mm", 0.012, 0.0, 0.1, "mm",
             "relief of the hard latewood above the worn earlywood"},
            {"latewood_fraction", 0.3, 0.05, 0.8, "", "fraction of each ring that is latewood"},
            {"latewood_contrast", 0.6, 0.0, 1.0, "",
             "early/late-wood contrast: sharpness of the transition and darkness of latewood"},
            {"pore_density_per_mm2", 4.0, 0.0, 40.0, "1/mm^2", "pores (vessels) per mm^2"},
            {"pore_size_mm", 0.08, 0.02, 0.4, "mm", "pore width across the grain"},
            {"pore_elongation", 6.0, 1.0, 12.0, "", "pore length along the grain / width"},
            {"pore_depth_mm", 0.02, 0.0, 0.1, "mm", "depth of an open pore"},
            {"fibre_depth_mm", 0.002, 0.0, 0.01, "mm",
             "relief of the fine streaks along the grain"},
        }) {
    update();
  }

  std::string name() const override { return "wood"; }

  double heightMm(double x_mm, double y_mm) const override {
    const Sample s = evaluate(x_mm, y_mm);
    return ring_depth_ * s.latewood + fibre_depth_ * s.fibre -
           pore_depth_ * s.pore * (1.0 - 0.85 * s.latewood);
  }

  cv::Vec3b albedo(double x_mm, double y_mm) const override {
    const Sample s = evaluate(x_mm, y_mm);
    static const cv::Vec3d kEarly(125, 175, 222), kLate(55, 95, 150);  // BGR
    const double late = contrast_ * s.latewood;
    const double shade = (1.0 + 0.08 * s.fibre) * (1.0 - 0.55 * s.pore * (1.0 - 0.85 * s.latewood));
    cv::Vec3b colour;
    for (int k = 0; k < 3; ++k) {
      colour[k] = cv::saturate_cast<uchar>((kEarly[k] + (kLate[k] - kEarly[k]) * late) * shade);
    }
    return colour;
  }

 private:
  struct Sample {
    double latewood;  ///< ring profile in [0, 1]: 0 earlywood, 1 latewood
    double fibre;     ///< fibre streak noise, about [-1, 1]
    double pore;      ///< pore depth profile in [0, 1]
  };

  void update() override {
    const double angle = value(kGrainAngle) * kDegToRad;
    cos_ = std::cos(angle);
    sin_ = std::sin(angle);
    spacing_ = value(kRingSpacing);
    warp_ = value(kRingIrregularity) * spacing_;
    // Rings bend slowly along the grain and vary their spacing across it.
    warp_scale_u_ = 1.0 / (5.0 * spacing_);
    warp_scale_v_ = 1.0 / (2.5 * spacing_);
    ring_depth_ = value(kRingDepth);
    latewood_ = value(kLatewoodFraction);
    contrast_ = value(kLatewoodContrast);
    // Earlywood -> latewood is gradual (wider for low contrast); latewood -> next year's
    // earlywood is abrupt (6% of a ring).
    fall_ = 0.06;
    rise_ = std::min(0.05 + 0.6 * (1.0 - contrast_) * (1.0 - latewood_), 1.0 - latewood_ - 0.02);
    pore_depth_ = value(kPoreDepth);
    const double density = value(kPoreDensity);
    pores_ = density > 0.0 && pore_depth_ > 0.0;
    if (pores_) {
      // One pore per cell; cells stretched like the pores keep the search to a few cells.
      const double side = 1.0 / std::sqrt(density), e = value(kPoreElongation);
      cell_u_ = side * std::sqrt(e);
      cell_v_ = side / std::sqrt(e);
      pore_half_width_ = 0.5 * value(kPoreSize);
      pore_half_length_ = pore_half_width_ * e;
    }
    fibre_depth_ = value(kFibreDepth);
    seed_warp_ = noise::derive(seed(), 1);
    seed_fibre_ = noise::derive(seed(), 2);
    seed_pores_ = noise::derive(seed(), 3);
  }

  /// One pore cell's hash draws, which depend on the seed and the cell only.
  struct PoreCell {
    bool used = false;
    std::uint64_t seed = 0;
    std::int64_t iu = 0, iv = 0;
    double at_u = 0, at_v = 0, size_draw = 0, depth_draw = 0;
  };

  /// Noise look-ups of one thread's last texels: neighbouring texels share lattice and pore
  /// cells, so most hashes are reused (noise.hpp). Same bits as without.
  struct Caches {
    noise::FbmCache<3> warp;
    noise::FbmCache<2> fibre;
    PoreCell pores[64];  ///< direct-mapped by cell
  };

  Sample evaluate(double x, double y) const {
    thread_local Caches caches;
    const double u = cos_ * x + sin_ * y;   // along the grain
    const double v = -sin_ * x + cos_ * y;  // across
    const double vw =
        v + warp_ * noise::fbm2(caches.warp, seed_warp_, u * warp_scale_u_, v * warp_scale_v_, 3);
    const double t = vw / spacing_;
    const double f = t - static_cast<double>(noise::floorInt(t));
    Sample s;
    s.latewood = noise::smoothstep(1.0 - latewood_ - rise_, 1.0 - latewood_, f) *
                 (1.0 - noise::smoothstep(1.0 - fall_, 1.0, f));
    // Fibres: long along the grain (2.5 mm), fine across it (0.15 mm); they follow the rings.
    s.fibre = noise::fbm2(caches.fibre, seed_fibre_, u * (1.0 / 2.5), vw * (1.0 / 0.15), 2);
    s.pore = pores_ ? pore(u, vw, caches.pores) : 0.0;
    return s;
  }

  /// Deepest pore profile (1 - r^2)^2 over the elliptic pores near (u, v): one pore per cell of
  /// a jittered grid in (along, warped across) coordinates, size varying +-30%.
  double pore(double u, double v, PoreCell (&cells)[64]) const {
    const double reach_u = 1.3 * pore_half_length_, reach_v = 1.3 * pore_half_width_;
    const std::int64_t iu0 = noise::floorInt((u - reach_u) / cell_u_);
    const std::int64_t iu1 = noise::floorInt((u + reach_u) / cell_u_);
    const std::int64_t iv0 = noise::floorInt((v - reach_v) / cell_v_);
    const std::int64_t iv1 = noise::floorInt((v + reach_v) / cell_v_);
    double deepest = 0.0;
    for (std::int64_t iv = iv0; iv <= iv1; ++iv) {
      for (std::int64_t iu = iu0; iu <= iu1; ++iu) {
        PoreCell& cell =
            cells[(static_cast<std::uint64_t>(iu) * 31u + static_cast<std::uint64_t>(iv)) & 63u];
        if (!cell.used || cell.iu != iu || cell.iv != iv || cell.seed != seed_pores_) {
          const std::uint64_t h = noise::hash2(seed_pores_, iu, iv);
          const std::uint64_t h2 = noise::mix64(h), h3 = noise::mix64(h2);
          cell = {true,
                  seed_pores_,
                  iu,
                  iv,
                  noise::unit(h),
                  noise::unit(h2),
                  noise::unit(h3),
                  noise::unit(noise::mix64(h3))};
        }
        const double size = 0.7 + 0.6 * cell.size_draw;
        const double du =
            (u - cell_u_ * (static_cast<double>(iu) + cell.at_u)) / (pore_half_length_ * size);
        const double dv =
            (v - cell_v_ * (static_cast<double>(iv) + cell.at_v)) / (pore_half_width_ * size);
        const double r2 = du * du + dv * dv;
        if (r2 < 1.0) {
          const double depth = (0.6 + 0.4 * cell.depth_draw) * (1.0 - r2) * (1.0 - r2);
          if (depth > deepest) deepest = depth;
        }
      }
    }
    return deepest;
  }

  double cos_ = 1, sin_ = 0, spacing_ = 1, warp_ = 0, warp_scale_u_ = 1, warp_scale_v_ = 1;
  double ring_depth_ = 0, latewood_ = 0.3, contrast_ = 0.5, rise_ = 0.1, fall_ = 0.06;
  bool pores_ = false;
  double pore_depth_ = 0, cell_u_ = 1, cell_v_ = 1, pore_half_width_ = 0, pore_half_length_ = 0;
  double fibre_depth_ = 0;
  std::uint64_t seed_warp_ = 0, seed_fibre_ = 0, seed_pores_ = 0;
};

}  // namespace

std::unique_ptr<ProceduralMaterial> makeWood() { return std::make_unique<Wood>(); }

}  // namespace materials
}  // namespace norm2tex
