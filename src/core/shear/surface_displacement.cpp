#include "norm2tex/shear/surface_displacement.hpp"

#include <cmath>
#include <optional>
#include <string>

#include "norm2tex/common/error.hpp"
#include "norm2tex/shear/cerruti_kernel.hpp"
#include "norm2tex/shear/layer_compliance.hpp"

namespace norm2tex {
namespace {

// The offset an index of the padded grid stands for: 0 .. n-1 forwards, the rest backwards
// (circular indexing), so that the product of spectra is the linear convolution over the
// original grid as long as the padded size is at least 2 n - 1.
int offsetOf(int index, int padded) { return index < padded / 2 ? index : index - padded; }

}  // namespace

SurfaceDisplacement::SurfaceDisplacement(int rows, int cols, double cell_mm,
                                         double shear_modulus_mpa, double thickness_mm)
    : rows_(rows), cols_(cols), cell_mm_(cell_mm) {
  if (rows < 1 || cols < 1) {
    throw Error("SurfaceDisplacement: the grid is empty (" + std::to_string(rows) + " x " +
                std::to_string(cols) + " cells)");
  }
  if (!(cell_mm > 0.0) || !(shear_modulus_mpa > 0.0)) {
    throw Error("SurfaceDisplacement: cell size and shear modulus must be > 0");
  }
  if (!(thickness_mm >= 0.0) || !std::isfinite(thickness_mm)) {
    throw Error("SurfaceDisplacement: the layer's thickness must be >= 0 mm (0: a half-space)");
  }
  padded_ = {cv::getOptimalDFTSize(2 * cols), cv::getOptimalDFTSize(2 * rows)};
  std::optional<LayerCorrection> layer;
  if (thickness_mm > 0.0) {
    layer = layerCorrection(thickness_mm, std::hypot(padded_.width, padded_.height) * 0.5 * cell_mm);
  }
  const double area_over_g = cell_mm * cell_mm / shear_modulus_mpa;
  cv::Mat1f xx(padded_), xy(padded_), yy(padded_);
  for (int i = 0; i < padded_.height; ++i) {
    const double dy = offsetOf(i, padded_.height) * cell_mm;
    for (int j = 0; j < padded_.width; ++j) {
      const double dx = offsetOf(j, padded_.width) * cell_mm;
      LateralInfluence k = cerrutiCellInfluence(dx, dy, cell_mm, shear_modulus_mpa);
      if (layer) {
        const double r = std::hypot(dx, dy);
        double s = 0.0, d = 0.0;
        layer->at(r, s, d);
        // S I + D (2 r^ r^T - I), for the cell's traction at its centre.
        const double cx = r > 0.0 ? dx / r : 0.0, cy = r > 0.0 ? dy / r : 0.0;
        k.xx += area_over_g * (s + d * (2 * cx * cx - 1));
        k.xy += area_over_g * (d * 2 * cx * cy);
        k.yy += area_over_g * (s + d * (2 * cy * cy - 1));
      }
      xx(i, j) = static_cast<float>(k.xx);
      xy(i, j) = static_cast<float>(k.xy);
      yy(i, j) = static_cast<float>(k.yy);
    }
  }
  cv::dft(xx, kxx_);
  cv::dft(xy, kxy_);
  cv::dft(yy, kyy_);
  pad_x_ = cv::Mat1f::zeros(padded_);
  pad_y_ = cv::Mat1f::zeros(padded_);
}

void SurfaceDisplacement::solve(const cv::Mat1f& qx, const cv::Mat1f& qy, cv::Mat1f& ux,
                                cv::Mat1f& uy) {
  if (qx.rows != rows_ || qx.cols != cols_ || qy.size() != qx.size()) {
    throw Error("SurfaceDisplacement::solve: traction of " + std::to_string(qx.rows) + " x " +
                std::to_string(qx.cols) + " cells for a grid of " + std::to_string(rows_) +
                " x " + std::to_string(cols_));
  }
  const cv::Rect grid(0, 0, cols_, rows_);
  qx.copyTo(pad_x_(grid));
  qy.copyTo(pad_y_(grid));
  // The padding's rows are zero and only the grid's rows of the result are read: both
  // transforms skip the rest (OpenCV's nonzeroRows).
  cv::dft(pad_x_, spec_x_, 0, rows_);
  cv::dft(pad_y_, spec_y_, 0, rows_);
  const auto component = [&](const cv::Mat1f& k_from_x, const cv::Mat1f& k_from_y,
                             cv::Mat1f& out) {
    cv::mulSpectrums(spec_x_, k_from_x, sum_, 0);
    cv::mulSpectrums(spec_y_, k_from_y, product_, 0);
    sum_ += product_;
    cv::dft(sum_, result_, cv::DFT_INVERSE | cv::DFT_SCALE | cv::DFT_REAL_OUTPUT, rows_);
    result_(grid).copyTo(out);
  };
  component(kxx_, kxy_, ux);
  component(kxy_, kyy_, uy);
}

}  // namespace norm2tex
