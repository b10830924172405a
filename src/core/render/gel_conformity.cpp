#include "norm2tex/render/gel_conformity.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/common/simd_dispatch.hpp"

namespace norm2tex {
namespace {

constexpr int kBands = GelConformity::kBandCount;
constexpr double kPi = 3.14159265358979323846;
// The bands' statistics are global over the contact: a thousand samples are plenty, so a
// large contact is sampled on every 2nd to 8th row and column.
constexpr long kEnoughSamples = 1000;
// Bins of a band's values over the contact, for the mean rise of clipping it at a level.
constexpr int kBins = 256;
// Entries of the total mean rise as a function of the indentation (an 8-bit look-up).
constexpr int kRiseEntries = 256;

// Running sums of one band over the sampled contact.
struct BandSums {
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  double sum = 0.0, sum_sq = 0.0;           // of the values
  double step_sq_x = 0.0, step_sq_y = 0.0;  // of the squared steps to the next pixel in x, y
  std::array<double, kBins> counts{};
};

// Step 1's sums over one row of the indentation: its sum, the pixels in contact and the deepest,
// in eight lanes of floats (the counts are exact: a lane counts at most a row's 1/8). Written
// with GCC vector types: the loop vectoriser leaves a float sum alone (it may not reorder it) and
// does not vectorise lanes in arrays, and both builds then add in the same order.
constexpr int kLanes = 8;
typedef float Lanes __attribute__((vector_size(kLanes * sizeof(float))));
struct ContactLanes {
  Lanes sum, count, top;
};

NORM2TEX_ALWAYS_INLINE void contactRowBody(int n, const float* __restrict row, ContactLanes& out) {
  Lanes sum = {}, count = {}, top = {};
  const Lanes zero = {};
  int c = 0;
  for (; c + kLanes <= n; c += kLanes) {
    Lanes depth;
    std::memcpy(&depth, row + c, sizeof depth);
    sum += depth;
    count -= __builtin_convertvector(depth > zero, Lanes);  // true is -1
    top = depth > top ? depth : top;
  }
  for (; c < n; ++c) {  // the row's tail in lane 0
    sum[0] += row[c];
    count[0] += row[c] > 0.0f ? 1.0f : 0.0f;
    top[0] = std::max(top[0], row[c]);
  }
  out = {sum, count, top};
}

using ContactRowFunction = void (*)(int, const float*, ContactLanes&);
void contactRowBaseline(int n, const float* row, ContactLanes& out) { contactRowBody(n, row, out); }
#if NORM2TEX_HAS_AVX2_BUILD
NORM2TEX_TARGET_AVX2 void contactRowAvx2(int n, const float* row, ContactLanes& out) {
  contactRowBody(n, row, out);
}
const ContactRowFunction contactRow =
    pickSimd<ContactRowFunction>(contactRowAvx2, contactRowBaseline);
#else
const ContactRowFunction contactRow = contactRowBaseline;
#endif

// One row of step 6 (see GelConformity::run): each band clipped at its patch-edge level and
// summed, the mean rise looked up by the quantised indentation and taken off, and on the
// renderer's path H_final = clamp(followed - gap, 0, thickness). All three bands in one pass
// (a band folded into the next reads a row of zeros and a level of -inf, so it adds 0; the
// residual band's lower level is that row of zeros), so the row's data is read once.
struct FollowRow {
  const float* upper[kBands];
  const float* lower[kBands];
  float top[kBands], per_mm[kBands], full[kBands];
  const float* rise;  // the rise table, kRiseEntries entries
  float levels_per_mm;
};

NORM2TEX_ALWAYS_INLINE void followRowBody(int n, const FollowRow& a, const float* __restrict h,
                                          const float* __restrict gap, float thickness,
                                          float* __restrict out) {
  const float* __restrict u0 = a.upper[0];
  const float* __restrict u1 = a.upper[1];
  const float* __restrict u2 = a.upper[2];
  const float* __restrict l0 = a.lower[0];
  const float* __restrict l1 = a.lower[1];
  const float* __restrict l2 = a.lower[2];
  const float* __restrict rise = a.rise;
  for (int c = 0; c < n; ++c) {
    const float depth = h[c];
    float sum = 0.0f;
    sum += std::max(u0[c] - l0[c], a.top[0] - std::min(a.per_mm[0] * depth, a.full[0]));
    sum += std::max(u1[c] - l1[c], a.top[1] - std::min(a.per_mm[1] * depth, a.full[1]));
    sum += std::max(u2[c] - l2[c], a.top[2] - std::min(a.per_mm[2] * depth, a.full[2]));
    const int level = std::min(static_cast<int>(depth * a.levels_per_mm + 0.5f), kRiseEntries - 1);
    sum -= rise[level];
    out[c] = gap ? std::min(std::max(sum - gap[c], 0.0f), thickness) : sum;
  }
}

using FollowRowFunction = void (*)(int, const FollowRow&, const float*, const float*, float,
                                   float*);

// Two copies of the loop, so that the compiler hoists the gap test out of each.
void followRowBaseline(int n, const FollowRow& a, const float* h, const float* gap, float thickness,
                       float* out) {
  if (gap) {
    followRowBody(n, a, h, gap, thickness, out);
  } else {
    followRowBody(n, a, h, nullptr, thickness, out);
  }
}

#if NORM2TEX_HAS_AVX2_BUILD
NORM2TEX_TARGET_AVX2 void followRowAvx2(int n, const FollowRow& a, const float* h, const float* gap,
                                        float thickness, float* out) {
  if (gap) {
    followRowBody(n, a, h, gap, thickness, out);
  } else {
    followRowBody(n, a, h, nullptr, thickness, out);
  }
}
const FollowRowFunction followRow = pickSimd<FollowRowFunction>(followRowAvx2, followRowBaseline);
#else
const FollowRowFunction followRow = followRowBaseline;
#endif

// One run's state, as each step leaves it for the next (GelConformity::run).
struct Pass {
  cv::Rect box;
  cv::Mat1f h;  // H_sensor over the box, >= 0 (the rasterizer clamps it)
  double pixel_area = 0.0;
  long contact_pixels = 0;
  float deepest = 0.0f;
  double pressure_per_mm = 0.0;  // the pressure at 1 mm of indentation, MPa
  // The bands: band k runs from pyramid level fine[k] to level coarse[k] (kBands: nothing, the
  // residual); a folded band (inactive) gives its levels to the next coarser one. Every level is
  // continuous and box-sized, so a pixel is one offset into each.
  const float* level_data[kBands] = {nullptr, nullptr, nullptr};
  std::array<int, kBands> fine{0, 1, 2}, coarse{1, 2, kBands};
  std::array<bool, kBands> active{true, true, true};
  // The sampled contact (step 3).
  bool anywhere = false;  // no contact: sample all of the box
  long samples = 0;
  const int* offsets = nullptr;
  std::array<BandSums, kBands> sums;
  std::array<double, kBands> bin_width{};
  // Each band's clipping: its crest, how far its edge level sinks per mm of indentation, and at
  // most (step 4).
  std::array<float, kBands> crest{}, sink_per_mm{}, full_sink{};

