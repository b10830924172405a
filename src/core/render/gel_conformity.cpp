#include "norm2tex/render/gel_conformity.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

constexpr int kBands = 4;
constexpr double kPi = 3.14159265358979323846;

// Running sums of one band over the statistics region.
struct BandSums {
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  double sum = 0.0, sum_sq = 0.0;  // of the values
  double slope_sq = 0.0;           // of |grad|^2 (per pixel^2), central differences
  long slope_count = 0;
};

// Bins of a band's values over the contact, for the mean rise of clipping it at a level.
constexpr int kBins = 256;

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

ConformityStats GelConformity::apply(const cv::Mat1f& h_sensor_mm, const cv::Mat1f& relief_mm,
                                     cv::Rect box, double normal_force_n,
                                     cv::Mat1f& followed_mm) {
  if (!(std::isfinite(normal_force_n) && normal_force_n >= 0.0)) {
    throw Error("normal force = " + std::to_string(normal_force_n) +
                " N is not valid; valid: a finite force >= 0 N");
  }
  if (h_sensor_mm.size() != relief_mm.size()) {
    throw Error("GelConformity: the indentation and the relief differ in size");
  }
  if (followed_mm.size() != relief_mm.size()) followed_mm = cv::Mat1f::zeros(relief_mm.size());
  ConformityStats stats;
  stats.normal_force_n = normal_force_n;
  box &= cv::Rect(0, 0, relief_mm.cols, relief_mm.rows);
  if (box.empty()) return stats;

  // The pressure: the force spread in proportion to the indentation (a Winkler foundation).
  const cv::Mat1f h = h_sensor_mm(box);
  double indentation_sum = 0.0;
  long contact_pixels = 0;
  for (int r = 0; r < h.rows; ++r) {
    const float* row = h.ptr<float>(r);
    for (int c = 0; c < h.cols; ++c) {
      if (row[c] > 0.0f) {
        indentation_sum += row[c];
        ++contact_pixels;
      }
    }
  }
  const double pixel_area = mm_per_pixel_ * mm_per_pixel_;
  stats.contact_area_mm2 = contact_pixels * pixel_area;
  stats.mean_pressure_mpa =  // N / mm^2 = MPa
      contact_pixels > 0 ? normal_force_n / stats.contact_area_mm2 : 0.0;
  const double pressure_per_mm =
      indentation_sum > 0.0 ? normal_force_n / (indentation_sum * pixel_area) : 0.0;

  // The bands: differences of successive Gaussians (each blur continues the previous one).
  relief_mm(box).copyTo(smoothed_[0]);
  double previous_sigma_px = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double sigma_px = kBandSigmasMm[i] / mm_per_pixel_;
    const double step = std::sqrt(sigma_px * sigma_px - previous_sigma_px * previous_sigma_px);
    cv::GaussianBlur(smoothed_[i], smoothed_[i + 1], cv::Size(), step, step, cv::BORDER_REFLECT);
    previous_sigma_px = sigma_px;
  }
  const auto band = [this](int k, int r, int c) -> float {
    return k < 3 ? smoothed_[k](r, c) - smoothed_[k + 1](r, c) : smoothed_[3](r, c);
  };

  // Statistics over the contact (over the whole box when only crests touch).
  std::array<BandSums, kBands> sums;
  double relief_min = std::numeric_limits<double>::infinity();
  double relief_max = -relief_min;
  for (int r = 0; r < box.height; ++r) {
    const float* hr = h.ptr<float>(r);
    for (int c = 0; c < box.width; ++c) {
      if (contact_pixels > 0 && !(hr[c] > 0.0f)) continue;
      relief_min = std::min(relief_min, static_cast<double>(smoothed_[0](r, c)));
      relief_max = std::max(relief_max, static_cast<double>(smoothed_[0](r, c)));
      const bool interior = r > 0 && c > 0 && r + 1 < box.height && c + 1 < box.width;
      for (int k = 0; k < kBands; ++k) {
        const double v = band(k, r, c);
        BandSums& s = sums[k];
        s.min = std::min(s.min, v);
        s.max = std::max(s.max, v);
        s.sum += v;
        s.sum_sq += v * v;
        if (interior) {
          const double gx = 0.5 * (band(k, r, c + 1) - band(k, r, c - 1));
          const double gy = 0.5 * (band(k, r + 1, c) - band(k, r - 1, c));
          s.slope_sq += gx * gx + gy * gy;
          ++s.slope_count;
        }
      }
    }
  }
  const long region_pixels = contact_pixels > 0 ? contact_pixels : long(box.area());
  stats.relief_amplitude_mm = 0.5 * (relief_max - relief_min);

  // Per band: the edge level at zero pressure (its crest), and how fast it sinks with pressure.
  std::array<float, kBands> crest{}, sink_per_mm{}, full_sink{};
  for (int k = 0; k < kBands; ++k) {
    const BandSums& s = sums[k];
    ConformityBand& out = stats.bands[k];
    const double mean = s.sum / region_pixels;
    const double variance = std::max(0.0, s.sum_sq / region_pixels - mean * mean);
    const double slope_rms = s.slope_count > 0 ? std::sqrt(s.slope_sq / s.slope_count) : 0.0;
    out.amplitude_mm = 0.5 * (s.max - s.min);
    if (!(out.amplitude_mm > 0.0) || !(slope_rms > 0.0) || !(variance > 0.0)) {
      // A flat band: nothing to clip; it passes unchanged.
      crest[k] = -std::numeric_limits<float>::infinity();
      continue;
    }
    const double wavenumber_per_mm = slope_rms / std::sqrt(variance) / mm_per_pixel_;
    out.wavelength_mm = 2.0 * kPi / wavenumber_per_mm;
    out.full_contact_pressure_mpa =
        kPi * options_.contact_modulus_mpa * stats.relief_amplitude_mm / out.wavelength_mm;
    // level = crest - 2 A min(1, p / p*), with p = pressure_per_mm * H_sensor.
    crest[k] = static_cast<float>(s.max);
    full_sink[k] = static_cast<float>(2.0 * out.amplitude_mm);
    sink_per_mm[k] = static_cast<float>(2.0 * out.amplitude_mm * pressure_per_mm /
                                        out.full_contact_pressure_mpa);
  }
  // The depth each band follows, min(1, p / p*), averaged over the contact.
  if (contact_pixels > 0) {
    for (int k = 0; k < kBands; ++k) {
      if (!(stats.bands[k].full_contact_pressure_mpa > 0.0)) continue;
      double sum = 0.0;
      const double scale = pressure_per_mm / stats.bands[k].full_contact_pressure_mpa;
      for (int r = 0; r < h.rows; ++r) {
        const float* hr = h.ptr<float>(r);
        for (int c = 0; c < h.cols; ++c) {
          if (hr[c] > 0.0f) sum += std::min(1.0, scale * hr[c]);
        }
      }
      stats.bands[k].followed_fraction = sum / contact_pixels;
    }
  }

  // Clipping a band at level L raises its mean by rise(L) = mean over the contact of
  // (L - band)+. The gel's mean indentation is the physics' (the law gives the force for
  // H_sensor), so each pixel's rise is taken off again: the texture only redistributes the
  // indentation, and where p = 0 a band sits at its mean. rise(L) from the band's histogram
  // (exact for any distribution of heights, not only a sinusoid's), tabulated at the bin edges.
  std::array<std::array<float, kBins + 1>, kBands> rise{};
  std::array<float, kBands> rise_origin{}, rise_per_mm{};
  {
    std::array<std::array<double, kBins>, kBands> counts{};
    std::array<double, kBands> bin_width{};
    for (int k = 0; k < kBands; ++k) {
      bin_width[k] = std::max(sums[k].max - sums[k].min, 1e-12) / kBins;
    }
    for (int r = 0; r < box.height; ++r) {
      const float* hr = h.ptr<float>(r);
      for (int c = 0; c < box.width; ++c) {
        if (contact_pixels > 0 && !(hr[c] > 0.0f)) continue;
        for (int k = 0; k < kBands; ++k) {
          const int bin = static_cast<int>((band(k, r, c) - sums[k].min) / bin_width[k]);
          counts[k][std::min(std::max(bin, 0), kBins - 1)] += 1.0;
        }
      }
    }
    for (int k = 0; k < kBands; ++k) {
      double below = 0.0, below_sum = 0.0;  // count and sum of the bin centres below edge j
      for (int j = 0; j <= kBins; ++j) {
        const double level = sums[k].min + j * bin_width[k];
        rise[k][j] = static_cast<float>((level * below - below_sum) / region_pixels);
        if (j < kBins) {
          below += counts[k][j];
          below_sum += counts[k][j] * (level + 0.5 * bin_width[k]);
        }
      }
      rise_origin[k] = static_cast<float>(sums[k].min);
      rise_per_mm[k] = static_cast<float>(1.0 / bin_width[k]);
    }
  }
  const auto riseAt = [&](int k, float level) {
    const float x = std::min(std::max((level - rise_origin[k]) * rise_per_mm[k], 0.0f),
                             static_cast<float>(kBins));
    const int j = std::min(static_cast<int>(x), kBins - 1);
    return rise[k][j] + (x - j) * (rise[k][j + 1] - rise[k][j]);
  };

  // The followed relief: every band clipped at its edge level, its mean rise taken off, summed.
  for (int r = 0; r < box.height; ++r) {
    const float* hr = h.ptr<float>(r);
    const float* s0 = smoothed_[0].ptr<float>(r);
    const float* s1 = smoothed_[1].ptr<float>(r);
    const float* s2 = smoothed_[2].ptr<float>(r);
    const float* s3 = smoothed_[3].ptr<float>(r);
    float* out = followed_mm.ptr<float>(box.y + r) + box.x;
    for (int c = 0; c < box.width; ++c) {
      const float indentation = std::max(hr[c], 0.0f);
      const float values[kBands] = {s0[c] - s1[c], s1[c] - s2[c], s2[c] - s3[c], s3[c]};
      float total = 0.0f;
      for (int k = 0; k < kBands; ++k) {
        if (!(crest[k] > -std::numeric_limits<float>::infinity())) {
          total += values[k];  // a flat band
          continue;
        }
        const float level = crest[k] - std::min(full_sink[k], sink_per_mm[k] * indentation);
        total += std::max(values[k], level) - riseAt(k, level);
      }
      out[c] = total;
    }
  }
  return stats;
}

}  // namespace norm2tex
