// 3-D print (FDM): the side wall of a printed part. Rounded extrusion beads stacked at the layer
// pitch, with cusps between layers, per-layer variation of the bead, a slight wobble of the
// layer lines, and faint rasterised infill (two line families at +-infill_angle to the layers)
// showing through the wall.

#include <algorithm>
#include <cmath>

#include "materials.hpp"
#include "noise.hpp"
#include "norm2tex/common/huge_pages.hpp"
#include "norm2tex/common/simd_dispatch.hpp"

namespace norm2tex {
namespace materials {
namespace {

/// The relief's parameters, as evaluate() and the row kernel read them.
struct Layers {
  double pitch = 0.2, cos = 1, sin = 0, depth = 0, variation = 0;
  double infill_amplitude = 0, infill_spacing = 1, n1x = 0, n1y = 1, n2x = 0, n2y = 1;
  double phase1 = 0, phase2 = 0;
  std::uint64_t seed_wobble = 0, seed_layer = 0;
};

/// Noise look-ups of one thread's last texels (see noise.hpp); same bits as without.
struct Caches {
  noise::GradientCell wobble;
  bool layer_used = false;
  std::uint64_t layer_seed = 0;
  std::int64_t layer_index = 0;
  std::uint64_t layer_hash = 0;
  noise::GradientInterval bulge;
};

Caches& threadCaches() {
  thread_local Caches caches;
  return caches;
}

/// The hash of layer n, through the cache.
inline std::uint64_t layerHash(const Layers& p, Caches& caches, std::int64_t n) {
  if (!caches.layer_used || caches.layer_index != n || caches.layer_seed != p.seed_layer) {
    caches.layer_hash = noise::hash1(p.seed_layer, n);
    caches.layer_used = true;
    caches.layer_seed = p.seed_layer;
    caches.layer_index = n;
  }
  return caches.layer_hash;
}

/// Raised line of the infill, smooth (C1), centred on half-integers of t, zero at integers;
/// `floored` is floor(t).
inline double infillLine(double t, double floored) {
  const double g = t - floored;
  const double b = 4.0 * g * (1.0 - g);
  return b * b;
}

// The row kernel: evaluate()'s arithmetic for up to kChunk texels of one row, split into loops
// that vectorise (the arithmetic, five divisions a texel among it) and loops point by point
// (lattice cells and hashes, cached as in evaluate). The same operations in the same order, so
// the same bits: the core builds with -ffp-contract=off (simd_dispatch.hpp). Per texel,
// evaluate() took ~30 ns, a third of a 2048^2 variant's preparation.
constexpr int kChunk = 256;

NORM2TEX_ALWAYS_INLINE void heightChunkBody(const Layers& p, Caches& caches,
                                            const double* __restrict x, double y, int count,
                                            float* __restrict out) {
  alignas(32) double u[kChunk], v[kChunk], wx[kChunk], wy[kChunk], fx[kChunk], fy[kChunk];
  alignas(32) double g[8][kChunk], t[kChunk], floored[kChunk];
  for (int i = 0; i < count; ++i) {
    u[i] = p.cos * x[i] + p.sin * y;   // along the layers
    v[i] = -p.sin * x[i] + p.cos * y;  // across (build direction)
    wx[i] = u[i] / 1.5;
    wy[i] = v[i] / (6.0 * p.pitch);
  }
  // The wobble's lattice cells, point by point (hashes only where the cell changes).
  noise::GradientCell& cell = caches.wobble;
  for (int i = 0; i < count; ++i) {
    const std::int64_t ix = noise::floorInt(wx[i]), iy = noise::floorInt(wy[i]);
    noise::detail::enterCell(cell, p.seed_wobble, ix, iy);
    fx[i] = wx[i] - static_cast<double>(ix);
    fy[i] = wy[i] - static_cast<double>(iy);
    for (int k = 0; k < 4; ++k) {
      g[2 * k][i] = cell.g[k][0];
      g[2 * k + 1][i] = cell.g[k][1];
    }
  }
  for (int i = 0; i < count; ++i) {
    const double c00[2] = {g[0][i], g[1][i]}, c10[2] = {g[2][i], g[3][i]};
    const double c01[2] = {g[4][i], g[5][i]}, c11[2] = {g[6][i], g[7][i]};
    const double* const corners[4] = {c00, c10, c01, c11};
    const double wobble = noise::detail::blendCorners(corners, fx[i], fy[i]);
    t[i] = (v[i] + 0.25 * p.variation * p.pitch * wobble) / p.pitch;
    wx[i] = u[i] / 0.8;  // the bulge's coordinate along the layer
  }
  // Layer index, its hash and the bulge's interval, point by point (into free arrays).
  double* const layer_unit = wy;
  double* const bulge_g0 = g[0];
  double* const bulge_g1 = g[1];
  double* const bulge_f = fy;
  for (int i = 0; i < count; ++i) {
    const std::int64_t n = noise::floorInt(t[i]);
    floored[i] = static_cast<double>(n);
    const std::uint64_t layer = layerHash(p, caches, n);
    layer_unit[i] = noise::unit(layer);
    const std::int64_t ix = noise::floorInt(wx[i]);
    noise::detail::enterInterval(caches.bulge, layer, ix);
    bulge_g0[i] = caches.bulge.g0;
    bulge_g1[i] = caches.bulge.g1;
    bulge_f[i] = wx[i] - static_cast<double>(ix);
  }
  // The infill lines' coordinates, then their floors (floorInt: no libm call).
  double* const a1 = g[2];
  double* const a2 = g[3];
  double* const a1_floor = g[4];
  double* const a2_floor = g[5];
  for (int i = 0; i < count; ++i) {
    a1[i] = (p.n1x * x[i] + p.n1y * y) / p.infill_spacing + p.phase1;
    a2[i] = (p.n2x * x[i] + p.n2y * y) / p.infill_spacing + p.phase2;
  }
  for (int i = 0; i < count; ++i) {
    a1_floor[i] = static_cast<double>(noise::floorInt(a1[i]));
    a2_floor[i] = static_cast<double>(noise::floorInt(a2[i]));
  }
  for (int i = 0; i < count; ++i) {
    const double q = 2.0 * (t[i] - floored[i]) - 1.0;
    const double q2 = q * q;
    const double bead = 1.0 - q2 * q2;
    const double bulge =
        1.0 + p.variation * (layer_unit[i] - 0.5) +
        0.3 * p.variation * noise::detail::blendEnds(bulge_g0[i], bulge_g1[i], bulge_f[i]);
    const double infill = 0.5 * (infillLine(a1[i], a1_floor[i]) + infillLine(a2[i], a2_floor[i]));
    out[i] = static_cast<float>(p.depth * (bulge * bead - 1.0) + p.infill_amplitude * infill);
  }
}

void heightChunkBaseline(const Layers& p, Caches& caches, const double* x, double y, int count,
                         float* out) {
  heightChunkBody(p, caches, x, y, count, out);
}
#if NORM2TEX_HAS_AVX2_BUILD
NORM2TEX_TARGET_AVX2 void heightChunkAvx2(const Layers& p, Caches& caches, const double* x,
                                          double y, int count, float* out) {
  heightChunkBody(p, caches, x, y, count, out);
}
using HeightChunk = void (*)(const Layers&, Caches&, const double*, double, int, float*);
const HeightChunk heightChunk = pickSimd<HeightChunk>(heightChunkAvx2, heightChunkBaseline);
#else
const auto heightChunk = heightChunkBaseline;
#endif

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

