#pragma once

#include <array>
#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/render/sensor_model.hpp"

namespace norm2tex {

/// One wavelength band of the texture in one contact, as GelConformity saw it.
struct ConformityBand {
  double wavelength_mm = 0.0;  ///< the band's dominant wavelength (RMS step / RMS)
  double amplitude_mm = 0.0;   ///< half its peak-to-valley inside the contact
  double full_contact_pressure_mpa = 0.0;  ///< Johnson's p* = pi E* Delta / lambda
  double followed_fraction = 0.0;  ///< mean over the contact of min(1, p / p*): depth followed
};

/// What GelConformity computed for one frame.
struct ConformityStats {
  double normal_force_n = 0.0;
  double contact_area_mm2 = 0.0;    ///< pixels with H_sensor > 0
  double mean_pressure_mpa = 0.0;   ///< force / contact area (0 without contact)
  double relief_amplitude_mm = 0.0; ///< Delta: half the texture's peak-to-valley in the contact
  /// Fine to coarse (the last: everything coarser); a band folded into the next coarser one
  /// (under 5 % of the relief's RMS) has amplitude 0.
  std::array<ConformityBand, 3> bands{};
};

/// How much of the texture's relief the gel follows, from the contact pressure (Johnson,
/// Contact Mechanics 1985, section 13.2, an elastic half-space on a wavy surface).
///
/// An elastic body pressed with mean pressure p onto a sinusoid of amplitude Delta and
/// wavelength lambda touches it completely once p >= p* = pi E* Delta / lambda; below, only
/// the crests, over patches of width 2a with sin^2(pi a / lambda) = p / p*. The gel follows the
/// relief from each crest down to the level of the patch edge,
/// Delta cos(2 pi a / lambda) = Delta (1 - 2 p / p*), and spans the valleys below that level
/// without touching them: the followed relief is max(relief, Delta (1 - 2 p / p*)), exact for
/// the sinusoid; its peak-to-valley is min(1, p / p*) of the full one.
///
/// Per band: the relief (beta H_local, mm, positive into the gel) is split into three bands by
/// a Gaussian pyramid (levels of 2 and 4 pixels: at QVGA wavelengths below about 0.25 mm,
/// 0.25-0.5 mm and above), each band is clipped at its own patch-edge level with its own
/// p*_k = pi E* Delta / lambda_k, and the bands are summed again. lambda_k is the band's
/// dominant wavelength (from its RMS step between pixels, exact for a sinusoid); Delta is the
/// whole relief's amplitude, since it is the whole relief the gel must reach into at that
/// wavelength. A band with under 5 % of the relief's RMS is folded into the next coarser one.
/// Clipping raises a band's mean; that rise is taken off again (from the band's histogram), so
/// the gel's mean indentation stays the one the physics' force-indentation law gave.
///
/// The pressure: the force spread over the contact in proportion to the local indentation,
/// p(x) = F H_sensor(x) / integral(H_sensor dA): a thin gel on a rigid window is a Winkler
/// foundation, so a flat face presses uniformly and a ball hardest at its centre. Where the gel
/// does not touch the smooth surface (p = 0) each band sits at its mean: no texture.
///
/// Not thread-safe (holds its scratch); one per renderer.
class GelConformity {
 public:
  /// Throws Error for a contact modulus out of (0, 100] MPa or mm_per_pixel <= 0.
  GelConformity(const ConformityOptions& options, double mm_per_pixel);

  /// Writes, over `box`, the relief the gel follows (mm) into `followed_mm` (reallocated to
  /// the image size if its size differs; left untouched outside `box`). `h_sensor_mm`:
  /// indentation of the smooth surface (mm, > 0 in contact, never negative); the relief is
  /// `beta_mm` H_local over the covered pixels (0 elsewhere); `normal_force_n`: the contact's
  /// normal force (N). Throws Error for a negative or non-finite force or beta, or fields of
  /// different sizes.
  ConformityStats apply(const cv::Mat1f& h_sensor_mm, const cv::Mat1f& h_local, double beta_mm,
                        cv::Rect box, double normal_force_n, cv::Mat1f& followed_mm);

  /// As apply(), but writes H_final = clamp(followed - gap_mm, 0, thickness_mm) over `box`
  /// straight into `h_final_mm` (which must be of the image size), in the same pass: the
  /// renderer's path. `gap_mm`: the smooth surface's height above the gel (the rasterizer's,
  /// negative where it presses in), so followed - gap is the texture overlay's H_final with the
  /// followed relief in place of beta H_local.
  ConformityStats applyToFinal(const cv::Mat1f& h_sensor_mm, const cv::Mat1f& h_local,
                               double beta_mm, cv::Rect box, double normal_force_n,
                               const cv::Mat1f& gap_mm, double thickness_mm,
                               cv::Mat1f& h_final_mm);

  const ConformityOptions& options() const { return options_; }
  /// Bands: a Gaussian pyramid's levels (2 and 4 pixels) split the relief into three.
  static constexpr int kBandCount = 3;

 private:
  ConformityOptions options_;
  double mm_per_pixel_;
  std::array<cv::Mat1f, kBandCount> smoothed_;  // relief, then each pyramid level at full size
  std::array<cv::Mat1f, 2> half_;               // the pyramid: 1/2, 1/4 resolution (scratch)
  cv::Mat1f up_;                                // the 1/4 level on its way back up (scratch)
  std::vector<int> sample_offsets_;     // where the statistics are sampled (scratch)
  std::vector<float> sample_depths_;    // H_sensor there
  cv::Mat1f rise_table_;               // the clipping's mean rise by quantised indentation
  std::vector<float> zeros_;           // a row of zeros: a folded band's, the residual's lower

  // apply() and applyToFinal(): with `gap_mm`, H_final goes to `out`, else the followed relief.
  ConformityStats run(const cv::Mat1f& h_sensor_mm, const cv::Mat1f& h_local, double beta_mm,
                      cv::Rect box, double normal_force_n, const cv::Mat1f* gap_mm,
                      float thickness_mm, cv::Mat1f& out);
};

}  // namespace norm2tex
