#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/calibrate/press_detection.hpp"
#include "norm2tex/render/sensor_model.hpp"

namespace norm2tex {

/// One ball press of a calibration set.
struct PressObservation {
  std::string name;    ///< for messages and the report (usually the file name)
  cv::Mat3f diff;      ///< frame - background, grey levels (drift-corrected, see calibration)
  PressCircle circle;  ///< detected or labelled contact circle
};

/// What the presses share: the scale, and one factor on every detected contact radius (the
/// detector's threshold contour lies near, not on, the true rim).
struct PressGeometry {
  double mm_per_pixel = 0.054;
  double radius_factor = 1.0;
};

/// The gel's deformation (mm) that `base` (its GelModel options) produces for `press` under
/// `geometry`: a ball of `ball_radius_mm` whose contact circle is the press's circle with the
/// radius scaled by radius_factor. Throws Error if the contact is wider than the ball.
cv::Mat1f simulatedPressGel(const SensorModel& base, const PressCircle& circle,
                            const PressGeometry& geometry, double ball_radius_mm);

/// Pixels that a press is fitted and judged on: within this many (detected) contact radii of
/// its centre; far enough out to hold the rim shadow.
constexpr double kFitRegionRadii = 2.0;

/// The scales searched at QVGA (mm per pixel): a generous band around the 0.051-0.059 that
/// four calibrations of real DIGITs measured.
constexpr double kMinSearchedScale = 0.03;
constexpr double kMaxSearchedScale = 0.1;

/// The fit at one scale of the coarse search grid: the best radius factor there, at the default
/// rim-shadow width, on the presses as given to the search (detected circles).
struct ScaleProfilePoint {
  double mm_per_pixel = 0.0;
  double radius_factor = 1.0;
  double variance_explained = 0.0;
};

/// Scales whose fit explains within this share of the pixel variance of the best one are not
/// told apart by the presses: the margin by which a wider rim shadow is judged "barely better".
constexpr double kScaleIndifference = 0.01;

/// How sharply the presses pick the scale, when it was searched. Ball presses pin it only weakly:
/// in pixels a ball's slopes depend on the scale through the ball radius in pixels alone, to
/// first order as one factor that the fitted response absorbs; what is left (the sphere's
/// departure from a paraboloid, the gel blurs' widths in mm) is of the size of the response
/// model's own error. Presses with a response unlike the fitted one (the analytic LEDs, rendered
/// at 0.054) and the real s09 presses (0.0532) both fit best at the smallest scale searched.
struct ScaleSearch {
  std::vector<ScaleProfilePoint> profile;   ///< the coarse grid, by increasing scale
  double range_min = 0.0, range_max = 0.0;  ///< scales of the profile within kScaleIndifference
};

/// A least-squares fit of the calibrated response to presses.
struct ShadingFit {
  ShadingOptions shading;              ///< response fitted; gain 1; shadow_sigma_mm as used
  PressGeometry geometry;              ///< as used
  GelOptions gel;                      ///< the gel smoothing used (base's; not fitted)
  bool scale_at_search_bound = false;  ///< the fitted scale is an end of the searched range
  ScaleSearch scale_search;            ///< empty unless the scale was searched on a coarse grid
  double variance_explained = 0.0;     ///< on the fitted presses, pixels of kFitRegionRadii
};

/// Fits the response (per channel, all features of digit_shader_response.hpp) to `presses` at
/// one geometry. Throws Error if a press does not fit the ball (see simulatedPressGel).
ShadingFit fitShadingResponse(const SensorModel& base, const std::vector<PressObservation>& presses,
                              const PressGeometry& geometry, double ball_radius_mm,
                              double shadow_sigma_mm);

/// Fits the response and the geometry: the radius factor always, the scale when
/// `mm_per_pixel` is not given, and the rim-shadow width; each chosen as the one whose fit explains
/// the most variance (a coarse grid, then a local pattern search). Throws Error when no scale in
/// the searched range (kMinSearchedScale-kMaxSearchedScale mm/px at QVGA, halved at VGA) fits the
/// ball. A given `mm_per_pixel` is the geometry's scale, exactly: the radius factor is limited to
/// what the ball can make at it, and when even the smallest factor (0.6) makes a press wider than
/// the ball, it throws Error naming that press, its radius in pixels and the ball's radius.
/// When the scale is searched and there are more than 16 presses, the search runs on 16 of
/// them spread evenly over the set, and the response is then fitted on all.
/// With `start`, the coarse grid is skipped and the local search starts there (a refit);
/// otherwise, when the scale is searched, `scale_search` holds the grid's profile.
ShadingFit fitShadingAndGeometry(const SensorModel& base,
                                 const std::vector<PressObservation>& presses,
                                 double ball_radius_mm, std::optional<double> mm_per_pixel,
                                 std::optional<PressGeometry> start = std::nullopt);

}  // namespace norm2tex
