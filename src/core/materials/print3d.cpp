// 3-D print (FDM): the side wall of a printed part. Rounded extrusion beads stacked at the layer
// pitch, with cusps between layers, per-layer variation of the bead, a slight wobble of the
// layer lines, and faint rasterised infill (two line families at +-infill_angle to the layers)
// showing through the wall.

#include <cmath>

#include "materials.hpp"
#include "noise.hpp"

namespace norm2tex {
namespace materials {
namespace {

class Print3d final : public ProceduralMaterial {
 public:
  enum Index { kPitch, kAngle, kDepth, kVariation, kInfillAmplitude, kInfillSpacing, kInfillAngle };

  Print3d()
      : ProceduralMaterial({
            {"layer_pitch_mm", 0.2, 0.05, 0.6, "mm", "layer height: distance between layer lines"},
            {"layer_angle_deg", 0.0, -180.0, 180.0, "deg",
             "direction the layer lines run, from +x towards +y"},
            {"layer_depth_mm", 0.012, 0.0, 0.1, "mm", "depth of the cusp between two layers"},
            {"layer_variation", 0.15, 0.0, 1.0, "",
             "per-layer variation of the bead and wobble of the layer lines (relative)"},
            {"infill_amplitude_mm", 0.0015, 0.0, 0.02, "mm",
             "relief of the infill pattern showing through the wall"},
            {"infill_spacing_mm", 2.0, 0.5, 5.0, "mm", "distance between infill lines"},
            {"infill_angle_deg", 45.0, 10.0, 90.0, "deg",
             "angle of the two infill line families to the layer lines (+ and -)"},
        }) {
    update();
  }

  std::string name() const override { return "print3d"; }

  double heightMm(double x_mm, double y_mm) const override {
    return evaluate(x_mm, y_mm, threadCaches()).height;
  }

  cv::Mat1f renderHeightMm(cv::Size size, double mm_per_texel,
                           cv::Point2d origin_mm) const override {
    Caches& caches = threadCaches();
    return renderHeightGrid(size, mm_per_texel, origin_mm,
                            [&](double x, double y) { return evaluate(x, y, caches).height; });
  }

  cv::Vec3b albedo(double x_mm, double y_mm) const override {
    const Sample s = evaluate(x_mm, y_mm, threadCaches());
    // Orange PLA: bead crowns catch the light, the cusps between layers look darker.
    const cv::Vec3d base(40, 120, 235);
    const double shade = 0.72 + 0.28 * s.bead + 0.03 * s.infill;
    cv::Vec3b colour;
    for (int k = 0; k < 3; ++k) colour[k] = cv::saturate_cast<uchar>(base[k] * shade);
    return colour;
  }

 private:
  struct Sample {
    double height;
    double bead;    ///< bead profile in [0, 1], 0 at the cusps
    double infill;  ///< infill pattern in [0, 1]
  };

  void update() override {
    pitch_ = value(kPitch);
    const double angle = value(kAngle) * kDegToRad;
    cos_ = std::cos(angle);
    sin_ = std::sin(angle);
    depth_ = value(kDepth);
    variation_ = value(kVariation);
    infill_amplitude_ = value(kInfillAmplitude);
    infill_spacing_ = value(kInfillSpacing);
    const double phi = value(kInfillAngle) * kDegToRad;
    // Normals (across directions) of the two infill line families at angle +-phi.
    n1x_ = -std::sin(angle + phi);
    n1y_ = std::cos(angle + phi);
    n2x_ = -std::sin(angle - phi);
    n2y_ = std::cos(angle - phi);
    seed_wobble_ = noise::derive(seed(), 1);
    seed_layer_ = noise::derive(seed(), 2);
    // Where the infill lines fall depends on the part: a random phase per family.
    const std::uint64_t infill = noise::derive(seed(), 3);
    phase1_ = noise::unit(infill);
    phase2_ = noise::unit(noise::mix64(infill));
  }

  /// Raised line of the infill, smooth (C1), centred on half-integers of t, zero at integers.
  static double infillLine(double t) {
    const double g = t - static_cast<double>(noise::floorInt(t));
    const double b = 4.0 * g * (1.0 - g);
    return b * b;
  }

  /// Noise look-ups of one thread's last texels (see noise.hpp); same bits as without.
  struct Caches {
    noise::GradientCell wobble;
    bool layer_used = false;
    std::uint64_t layer_seed = 0;
    std::int64_t layer_index = 0;
    std::uint64_t layer_hash = 0;
    noise::GradientInterval bulge;
  };

  static Caches& threadCaches() {
    thread_local Caches caches;
    return caches;
  }

  Sample evaluate(double x, double y, Caches& caches) const {
    const double u = cos_ * x + sin_ * y;   // along the layers
    const double v = -sin_ * x + cos_ * y;  // across (build direction)
    // The nozzle's path wanders slightly: layer lines wobble by up to a quarter pitch.
    const double vw =
        v + 0.25 * variation_ * pitch_ *
                noise::gradient2(caches.wobble, seed_wobble_, u / 1.5, v / (6.0 * pitch_));
    const double t = vw / pitch_;
    const std::int64_t n = noise::floorInt(t);
    const double q = 2.0 * (t - static_cast<double>(n)) - 1.0;  // -1 .. 1 across one layer
    const double q2 = q * q;
    Sample s;
    s.bead = 1.0 - q2 * q2;  // flat-topped bead, cusp at the layer seams
    // Each layer's bead: its own bulge, varying slowly along the layer (extrusion rate). The
    // bead factor multiplies a profile that is 0 at the seams, so layers join continuously.
    if (!caches.layer_used || caches.layer_index != n || caches.layer_seed != seed_layer_) {
      caches.layer_hash = noise::hash1(seed_layer_, n);
      caches.layer_used = true;
      caches.layer_seed = seed_layer_;
      caches.layer_index = n;
    }
    const std::uint64_t layer = caches.layer_hash;
    const double bulge = 1.0 + variation_ * (noise::unit(layer) - 0.5) +
                         0.3 * variation_ * noise::gradient1(caches.bulge, layer, u / 0.8);
    s.infill = 0.5 * (infillLine((n1x_ * x + n1y_ * y) / infill_spacing_ + phase1_) +
                      infillLine((n2x_ * x + n2y_ * y) / infill_spacing_ + phase2_));
    s.height = depth_ * (bulge * s.bead - 1.0) + infill_amplitude_ * s.infill;
    return s;
  }

  double pitch_ = 0.2, cos_ = 1, sin_ = 0, depth_ = 0, variation_ = 0;
  double infill_amplitude_ = 0, infill_spacing_ = 1, n1x_ = 0, n1y_ = 1, n2x_ = 0, n2y_ = 1;
  double phase1_ = 0, phase2_ = 0;
  std::uint64_t seed_wobble_ = 0, seed_layer_ = 0;
};

}  // namespace

std::unique_ptr<ProceduralMaterial> makePrint3d() { return std::make_unique<Print3d>(); }

}  // namespace materials
}  // namespace norm2tex
