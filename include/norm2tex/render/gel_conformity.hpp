#pragma once

#include <array>

#include <opencv2/core.hpp>

#include "norm2tex/render/sensor_model.hpp"

namespace norm2tex {

/// One wavelength band of the texture in one contact, as GelConformity saw it.
struct ConformityBand {
  double wavelength_mm = 0.0;  ///< the band's dominant wavelength (from its RMS slope / RMS)
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
  std::array<ConformityBand, 4> bands{};  ///< fine to coarse (the last: everything coarser)
};

/// How much of the texture's relief the gel follows, from the contact pressure (Johnson,
/// Contact Mechanics 1985, section 13.2, the elastic half-space on a wavy surface).
///
/// An elastic body pressed with mean pressure p onto a sinusoid of amplitude Delta and
/// wavelength lambda touches it completely once p >= p* = pi E* Delta / lambda; below, only
/// the crests, over patches of width 2a with sin^2(pi a / lambda) = p / p*. The gel then
/// follows the relief from its crest down to the level of the patch edge,
/// Delta cos(2 pi a / lambda) = Delta (1 - 2 p / p*), and spans the valleys below that level
/// without touching them: the followed relief is max(relief, Delta (1 - 2 p / p*)), exact for
/// the sinusoid, and its peak-to-valley is min(1, p / p*) of the full one.
///
/// Per band: the relief (beta H_local, mm, positive into the gel) is split into four octave
/// bands by differences of Gaussians (sigma 0.05, 0.1, 0.2 mm: wavelengths below about 0.3 mm,
/// 0.3-0.6, 0.6-1.3 and above), each band is clipped at its own edge level with its own
/// p*_k = pi E* Delta / lambda_k, and the bands are summed again. lambda_k is the band's
/// dominant wavelength (2 pi RMS / RMS slope, exact for a sinusoid); Delta is the whole
/// relief's amplitude, because it is the whole relief the gel must reach down into at that
/// wavelength (a sinusoid spread over several overlapping bands is then clipped exactly as one).
///
/// The pressure: the force spread over the contact in proportion to the local indentation,
/// p(x) = F H_sensor(x) / integral(H_sensor dA): a thin gel on a rigid window is a Winkler
/// foundation, so a flat face presses uniformly and a ball hardest at its centre. Where the gel
/// does not touch the smooth surface (p = 0) only the crests of each band reach it.
///
/// Not thread-safe (holds its scratch); one per renderer.
class GelConformity {
 public:
  /// Throws Error for a contact modulus out of (0, 100] MPa or mm_per_pixel <= 0.
  GelConformity(const ConformityOptions& options, double mm_per_pixel);

  /// Writes, over `box`, the relief the gel follows into `followed_mm` (reallocated to the
  /// image size if its size differs; left untouched outside `box`). `h_sensor_mm`: indentation
  /// of the smooth surface (mm, > 0 in contact); `relief_mm`: beta H_local (mm) over the
  /// covered pixels, 0 elsewhere; `normal_force_n`: the contact's normal force (N). Throws
  /// Error for a negative or non-finite force, or fields of different sizes.
  ConformityStats apply(const cv::Mat1f& h_sensor_mm, const cv::Mat1f& relief_mm, cv::Rect box,
                        double normal_force_n, cv::Mat1f& followed_mm);

  const ConformityOptions& options() const { return options_; }
  /// The Gaussians' sigmas (mm) whose differences make the bands.
  static constexpr std::array<double, 3> kBandSigmasMm = {0.05, 0.1, 0.2};

 private:
  ConformityOptions options_;
  double mm_per_pixel_;
  std::array<cv::Mat1f, 4> smoothed_;  // relief, then blurred by each sigma (scratch)
};

}  // namespace norm2tex
