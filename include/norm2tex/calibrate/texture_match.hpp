#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "norm2tex/calibrate/texture_band.hpp"
#include "norm2tex/mesh/textured_mesh.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/texture/height_atlas.hpp"

namespace norm2tex {

/// One real frame of the user's DIGIT pressing a flat sample of the material.
struct TextureFrame {
  std::string name;  ///< reported in errors (usually its file)
  cv::Mat3b image;   ///< BGR, the background's size
  std::optional<double> normal_force_n;  ///< the press's normal force (N), when measured
};

/// The sample's texture as the renderer sees it: H_global tiled over a flat face.
struct TextureSample {
  std::shared_ptr<const HeightAtlas> atlas;
  double period_mm = 0.0;  ///< the atlas's side on the face, mm (its size x mm per texel)
  double beta_mm = 0.0;    ///< the texture depth to start from (the material's current one)
};

struct TextureMatchOptions {
  /// The simulated sample: a flat face tilted by this angle about the image's x axis, deepest at
  /// the image's bottom edge, so that its contact grows with the press (a face pressed exactly
  /// parallel to a flat gel covers the whole image at any depth, and its area tells nothing).
  double tilt_deg = 4.0;
  /// The search range of beta: the starting beta times [1 / factor, factor], within (0, 2] mm.
  double beta_range_factor = 20.0;
  /// Fit the contact modulus E* too when identifiable (conformity on, every force given, at
  /// least 3 frames, their mean pressures spanning min_pressure_ratio).
  bool fit_contact_modulus = true;
  double min_pressure_ratio = 2.5;
  std::int64_t noise_seed = 1000;  ///< simulated frame i gets noise seed noise_seed + i
  TextureBandOptions band;
};

/// One real frame and the simulated press matched to it.
struct FrameMatch {
  std::string name;
  double force_n = 0.0;        ///< given, or the gel law's at the matched press
  bool force_given = false;
  double press_mm = 0.0;       ///< deepest indentation of the simulated face
  double tilt_deg = 0.0;       ///< of the simulated face (0: the contact covered the image)
  double mean_pressure_mpa = 0.0;  ///< force / simulated contact area
  TextureBand real, sim;
  cv::Mat3b real_image, sim_image;
};

/// The fit and everything the report shows.
struct TextureMatchResult {
  double start_beta_mm = 0.0;
  double beta_mm = 0.0;
  bool beta_at_bound = false;  ///< the searched range's end: the frames want beta outside it
  /// No depth in the searched range matched the frames better than the material's own: beta is
  /// start_beta_mm (the frames' texture too faint to pin it; a warning says so).
  bool beta_kept = false;
  /// RMS over the frames of ln(sim RMS / real RMS): 0.05 is a 5 % misfit.
  double misfit = 0.0;
  double start_misfit = 0.0;   ///< the same at start_beta_mm
  double contact_modulus_mpa = 0.0;  ///< the one used (fitted or the sensor's)
  bool contact_modulus_fitted = false;
  std::string contact_modulus_note;  ///< why it was or was not fitted
  bool conformity = false;
  std::vector<FrameMatch> frames;
  std::vector<std::string> warnings;
};

/// Fewest frames a fit takes: one beta from one frame has no check on itself; 3 or more at
/// different forces (light, medium, firm) are recommended.
constexpr int kMinTextureMatchFrames = 2;

/// Fits a material's texture depth beta (and, when the frames allow, the gel's contact modulus
/// E*) to real frames of a DIGIT pressing a flat sample of it.
///
/// Per real frame the texture band (measureTextureBand: a difference of Gaussians of frame -
/// background inside the eroded contact, noise floor removed) gives a band RMS. The same sensor
/// (`model`, with `background` as its no-contact frame and its own noise, fixed seeds) renders
/// the sample as a tilted flat face, pressed so deep that its detected contact area equals the
/// real frame's (bisection on the depth; a contact that covers the image instead takes a
/// parallel face at the gel law's depth for the given force), with the given force, else the gel
/// law's for that depth. The simulated band RMS grows monotonically with beta, so beta is the
/// root of the mean over frames of ln(sim / real), found by bisection on ln beta: the least-
/// squares fit of the log ratios when RMS ~ beta^k for all frames alike; the press depths are
/// matched again at the fitted beta and beta refitted (the texture shifts the detected area a
/// little). With conformity on and every force given, E* (which sets Johnson's p* = pi E*
/// Delta / lambda) is fitted on a log grid (0.02-1 MPa, beta refitted at each) and refined, and
/// kept only when the misfit rises clearly on both sides of it: the band RMS must bend with the
/// pressure for p* to be seen.
///
/// Deterministic. Throws Error naming the frame for frames of another size than the background,
/// no detectable contact, a force that is not finite and > 0, a contact covering the image
/// without a force; and for fewer than kMinTextureMatchFrames frames, forces given for some
/// frames only, or a sample without texture.
class TextureMatcher {
 public:
  /// `model`: the user's sensor; its image size must equal `background`'s.
  TextureMatcher(SensorModel model, cv::Mat3b background, TextureSample sample,
                 TextureMatchOptions options = {});

  TextureMatchResult fit(const std::vector<TextureFrame>& frames) const;

  /// The flat face the sample is rendered as: a box 30 x 30 x 10 mm whose UVs repeat every
  /// `period_mm`, so the texture keeps its millimetre scale.
  static std::shared_ptr<const TexturedMesh> sampleFace(double period_mm);
  /// Its pose for a press `press_mm` deep at its deepest (the image's bottom edge when tilted)
  /// on a sensor of `model`'s image.
  static Eigen::Isometry3d samplePose(const SensorModel& model, double tilt_deg,
                                      double press_mm);

 private:
  class Session;
  SensorModel model_;
  cv::Mat3b background_;
  TextureSample sample_;
  TextureMatchOptions options_;
};

}  // namespace norm2tex
