#pragma once

#include <memory>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/shear/contact_traction.hpp"
#include "norm2tex/shear/marker_pattern.hpp"
#include "norm2tex/shear/shear_grid.hpp"
#include "norm2tex/shear/surface_displacement.hpp"

namespace norm2tex {

/// The gel's lateral motion at one frame: the contact's traction, the surface's displacement
/// and where the markers went. Fields are on a grid of square cells of cell_px pixels (the
/// displacement of a 1/r kernel is smooth at that scale; cell (i, j) covers the pixels from
/// (i cell_px, j cell_px), the last row and column of cells possibly only in part).
struct ShearFrame {
  int cell_px = 0;
  double cell_mm = 0.0;
  ContactTraction traction;
  cv::Mat1f ux_mm;              ///< lateral displacement of the gel's surface per cell, x
  cv::Mat1f uy_mm;              ///< and y (gel frame), mm
  std::vector<Marker> markers;  ///< empty when the sensor has no markers
  /// Fraction of the contact area that slips (ContactTraction::slip_fraction).
  double slipFraction() const { return traction.slip_fraction; }
  /// The displacement at every pixel of an image of `size`, metres (32FC2: x, y), bilinear
  /// between cell centres: what /<sensor>/shear publishes.
  cv::Mat2f displacementMetres(cv::Size size) const;
};

/// The shear stage: from H_sensor, the normal force and the tangential load to the traction
/// (solveContactTraction), the surface displacement (SurfaceDisplacement: an incompressible gel
/// of gel.thickness_mm bonded to its window) and the markers (MarkerPattern). Holds its buffers;
/// not thread-safe.
class ShearField {
 public:
  /// `cell_px` 0: cells of about kShearCellMm (8 px at a DIGIT's QVGA scale).
  explicit ShearField(const SensorModel& model, int cell_px = 0);

  /// Computes `out` for a press: h_sensor_mm per pixel (image size), its covered box (where it
  /// may be non-zero; empty = the whole image). Throws Error for a bad force or load.
  void compute(const cv::Mat1f& h_sensor_mm, const cv::Rect& covered_box, double normal_force_n,
               const ShearLoad& load, ShearFrame& out);

  /// `out` with no load: zero traction and displacement, the markers at rest.
  void rest(ShearFrame& out) const;

  /// The markers of `frame` drawn into `image`; nothing when the sensor has none.
  void drawMarkers(cv::Mat3b& image, const ShearFrame& frame) const;

  bool hasMarkers() const { return markers_ != nullptr; }
  int cellPx() const { return grid_.cell_px; }
  const ShearGrid& grid() const { return grid_; }

  /// The default cell's side, mm.
  static constexpr double kShearCellMm = ShearGrid::kDefaultCellMm;

 private:
  void placeMarkers(ShearFrame& out) const;

  SensorModel model_;
  ShearGrid grid_;
  std::unique_ptr<SurfaceDisplacement> displacement_;
  std::unique_ptr<MarkerPattern> markers_;
  cv::Mat1f penetration_;
};

}  // namespace norm2tex
