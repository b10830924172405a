#pragma once

#include <array>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace norm2tex {

/// One of the sensor's three LEDs (the analytic_leds shading).
struct LedModel {
  std::string name;        ///< "red", "green", "blue"
  cv::Vec3d position_mm;   ///< in the gel frame (see SensorModel)
  cv::Vec3d color_bgr;     ///< colour, each channel in [0, 1], OpenCV order
  double intensity = 1.0;  ///< relative, >= 0
};

/// Which shading model DigitShader uses.
enum class ShadingKind {
  kCalibrated,   ///< signed response to the gel's slopes, depth and rim (DigitShaderResponse)
  kAnalyticLeds  ///< the earlier analytic model: clamped Lambertian terms of three LEDs
};

/// Number of per-pixel features of the calibrated response (see digit_shader_response.hpp).
constexpr int kShadingFeatureCount = 24;

/// The shading stage's options (DigitShader).
struct ShadingOptions {
  ShadingKind kind = ShadingKind::kCalibrated;
  double gain = 1.0;  ///< multiplies the shading difference before the background is added
  /// Calibrated response: grey levels per unit of each feature, one row per channel (B, G, R),
  /// features in the order of digit_shader_response.hpp. Defaults: fitted by
  /// norm2tex_calibrate on the MIT calibration set of one real DIGIT (see config/digit.yaml).
  std::array<std::array<double, kShadingFeatureCount>, 3> response_bgr{};
  /// Width (mm) of the blur whose spill past the contact rim carries the rim-shadow features.
  double shadow_sigma_mm = 0.6;
  /// The slope s at which the slope features saturate: each takes g / sqrt(1 + |g|^2 / s^2)
  /// for the gel's slope g (mm/mm), so steep flanks of a deep press answer less than linearly;
  /// s = 1 makes them the gel normal's tangential components (a Lambertian surface's light is
  /// linear in the normal, not in the slope). 0: the slopes themselves (no saturation). The
  /// built-in DIGIT's is 0.3 (kDefaultSlopeSaturation, with its response); a yaml that gives a
  /// response without it means 0.
  double slope_saturation = 0.0;
};

/// Pixel noise added to a frame. A captured background already carries the sensor's noise, so
/// by default nothing is added on top of one; a synthetic (noise-free) background gets noise
/// with the per-channel sigma and the spatial and cross-channel correlations measured on real
/// DIGIT frames.
struct NoiseOptions {
  cv::Vec3d sigma_bgr{2.8, 1.5, 2.5};  ///< grey levels (of 255), per channel, OpenCV order
  double neighbour_correlation = 0.6;  ///< between horizontally / vertically adjacent pixels
  double correlation_bg = -0.33;       ///< between the blue and green noise of one pixel
  double correlation_gr = -0.42;       ///< green and red
  double correlation_br = 0.0;         ///< blue and red
  bool on_real_background = false;     ///< add noise on top of a captured background too
};

/// Elastomer smoothing (see GelModel): Taxim-style pyramid of Gaussian blurs that restores the
/// contact core after each level, then one small blur.
struct GelOptions {
  /// Coarse to fine. Real DIGIT presses fall from 80 % to 20 % of their shading over 0.29-0.36
  /// contact radii at the rim; Taxim's 1.0 mm level gives 0.42-0.45 at the measured scale.
  std::vector<double> pyramid_sigmas_mm = {0.5, 0.25, 0.1};
  double core_fraction = 0.4;   ///< pixels indented more than this x max indentation: the core
  /// Last blur over everything: the reflective coating's and the camera's smoothing (about one
  /// QVGA pixel), not the gel's conformity to texture, which GelConformity models.
  double final_sigma_mm = 0.05;
};

