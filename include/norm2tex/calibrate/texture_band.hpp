#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace norm2tex {

/// Scales of the texture band and of the contact, in pixels at QVGA (240 pixels on the short
/// side); scaled with the frame's (qvgaScale).
struct TextureBandOptions {
  /// The band: difference of Gaussians between these sigmas (px). The finest relief a DIGIT
  /// resolves is a few pixels; the press's own shading (indentation, slopes of the pressed face,
  /// vignetting, lighting drift) varies over millimetres, i.e. tens of pixels.
  double fine_sigma_px = 0.5;
  double coarse_sigma_px = 4.0;
  /// Blur of |B| + |G| + |R| before thresholding: the contact, not each groove of the texture.
  double detection_sigma_px = 2.0;
  /// Contact: blurred magnitude above the quiet tiles' level + this many of their deviations
  /// (and at least kMinContactStep grey levels).
  double threshold_sigmas = 6.0;
  /// The band is measured this far inside the contact's rim (where the rim's own shading and the
  /// gel's skirt dominate) and the image border (px).
  double rim_erosion_px = 8.0;
  double border_px = 4.0;
  /// The noise floor is measured this far outside the contact (past the rim shadow), px.
  double noise_clearance_px = 24.0;
  int spectrum_bins = 12;  ///< radial frequency bins over 0-0.5 cycles per pixel
};

/// The sensor's frames without contact, as measureTextureBand compares a frame with them.
struct NoContactLevel {
  double band_rms = 0.0;  ///< the band's RMS (the noise floor)
  double magnitude = 0.0; ///< mean of the blurred |B| + |G| + |R| (0: unknown)
  double spread = 0.0;    ///< its standard deviation
};

/// Measures a no-contact difference image (its border excepted).
NoContactLevel measureNoContactLevel(const cv::Mat3f& diff, const TextureBandOptions& options = {});

/// The texture in one press frame, seen through its difference to the no-contact frame.
struct TextureBand {
  cv::Mat1b contact;       ///< 255 on the detected contact (largest region, holes filled)
  cv::Mat1b measured;      ///< 255 where the band is measured: the contact, eroded
  int contact_pixels = 0;
  int measured_pixels = 0;
  double contact_fraction = 0.0;  ///< contact pixels / image pixels
  cv::Point2d contact_centre;     ///< centroid of `measured` (px)
  double raw_rms = 0.0;    ///< band RMS over `measured`, grey levels (B, G, R together)
  double noise_rms = 0.0;  ///< the band's RMS where there is no contact (the noise floor)
  bool noise_from_frame = false;  ///< false: the frame had too little free area; fallback used
  /// The texture's share: sqrt(max(0, raw^2 - noise^2)), grey levels.
  double rms = 0.0;
  /// Radially averaged power of the band over `measured` per bin of spectrum_bins (grey
  /// levels^2 per pixel, noise included); bin k covers [k, k + 1) * 0.5 / bins cycles/px.
  std::vector<double> spectrum;
};

/// The band-pass of a difference image (per channel, difference of Gaussians; options' sigmas
/// scaled to the image width).
cv::Mat3f textureBandPass(const cv::Mat3f& diff, const TextureBandOptions& options = {});

/// Measures one press: finds the contact in `diff` (frame - background, grey levels), the band's
/// RMS inside it, its noise floor and its spectrum.
///
/// The contact: m = |B| + |G| + |R| blurred; the frame is cut into 16 px tiles and the quietest
/// 4 % of them (by mean m, at least 4) are taken as free of contact: their mean and deviation of m set
/// the threshold (a level relative to the frame's own noise, whatever the sensor or drift). The
/// largest region above it, holes filled, is the contact. When even those tiles stand clearly
/// above `no_contact` (by threshold_sigmas of its spread, at least kMinContactStep, and twice
/// its level) the contact covers the whole image. The noise floor is the band's RMS farther than
/// noise_clearance_px from the contact, or no_contact.band_rms when fewer than 1500 px (QVGA)
/// are that far.
///
/// Throws Error naming `frame_name` when no contact stands out of the noise, or when the contact
/// is too small to leave 300 px (QVGA) inside its rim.
TextureBand measureTextureBand(const cv::Mat3f& diff, const NoContactLevel& no_contact,
                               const std::string& frame_name,
                               const TextureBandOptions& options = {});

/// Lower edge of each spectrum bin, cycles per pixel.
std::vector<double> spectrumBinFrequencies(const TextureBandOptions& options = {});

}  // namespace norm2tex
