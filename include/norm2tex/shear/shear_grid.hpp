#pragma once

#include <opencv2/core.hpp>

#include "norm2tex/render/sensor_model.hpp"

namespace norm2tex {

/// The grid of square cells the shear stage works on over a sensor's image: cell (i, j) covers
/// the pixels from (i cell_px, j cell_px), the last row and column of cells possibly only in
/// part. The renderer's ShearField and the contact's slip (ContactPatchMeter) use the same one,
/// so they solve the same traction.
struct ShearGrid {
  int cell_px = 0;
  double cell_mm = 0.0;
  cv::Size size;   ///< cells across (width) and down (height)
  cv::Size image;  ///< the image it covers, pixels

  /// The cells' side when none is asked for, mm (8 px at a DIGIT's QVGA scale).
  static constexpr double kDefaultCellMm = 0.4;
  /// The grid over `model`'s image; `cell_px` 0: cells of about kDefaultCellMm. Throws Error for
  /// a negative cell_px.
  static ShearGrid of(const SensorModel& model, int cell_px = 0);
};

/// Each cell's mean penetration, mm, from H_sensor (mm per pixel, of the grid's image) and
/// the box it covers (where it may be non-zero; empty = the whole image), into `out` (the grid's
/// size; cells outside the box are 0). Throws Error for an H_sensor of another size.
void meanCellPenetration(const cv::Mat1f& h_sensor_mm, const cv::Rect& covered_box,
                         const ShearGrid& grid, cv::Mat1f& out);

}  // namespace norm2tex