/// Pressure-dependent conformity of the gel to the texture (GelConformity, docs/sensor.md).
/// Off: the paper's fixed-depth overlay, H_final = H_sensor + beta H_local wherever the object
/// touches, whatever the force.
struct ConformityOptions {
  /// On: the texture's depth follows the contact pressure (GelConformity); off: the paper's
  /// fixed-depth overlay H_sensor + beta H_local.
  bool enabled = true;
  /// The gel's contact modulus E* = E / (1 - nu^2), MPa: the default gel law (Taxim-robot's
  /// GelSight table) read as a flat face pressing the gel pad, E = F h / (A d), gives
  /// 0.05-0.16 MPa over 0.1-2 mm of indentation (0.08-0.10 over the measured 0.4-0.58 mm).
  double contact_modulus_mpa = 0.1;
  /// The gel's coating as a thin plate on it, by its bending length l = (2 D / E*)^(1/3), mm
  /// (D the coating's bending stiffness): a plate on an elastic half-space needs
  /// (E* k / 2 + D k^4) w of pressure to bend into relief of wavenumber k and amplitude w, so it
  /// follows relief of wavelength lambda only at (1 + (2 pi l / lambda)^3) times Johnson's p*:
  /// short wavelengths are filtered, coarse relief is not. 0: no coating (Johnson's half-space).
  /// 0.23 mm: fitted to a real DIGIT pressing 0.6 mm ridges at 5-12 N (docs/sensor.md).
  double coating_length_mm = 0.23;
};

/// A printed dot grid on the gel's surface (GelSight Mini's gels carry one; DIGIT's do not).
/// The dots ride on the gel's lateral displacement (ShearField) and are drawn into the image
/// before the shading's difference is added, so they darken and move as real ones do.
struct MarkerOptions {
  bool enabled = false;          ///< off: frames exactly as without markers
  int rows = 9;                  ///< dots down the image (along +y); 9 x 7 fits a DIGIT's portrait
  int cols = 7;                  ///< dots across it (along +x)
  double pitch_mm = 1.8;         ///< centre-to-centre spacing, both directions
  double dot_diameter_mm = 0.5;  ///< printed dot diameter
  /// Fraction of the light a dot takes at its centre, 0..1 (0.7: a dot shows 30 % of the
  /// background's brightness there).
  double darkness = 0.7;
  double blur_mm = 0.04;         ///< Gaussian sigma of the dots' edge (print, coating, optics)
  double jitter_mm = 0.0;        ///< random offset of each dot (uniform, +-), seeded
  int seed = 0;                  ///< the jitter's seed
  /// The grid's centre from the image centre (gel frame x, y), mm.
  std::array<double, 2> offset_mm{0.0, 0.0};
};

/// The gel's lateral mechanics (ShearField): the surface's displacement under the contact's
/// tangential traction, an incompressible elastic layer of gel.thickness_mm bonded to the
/// rigid window behind it.
struct ShearOptions {
  /// Shear modulus G of the gel, MPa (E = 3 G for an incompressible gel).
  double shear_modulus_mpa = 0.1;
  /// Coulomb friction coefficient between gel and object when the caller gives none.
  double friction = 1.0;
};

/// One smooth glow of the synthetic no-contact frame: an anisotropic Gaussian in normalised image
/// coordinates (u = column / width, v = row / height, both 0..1 over the image), rotated.
struct BackgroundGlow {
  std::array<double, 2> centre_uv{0.5, 0.5};  ///< may lie outside 0..1 (a glow from past an edge)
  std::array<double, 2> sigma_uv{0.25, 0.25};  ///< along the glow's own axes a and b, > 0
  double angle_rad = 0.0;                      ///< axis a from +u towards +v
  cv::Vec3d color_bgr{0.0, 0.0, 0.0};          ///< grey levels at its peak, before vignetting
};

/// The DIGIT's four glows (fitted to a real DIGIT's no-contact frame; synthetic_background.cpp).
std::vector<BackgroundGlow> digitBackgroundGlows();

/// How the synthetic no-contact frame looks, used when background_image is empty:
///   I_bgr(u, v) = vignette(u, v) * (base_bgr + sum_j color_j * glow_j(u, v)),
///   vignette = 1 - vignette_strength * (r / r_corner)^vignette_power
/// in normalised coordinates, so it looks the same at any size of the same aspect. The defaults
/// are the DIGIT's (makeSyntheticBackground says what they reach); another sensor's yaml gives
/// its own (config/gelsight_mini.yaml).
struct SyntheticBackgroundOptions {
  cv::Vec3d base_bgr{59.0, 83.9, 47.8};  ///< grey levels everywhere, before vignetting
  double vignette_strength = 0.30;       ///< brightness lost in the corners, [0, 1)
  double vignette_power = 2.2;           ///< how fast it falls towards them, > 0
  std::vector<BackgroundGlow> glows = digitBackgroundGlows();
};