  /// heightMm on the grid, bit for bit, a row chunk at a time through the row kernel.
  cv::Mat1f renderHeightMm(cv::Size size, double mm_per_texel,
                           cv::Point2d origin_mm) const override {
    checkGrid(size, mm_per_texel);
    cv::Mat1f image;
    createWithHugePages(image, size.height, size.width);  // a 2048^2 texture's 16 MB
    Caches& caches = threadCaches();
    alignas(32) double x[kChunk];
    for (int r = 0; r < size.height; ++r) {
      const double y = texelY(r, mm_per_texel, origin_mm);
      float* row = image.ptr<float>(r);
      for (int c0 = 0; c0 < size.width; c0 += kChunk) {
        const int count = std::min(kChunk, size.width - c0);
        for (int i = 0; i < count; ++i) x[i] = texelX(c0 + i, mm_per_texel, origin_mm);
        heightChunk(layers_, caches, x, y, count, row + c0);
      }
    }
    return image;
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
    layers_.pitch = value(kPitch);
    const double angle = value(kAngle) * kDegToRad;
    layers_.cos = std::cos(angle);
    layers_.sin = std::sin(angle);
    layers_.depth = value(kDepth);
    layers_.variation = value(kVariation);
    layers_.infill_amplitude = value(kInfillAmplitude);
    layers_.infill_spacing = value(kInfillSpacing);
    const double phi = value(kInfillAngle) * kDegToRad;
    // Normals (across directions) of the two infill line families at angle +-phi.
    layers_.n1x = -std::sin(angle + phi);
    layers_.n1y = std::cos(angle + phi);
    layers_.n2x = -std::sin(angle - phi);
    layers_.n2y = std::cos(angle - phi);
    layers_.seed_wobble = noise::derive(seed(), 1);
    layers_.seed_layer = noise::derive(seed(), 2);
    // Where the infill lines fall depends on the part: a random phase per family.
    const std::uint64_t infill = noise::derive(seed(), 3);
    layers_.phase1 = noise::unit(infill);
    layers_.phase2 = noise::unit(noise::mix64(infill));
  }

