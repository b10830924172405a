// Rock: granular, cellular relief. Grains are Worley cells (warped by noise so they are not
// convex polygons), each a rounded dome of its own height that falls to a groove at the grain
// boundary, plus multi-octave fBm roughness from the grain scale down.

#include <cmath>

#include "materials.hpp"
#include "noise.hpp"

namespace norm2tex {
namespace materials {
namespace {

class Rock final : public ProceduralMaterial {
 public:
  enum Index {
    kGrainSize,
    kGrainRelief,
    kBoundaryWidth,
    kGrainIrregularity,
    kRoughnessMm,
    kRoughness,
    kOctaves
  };

  Rock()
      : ProceduralMaterial({
            {"grain_size_mm", 0.8, 0.1, 5.0, "mm", "mean grain diameter (Worley cell size)"},
            {"grain_relief_mm", 0.04, 0.0, 0.3, "mm",
             "height of the grain domes above the grooves"},
            {"boundary_width", 0.15, 0.02, 0.5, "",
             "width of the grooves between grains, in grain sizes"},
            {"grain_irregularity", 0.5, 0.0, 1.0, "", "noise warp of the grain shapes"},
            {"roughness_mm", 0.015, 0.0, 0.2, "mm", "amplitude of the multi-scale fBm roughness"},
            {"roughness", 0.55, 0.2, 0.8, "",
             "fBm gain per octave: higher keeps more fine detail (rougher)"},
            {"octaves", 5.0, 1.0, 8.0, "", "fBm octaves, each half the previous wavelength", true},
        }) {
    update();
  }

  std::string name() const override { return "rock"; }

  double heightMm(double x_mm, double y_mm) const override {
    const Sample s = evaluate(x_mm, y_mm);
    return relief_ * s.grain + roughness_mm_ * s.rough;
  }

  cv::Vec3b albedo(double x_mm, double y_mm) const override {
    const Sample s = evaluate(x_mm, y_mm);
    // Granite-like: grey grains of varied tone, some pinkish feldspar, some dark mica; grooves
    // darker.
    const double tone = noise::unit(s.id);
    cv::Vec3d base(150, 150, 150);
    if (tone < 0.2)
      base = cv::Vec3d(60, 60, 65);  // dark mineral
    else if (tone < 0.45)
      base = cv::Vec3d(150, 160, 195);  // pinkish
    else
      base *= 0.75 + 0.45 * noise::unit(noise::mix64(s.id));
    const double shade = (0.65 + 0.35 * s.edge) * (1.0 + 0.12 * s.rough);
    cv::Vec3b colour;
    for (int k = 0; k < 3; ++k) colour[k] = cv::saturate_cast<uchar>(base[k] * shade);
    return colour;
  }

 private:
  struct Sample {
    double grain;  ///< grain dome in [0, 1]
    double edge;   ///< 0 on a grain boundary, 1 inside
    double rough;  ///< fBm, about [-1, 1]
    std::uint64_t id;
  };

  void update() override {
    inv_grain_ = 1.0 / value(kGrainSize);
    relief_ = value(kGrainRelief);
    boundary_ = value(kBoundaryWidth);
    warp_ = 0.35 * value(kGrainIrregularity);
    roughness_mm_ = value(kRoughnessMm);
    gain_ = value(kRoughness);
    octaves_ = static_cast<int>(value(kOctaves));
    seed_cells_ = noise::derive(seed(), 1);
    seed_warp_x_ = noise::derive(seed(), 2);
    seed_warp_y_ = noise::derive(seed(), 3);
    seed_rough_ = noise::derive(seed(), 4);
  }

  /// Noise look-ups of one thread's last texels (see noise.hpp); same bits as without.
  struct Caches {
    noise::GradientCell warp_x, warp_y;
    noise::WorleyCell cells;
    noise::FbmCache<8> rough;  ///< up to the octaves parameter's maximum
  };

  Sample evaluate(double x, double y) const {
    thread_local Caches caches;
    // Everything in grain units.
    const double gx = x * inv_grain_, gy = y * inv_grain_;
    const double wx =
        gx + warp_ * noise::gradient2(caches.warp_x, seed_warp_x_, 0.7 * gx, 0.7 * gy);
    const double wy =
        gy + warp_ * noise::gradient2(caches.warp_y, seed_warp_y_, 0.7 * gx, 0.7 * gy);
    const noise::Worley w = noise::worley2(caches.cells, seed_cells_, wx, wy);
    // f2 - f1 is 0 on the boundary between two grains: the shoulder, and with it the grain's
    // random height, vanishes there, so the relief is continuous across grains.
    const double e = w.f2 - w.f1;
    const double d = e / boundary_;
    const double edge = d >= 1.0 ? 1.0 : d * (2.0 - d);  // rounded shoulder, flat top
    const double dome = 1.0 - 0.35 * w.f1 * w.f1;        // grains bulge in their middle
    Sample s;
    s.edge = edge;
    s.grain = edge * dome * (0.45 + 0.55 * noise::unit(noise::mix64(w.id ^ 0x5555)));
    s.rough = noise::fbm2(caches.rough, seed_rough_, 1.5 * gx, 1.5 * gy, octaves_, gain_);
    s.id = w.id;
    return s;
  }

  double inv_grain_ = 1, relief_ = 0, boundary_ = 0.15, warp_ = 0, roughness_mm_ = 0, gain_ = 0.5;
  int octaves_ = 5;
  std::uint64_t seed_cells_ = 0, seed_warp_x_ = 0, seed_warp_y_ = 0, seed_rough_ = 0;
};

}  // namespace

std::unique_ptr<ProceduralMaterial> makeRock() { return std::make_unique<Rock>(); }

}  // namespace materials
}  // namespace norm2tex