/// Everything about one sensor that the renderer needs, loaded from its yaml (config/digit.yaml,
/// config/gelsight_mini.yaml). The defaults are a DIGIT's.
///
/// Gel frame (shared by the CLI, the tests and the ROS nodes): origin at the centre of the
/// undeformed gel surface; +x towards increasing image columns (right); +y towards increasing
/// image rows (down); +z out of the gel towards the object. The camera sits behind the gel and
/// looks along +z. Pixel (row r, column c) sees the gel point
/// x = (c + 0.5 - cols / 2) * mm_per_pixel, y = (r + 0.5 - rows / 2) * mm_per_pixel.
struct SensorModel {
  int rows = 320;                 ///< image height, pixels (portrait QVGA as drivers publish)
  int cols = 240;                 ///< image width, pixels
  /// Gel millimetres per pixel at the gel surface. Four calibrations of real units measure
  /// 17-19.6 px/mm at QVGA; the default, 0.054, is the calibration set's unit (18.5 px/mm).
  double mm_per_pixel = 0.054;
  double gel_thickness_mm = 4.6;  ///< indentation is clamped to this
  /// The physical gel pad, which the gripper physics presses against (setGelFromSensor). The
  /// camera sees only its middle (gelWidthMm() x gelHeightMm(), about 13 x 17 mm at the
  /// measured scale); quoted DIGIT gels are 18.35 x 24.6 to 20 x 30 mm.
  double gel_pad_width_mm = 19.2;
  double gel_pad_height_mm = 25.6;
  double gel_curvature_radius_mm = 0.0;  ///< 0 = flat gel; else a dome of this radius
  double fx = 277.1, fy = 277.1;         ///< camera_info intrinsics, pixels
  double cx = 119.5, cy = 159.5;         ///< principal point, pixels
  std::array<LedModel, 3> leds;          ///< red, green, blue (the analytic_leds shading)
  ShadingOptions shading;
  NoiseOptions noise;
  std::string background_image;  ///< user's no-contact frame (BGR); empty = synthetic
  SyntheticBackgroundOptions synthetic_background;  ///< the synthetic frame's look
  GelOptions gel;
  ConformityOptions conformity;
  MarkerOptions markers;
  ShearOptions shear;

  /// The imaged part of the gel (cols x mm_per_pixel by rows x mm_per_pixel).
  double gelWidthMm() const { return cols * mm_per_pixel; }
  double gelHeightMm() const { return rows * mm_per_pixel; }
  cv::Size imageSize() const { return {cols, rows}; }
  /// Gel-frame x, y (mm) of a pixel centre.
  cv::Point2d pixelToGelMm(double row, double col) const;
};

/// Defaults for a DIGIT at QVGA (320 x 240) or VGA (640 x 480): same gel, halved mm per pixel.
SensorModel makeDigitSensorModel(bool vga = false);

/// Loads a sensor yaml such as config/digit.yaml (every key optional, defaults above; `preset:
/// qvga|vga` first).
/// A relative background_image is resolved against the yaml's directory. Throws Error naming
/// the file and key for unreadable yaml, an unknown key (a typo would otherwise be ignored
/// silently) or a value out of range.
SensorModel loadSensorModel(const std::string& yaml_path);

/// Writes `model` as a sensor yaml that loadSensorModel reads back to the same model (every
/// key written). `background_image` is written as given (make it relative to the yaml's
/// directory to keep the pair movable). Throws Error naming the file if it cannot be written.
void saveSensorModel(const SensorModel& model, const std::string& yaml_path);

const char* shadingKindName(ShadingKind kind);

/// Throws Error naming the first field out of range and its valid range.
void validate(const SensorModel& model);

}  // namespace norm2tex
