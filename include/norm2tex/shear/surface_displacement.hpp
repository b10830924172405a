#pragma once

#include <opencv2/core.hpp>

namespace norm2tex {

/// The gel surface's lateral displacement under a tangential traction given per cell of a grid:
/// the kernel integrated over each cell, convolved with the traction by FFT on a zero-padded
/// grid, so the result is the exact linear convolution (no wrap-around). The kernel's spectra are
/// computed once; a frame costs two forward and two inverse real DFTs of the padded grid.
///
/// The kernel: Cerruti's half-space (cerrutiCellInfluence, exact per cell), and for a layer of
/// finite thickness bonded to a rigid base what the layer changes of it (layerCorrection: smooth
/// on the scale of the thickness, so taken at the cell's centre). A gel as thick as a contact is
/// wide moves less than a half-space under it, and far less away from it: a half-space's
/// displacement decays as 1/r, a bonded layer's within a few thicknesses.
class SurfaceDisplacement {
 public:
  /// A grid of rows x cols square cells of side cell_mm; G in MPa; the layer's thickness in mm,
  /// 0 for a half-space. Throws Error for an empty grid, a non-positive cell or modulus, or a
  /// negative thickness.
  SurfaceDisplacement(int rows, int cols, double cell_mm, double shear_modulus_mpa,
                      double thickness_mm = 0.0);

  /// qx, qy: the traction on the gel (MPa, gel frame x and y), rows x cols. Writes the surface
  /// displacement at every cell centre (mm) to ux, uy. Throws Error for another size.
  void solve(const cv::Mat1f& qx, const cv::Mat1f& qy, cv::Mat1f& ux, cv::Mat1f& uy);

  int rows() const { return rows_; }
  int cols() const { return cols_; }
  double cellMm() const { return cell_mm_; }

 private:
  int rows_ = 0, cols_ = 0;
  double cell_mm_ = 0.0;
  cv::Size padded_;
  cv::Mat1f kxx_, kxy_, kyy_;            // the kernel's spectra (CCS packed)
  cv::Mat1f pad_x_, pad_y_;              // zero-padded traction
  cv::Mat1f spec_x_, spec_y_, product_, sum_, result_;
};

}  // namespace norm2tex