  /// One texel; heightChunkBody is the same arithmetic for a row.
  Sample evaluate(double x, double y, Caches& caches) const {
    const Layers& p = layers_;
    const double u = p.cos * x + p.sin * y;   // along the layers
    const double v = -p.sin * x + p.cos * y;  // across (build direction)
    // The nozzle's path wanders slightly: layer lines wobble by up to a quarter pitch.
    const double vw =
        v + 0.25 * p.variation * p.pitch *
                noise::gradient2(caches.wobble, p.seed_wobble, u / 1.5, v / (6.0 * p.pitch));
    const double t = vw / p.pitch;
    const std::int64_t n = noise::floorInt(t);
    const double q = 2.0 * (t - static_cast<double>(n)) - 1.0;  // -1 .. 1 across one layer
    const double q2 = q * q;
    Sample s;
    s.bead = 1.0 - q2 * q2;  // flat-topped bead, cusp at the layer seams
    // Each layer's bead: its own bulge, varying slowly along the layer (extrusion rate). The
    // bead factor multiplies a profile that is 0 at the seams, so layers join continuously.
    const std::uint64_t layer = layerHash(p, caches, n);
    const double bulge = 1.0 + p.variation * (noise::unit(layer) - 0.5) +
                         0.3 * p.variation * noise::gradient1(caches.bulge, layer, u / 0.8);
    const double a1 = (p.n1x * x + p.n1y * y) / p.infill_spacing + p.phase1;
    const double a2 = (p.n2x * x + p.n2y * y) / p.infill_spacing + p.phase2;
    s.infill = 0.5 * (infillLine(a1, static_cast<double>(noise::floorInt(a1))) +
                      infillLine(a2, static_cast<double>(noise::floorInt(a2))));
    s.height = p.depth * (bulge * s.bead - 1.0) + p.infill_amplitude * s.infill;
    return s;
  }

  Layers layers_;
};

}  // namespace

std::unique_ptr<ProceduralMaterial> makePrint3d() { return std::make_unique<Print3d>(); }

}  // namespace materials
}  // namespace norm2tex
