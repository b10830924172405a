#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/calibrate/fit_quality.hpp"
#include "norm2tex/calibrate/marker_detection.hpp"
#include "norm2tex/calibrate/press_detection.hpp"
#include "norm2tex/calibrate/press_frame_comparison.hpp"
#include "norm2tex/calibrate/shading_fit.hpp"
#include "norm2tex/render/sensor_model.hpp"

namespace norm2tex {

/// A frame and the name it is reported under (usually its file).
struct NamedFrame {
  std::string name;
  cv::Mat3b image;  ///< BGR, portrait as the driver publishes it
};

/// What a user has of their DIGIT: no-contact frames and ball presses.
struct CalibrationInput {
  std::vector<NamedFrame> backgrounds;  ///< one or more no-contact frames (averaged)
  std::vector<NamedFrame> presses;      ///< one ball press each, anywhere on the gel
  /// Optional contact circles, one per press (nullopt: detect it); empty = detect all.
  std::vector<std::optional<PressCircle>> labels;
  double ball_diameter_mm = 0.0;
  /// Fitted when not given; a given one is the calibrated scale exactly, or refused (Error naming
  /// the press the ball cannot make at it), never changed.
  std::optional<double> mm_per_pixel;
};

struct CalibrationOptions {
  /// Share of the presses held out of the fit and used to judge it (every n-th press).
  double holdout_fraction = 0.3;
};

/// The fitted sensor and how well it reproduces presses it was not fitted on.
struct CalibrationResult {
  SensorModel model;     ///< base + fitted scale, shading and noise; background_image unset
  cv::Mat3b background;  ///< mean of the no-contact frames
  ShadingFit fit;        ///< on the training presses (scale_search: the first fit's)
  FitQuality held_out;   ///< simulated vs real on the held-out presses
  std::vector<PressObservation> held_out_presses;
  std::vector<cv::Mat3f> held_out_simulated;  ///< the model's shading difference per press
  std::vector<double> held_out_radii_px;      ///< fitted contact radii
  int training_presses = 0;
  /// Each press's render (background + simulated difference) against its frame as captured, in
  /// the order of the input: SSIM, SSIM inside the contact, PSNR, mean |diff|.
  std::vector<PressFrameComparison> held_out_frames, training_frames;
  /// A marker gel's dots found on the backgrounds (none on a DIGIT): they are filled in from
  /// their surroundings in every frame before the fit (so the fit, the comparisons and
  /// `background` are of the gel without them), and their layout is model.markers.
  DetectedMarkers markers;
};

/// Minimum number of presses: 3 to fit, 1 to hold out.
constexpr int kMinCalibrationPresses = 4;

/// Calibrates a DIGIT: averages the backgrounds, finds each press's contact circle
/// (detectPress, unless labelled), removes the frame's lighting drift (per channel, the median
/// difference farther than 2.2 contact radii from the press), holds out every n-th press, fits
/// geometry and shading on the rest (fitShadingAndGeometry), refines every unlabelled press's
/// circle against that model (refinePressCircle: geometry only, so held-out presses stay
/// unseen by the shading fit), refits, renders the held-out presses with DigitShader at the
/// fitted geometry and compares (compareWithReal), compares every press's rendered frame with
/// its real one (held_out_frames, training_frames), and measures the background noise
/// (measureBackgroundNoise). A marker gel's dots (detectMarkers on the mean background) are
/// filled in first in every frame and their layout measured (result.markers, model.markers).
/// `base` gives the image size and the parts not
/// fitted (gel smoothing, camera, LEDs). Throws Error naming the frame for frames of another
/// size or orientation than `base`, presses it cannot find, a ball that cannot make the
/// contacts, or fewer than kMinCalibrationPresses presses.
CalibrationResult calibrateSensor(const SensorModel& base, const CalibrationInput& input,
                                  const CalibrationOptions& options = {});

/// Judges a calibrated sensor on presses it was not fitted on (another recording of the same
/// unit, or another unit): every press is held out. The circles are found as the calibration
/// finds its held-out presses' (detected or labelled, drift removed, refined against `fitted`,
/// geometry only); each is rendered by `fitted` on the mean of these backgrounds and compared
/// (held_out, held_out_frames). Nothing is fitted: result.model is `fitted`, training_presses 0,
/// fit.geometry its scale with radius factor 1. Throws Error as calibrateSensor does (one press
/// is enough), and for an input.mm_per_pixel other than the sensor's.
CalibrationResult judgeSensor(const SensorModel& fitted, const CalibrationInput& input);

}  // namespace norm2tex