  float bandAt(int k, int offset) const {
    return coarse[k] < kBands ? level_data[fine[k]][offset] - level_data[coarse[k]][offset]
                              : level_data[fine[k]][offset];
  }
  float levelAt(int k, float depth) const {
    return crest[k] - std::min(sink_per_mm[k] * depth, full_sink[k]);
  }
};

// 1. The pressure: the force spread in proportion to the indentation (a Winkler foundation).
void measurePressure(Pass& pass, double normal_force_n, double mm_per_pixel,
                     ConformityStats& stats) {
  const cv::Mat1f& h = pass.h;
  double indentation_sum = 0.0;
  for (int r = 0; r < h.rows; ++r) {
    ContactLanes lanes;
    contactRow(h.cols, h.ptr<float>(r), lanes);
    for (int j = 0; j < kLanes; ++j) {
      indentation_sum += lanes.sum[j];
      pass.contact_pixels += static_cast<long>(lanes.count[j]);
      pass.deepest = std::max(pass.deepest, lanes.top[j]);
    }
  }
  pass.pixel_area = mm_per_pixel * mm_per_pixel;
  stats.contact_area_mm2 = pass.contact_pixels * pass.pixel_area;
  stats.mean_pressure_mpa =  // N / mm^2 = MPa
      pass.contact_pixels > 0 ? normal_force_n / stats.contact_area_mm2 : 0.0;
  pass.pressure_per_mm =
      indentation_sum > 0.0 ? normal_force_n / (indentation_sum * pass.pixel_area) : 0.0;
}

// 2. The bands: differences of successive blurs of the relief, a Gaussian pyramid (each level
//    the 5-tap binomial and every second pixel), each level expanded back to full resolution:
//    cheap, and the bands telescope, summing to the relief exactly.
void buildPyramid(const cv::Mat1f& relief_unit, double beta_mm,
                  std::array<cv::Mat1f, kBands>& smoothed, std::array<cv::Mat1f, 2>& half,
                  cv::Mat1f& up, Pass& pass) {
  const cv::Size size = relief_unit.size();
  relief_unit.convertTo(smoothed[0], CV_32F, beta_mm);  // the relief, mm
  cv::pyrDown(smoothed[0], half[0], cv::Size((size.width + 1) / 2, (size.height + 1) / 2),
              cv::BORDER_DEFAULT);
  cv::pyrDown(half[0], half[1], cv::Size((half[0].cols + 1) / 2, (half[0].rows + 1) / 2),
              cv::BORDER_DEFAULT);
  // Back up by pyrUp, aligned with pyrDown's grid (a resize would shift each level by a
  // fraction of its pixel, and the differences would hold that shift, not texture).
  cv::pyrUp(half[0], smoothed[1], size, cv::BORDER_DEFAULT);
  cv::pyrUp(half[1], up, half[0].size(), cv::BORDER_DEFAULT);
  cv::pyrUp(up, smoothed[2], size, cv::BORDER_DEFAULT);
  for (int k = 0; k < kBands; ++k) pass.level_data[k] = smoothed[k].ptr<float>();
}

// 3. Where to sample the bands' statistics: contact pixels (all of the box when only crests
//    touch) on a grid, off the box's border so that each has its neighbours.
void sampleContact(Pass& pass, std::vector<int>& offsets, std::vector<float>& depths) {
  const cv::Rect& box = pass.box;
  pass.anywhere = pass.contact_pixels == 0;
  const long region = pass.anywhere ? long(box.area()) : pass.contact_pixels;
  const int stride =
      std::max(1, std::min(8, static_cast<int>(std::sqrt(double(region) / kEnoughSamples))));
  offsets.clear();
  depths.clear();
  for (int r = 1; r + 1 < box.height; r += stride) {
    const float* hr = pass.h.ptr<float>(r);
    for (int c = 1; c + 1 < box.width; c += stride) {
      if (!pass.anywhere && !(hr[c] > 0.0f)) continue;
      offsets.push_back(r * box.width + c);
      depths.push_back(hr[c]);
    }
  }
  pass.samples = static_cast<long>(offsets.size());
  pass.offsets = offsets.data();
}

//    Then each band's statistics over the samples. A band with under 5 % of the relief's RMS is
//    folded into the next coarser one: it holds no wavelength of its own, only the tail of a
//    neighbour's (a pure sinusoid leaves a sliver in every band), and its statistics would be
//    the interpolation's, not the texture's.
void bandStatistics(Pass& pass, ConformityStats& stats) {
  const long samples = pass.samples;
  const int* const offsets = pass.offsets;
  const auto rmsOver = [&](const auto& value) {
    double sum = 0.0, sum_sq = 0.0;
    for (long i = 0; i < samples; ++i) {
      const double v = value(offsets[i]);
      sum += v;
      sum_sq += v * v;
    }
    const double mean = samples > 0 ? sum / samples : 0.0;
    return samples > 0 ? std::sqrt(std::max(0.0, sum_sq / samples - mean * mean)) : 0.0;
  };
  const double relief_rms = rmsOver([&](int o) { return pass.level_data[0][o]; });
  for (int k = 0, start = 0; k < kBands; ++k) {
    pass.fine[k] = start;
    if (k + 1 < kBands && rmsOver([&](int o) { return pass.bandAt(k, o); }) < 0.05 * relief_rms) {
      pass.active[k] = false;  // its levels go to band k + 1
      continue;
    }
    start = k + 1;
  }
  // Each band's extremes, RMS and RMS step to the next pixel, then its histogram.
  double relief_min = std::numeric_limits<double>::infinity(), relief_max = -relief_min;
  {
    const float* relief = pass.level_data[0];
    for (long i = 0; i < samples; ++i) {
      relief_min = std::min(relief_min, double(relief[offsets[i]]));
      relief_max = std::max(relief_max, double(relief[offsets[i]]));
    }
  }
  for (int k = 0; k < kBands; ++k) {
    if (!pass.active[k]) continue;
    const int w = pass.box.width;
    BandSums& s = pass.sums[k];
    for (long i = 0; i < samples; ++i) {
      const int o = offsets[i];
      const double v = pass.bandAt(k, o);
      s.min = std::min(s.min, v);
      s.max = std::max(s.max, v);
      s.sum += v;
      s.sum_sq += v * v;
      const double dx = pass.bandAt(k, o + 1) - v, dy = pass.bandAt(k, o + w) - v;
      s.step_sq_x += dx * dx;
      s.step_sq_y += dy * dy;
    }
    pass.bin_width[k] = std::max(s.max - s.min, 1e-12) / kBins;
    const double bins_per_mm = 1.0 / pass.bin_width[k];
    for (long i = 0; i < samples; ++i) {
      const int bin = static_cast<int>((pass.bandAt(k, offsets[i]) - s.min) * bins_per_mm);
      s.counts[std::min(std::max(bin, 0), kBins - 1)] += 1.0;
    }
  }
  stats.relief_amplitude_mm = samples > 0 ? 0.5 * (relief_max - relief_min) : 0.0;
}

// 4. Per band: Johnson's p*, and its patch-edge level at indentation h,
//    level = crest - 2 A p / p* with p = pressure_per_mm h: the band's lowest value at p*,
//    and lower still beyond (nothing clipped); -inf for a flat band.
void clipLevels(Pass& pass, const std::vector<float>& sample_depths, double contact_modulus_mpa,
                double coating_length_mm, double mm_per_pixel, ConformityStats& stats) {
  const long samples = pass.samples;
  for (int k = 0; k < kBands; ++k) {
    const BandSums& s = pass.sums[k];
    ConformityBand& out = stats.bands[k];
    pass.crest[k] = -std::numeric_limits<float>::infinity();
    if (samples == 0 || !pass.active[k]) continue;
    const double mean = s.sum / samples;
    const double variance = std::max(0.0, s.sum_sq / samples - mean * mean);
    out.amplitude_mm = 0.5 * (s.max - s.min);
    if (!(out.amplitude_mm > 0.0) || !(variance > 0.0)) continue;
    // The dominant wavenumber from the RMS step to the next pixel: a sinusoid of wavenumber w
    // (per pixel) steps by 2 sin(w / 2) times its RMS, inverted exactly per axis (a central
    // difference's sin(w) / w would make the finest band's wavelength up to 1.7x too long).
    const auto wavenumberAlong = [&](double step_sq) {
      const double ratio = std::sqrt(step_sq / samples / variance);
      return 2.0 * std::asin(std::min(1.0, 0.5 * ratio));
    };
    const double wx = wavenumberAlong(s.step_sq_x), wy = wavenumberAlong(s.step_sq_y);
    const double wavenumber_per_mm = std::sqrt(wx * wx + wy * wy) / mm_per_pixel;
    if (!(wavenumber_per_mm > 0.0)) continue;
    out.wavelength_mm = 2.0 * kPi / wavenumber_per_mm;
    // A coating over the gel bends into short wavelengths only at a higher pressure (a plate on
    // an elastic half-space; exactly 1 without one, so the frames are Johnson's).
    const double coating = 1.0 + std::pow(2.0 * kPi * coating_length_mm / out.wavelength_mm, 3);
    out.full_contact_pressure_mpa =
        kPi * (contact_modulus_mpa * coating) * stats.relief_amplitude_mm / out.wavelength_mm;
    pass.crest[k] = static_cast<float>(s.max);
    pass.full_sink[k] = static_cast<float>(4.0 * out.amplitude_mm);  // see step 6
    pass.sink_per_mm[k] = static_cast<float>(2.0 * out.amplitude_mm * pass.pressure_per_mm /
                                             out.full_contact_pressure_mpa);
    // The depth it follows, min(1, p / p*), averaged over the (sampled) contact.
    if (!pass.anywhere) {
      const double ratio_per_mm = pass.pressure_per_mm / out.full_contact_pressure_mpa;
      double followed = 0.0;
      for (long i = 0; i < samples; ++i) {
        followed += std::min(1.0, ratio_per_mm * sample_depths[i]);
      }
      out.followed_fraction = followed / samples;
    }
  }
}

// 5. Clipping a band at level L raises its mean by rise(L) = mean over the contact of
//    (L - band)+. The gel's mean indentation is the physics' (the law gives the force for
//    H_sensor), so each pixel's rise is taken off again: the texture only redistributes the
//    indentation, and where p = 0 a band sits at its mean. rise(L) from the band's histogram
//    (right for any distribution of heights, not only a sinusoid's); the levels depend on
//    the indentation only, so the rise of all bands is tabulated against it.
void tabulateRise(const Pass& pass, cv::Mat1f& rise_table) {
  const long samples = pass.samples;
  // Prefix sums over the bins: count and sum of the bin centres below each bin edge.
  std::array<std::array<double, kBins + 1>, kBands> below_count{}, below_sum{};
  for (int k = 0; k < kBands; ++k) {
    for (int j = 0; j < kBins; ++j) {
      const double centre = pass.sums[k].min + (j + 0.5) * pass.bin_width[k];
      below_count[k][j + 1] = below_count[k][j] + pass.sums[k].counts[j];
      below_sum[k][j + 1] = below_sum[k][j] + pass.sums[k].counts[j] * centre;
    }
  }
  const auto riseAt = [&](int k, float level) {
    if (!(level > pass.sums[k].min)) return 0.0;
    const double edge = std::floor((level - pass.sums[k].min) / pass.bin_width[k] + 0.5);
    const int j = static_cast<int>(std::min(edge, double(kBins)));  // bins with centre < level
    return (level * below_count[k][j] - below_sum[k][j]) / samples;
  };
  rise_table.create(1, kRiseEntries);
  const double depth_step = std::max(double(pass.deepest), 1e-9) / (kRiseEntries - 1);
  for (int i = 0; i < kRiseEntries; ++i) {
    double rise = 0.0;
    for (int k = 0; k < kBands; ++k) {
      if (pass.crest[k] > -std::numeric_limits<float>::infinity()) {
        rise += riseAt(k, pass.levelAt(k, static_cast<float>(i * depth_step)));
      }
    }
    rise_table(0, i) = static_cast<float>(rise);
  }
}

// 6. The followed relief: every band clipped at its edge level, the mean rise taken off
//    (looked up by the indentation quantised to the table's entries), then, on the renderer's
//    path, H_final from it; one pass over each row (followRow).
void writeFollowed(const Pass& pass, const std::array<cv::Mat1f, kBands>& smoothed,
                   const cv::Mat1f& rise_table, std::vector<float>& zeros, const cv::Mat1f* gap_mm,
                   float thickness_mm, cv::Mat1f& out_mm) {
  const cv::Rect& box = pass.box;
  FollowRow args;
  zeros.assign(box.width, 0.0f);
  for (int k = 0; k < kBands; ++k) {
    args.top[k] = pass.active[k] ? pass.crest[k] : -std::numeric_limits<float>::infinity();
    args.per_mm[k] = pass.active[k] ? pass.sink_per_mm[k] : 0.0f;
    args.full[k] = pass.active[k] ? pass.full_sink[k] : 0.0f;
  }
  args.rise = rise_table.ptr<float>();
  args.levels_per_mm =
      static_cast<float>((kRiseEntries - 1) / std::max(double(pass.deepest), 1e-9));
  for (int r = 0; r < box.height; ++r) {
    for (int k = 0; k < kBands; ++k) {
      args.upper[k] = pass.active[k] ? smoothed[pass.fine[k]].ptr<float>(r) : zeros.data();
      args.lower[k] = pass.active[k] && pass.coarse[k] < kBands
                          ? smoothed[pass.coarse[k]].ptr<float>(r)
                          : zeros.data();
    }
    float* out = out_mm.ptr<float>(box.y + r) + box.x;
    const float* gap = gap_mm ? gap_mm->ptr<float>(box.y + r) + box.x : nullptr;
    followRow(box.width, args, pass.h.ptr<float>(r), gap, thickness_mm, out);
  }
}

}  // namespace

GelConformity::GelConformity(const ConformityOptions& options, double mm_per_pixel)
    : options_(options), mm_per_pixel_(mm_per_pixel) {
  if (!(options_.contact_modulus_mpa > 0.0 && options_.contact_modulus_mpa <= 100.0)) {
    throw Error("conformity.contact_modulus_mpa = " + std::to_string(options_.contact_modulus_mpa) +
                " is out of range; valid: (0, 100] MPa");
  }
  if (!(mm_per_pixel_ > 0.0 && std::isfinite(mm_per_pixel_))) {
    throw Error("GelConformity: mm_per_pixel = " + std::to_string(mm_per_pixel_) +
                " is out of range; valid: > 0");
  }
}

ConformityStats GelConformity::apply(const cv::Mat1f& h_sensor_mm, const cv::Mat1f& h_local,
                                     double beta_mm, cv::Rect box, double normal_force_n,
                                     cv::Mat1f& followed_mm) {
  return run(h_sensor_mm, h_local, beta_mm, box, normal_force_n, nullptr, 0.0f, followed_mm);
}

ConformityStats GelConformity::applyToFinal(const cv::Mat1f& h_sensor_mm, const cv::Mat1f& h_local,
                                            double beta_mm, cv::Rect box, double normal_force_n,
                                            const cv::Mat1f& gap_mm, double thickness_mm,
                                            cv::Mat1f& h_final_mm) {
  if (gap_mm.size() != h_local.size() || h_final_mm.size() != h_local.size()) {
    throw Error("GelConformity: the gap, H_final and the relief differ in size");
  }
  return run(h_sensor_mm, h_local, beta_mm, box, normal_force_n, &gap_mm,
             static_cast<float>(thickness_mm), h_final_mm);
}

ConformityStats GelConformity::run(const cv::Mat1f& h_sensor_mm, const cv::Mat1f& h_local,
                                   double beta_mm, cv::Rect box, double normal_force_n,
                                   const cv::Mat1f* gap_mm, float thickness_mm, cv::Mat1f& out_mm) {
  if (!(std::isfinite(normal_force_n) && normal_force_n >= 0.0)) {
    throw Error("normal force = " + std::to_string(normal_force_n) +
                " N is not valid; valid: a finite force >= 0 N");
  }
  if (!(std::isfinite(beta_mm) && beta_mm >= 0.0)) {
    throw Error("GelConformity: beta = " + std::to_string(beta_mm) + " mm; valid: >= 0 mm");
  }
  if (h_sensor_mm.size() != h_local.size()) {
    throw Error("GelConformity: the indentation and the relief differ in size");
  }
  if (out_mm.size() != h_local.size()) out_mm = cv::Mat1f::zeros(h_local.size());
  ConformityStats stats;
  stats.normal_force_n = normal_force_n;
  box &= cv::Rect(0, 0, h_local.cols, h_local.rows);
  if (box.empty()) return stats;

  // The steps (each above, numbered as in the class's comment).
  Pass pass;
  pass.box = box;
  pass.h = h_sensor_mm(box);
  measurePressure(pass, normal_force_n, mm_per_pixel_, stats);
  buildPyramid(h_local(box), beta_mm, smoothed_, half_, up_, pass);
  sampleContact(pass, sample_offsets_, sample_depths_);
  bandStatistics(pass, stats);
  clipLevels(pass, sample_depths_, options_.contact_modulus_mpa, options_.coating_length_mm,
             mm_per_pixel_, stats);
  tabulateRise(pass, rise_table_);
  writeFollowed(pass, smoothed_, rise_table_, zeros_, gap_mm, thickness_mm, out_mm);
  return stats;
}

}  // namespace norm2tex
