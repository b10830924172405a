#include "norm2tex/shear/shear_field.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

// Bilinear sample of a cell-centred field at pixel (x, y); clamped at the grid's edge.
float sampleCells(const cv::Mat1f& field, int cell_px, double x_px, double y_px) {
  const double u = std::clamp((x_px + 0.5) / cell_px - 0.5, 0.0, field.cols - 1.0);
  const double v = std::clamp((y_px + 0.5) / cell_px - 0.5, 0.0, field.rows - 1.0);
  const int j = std::min(static_cast<int>(u), std::max(0, field.cols - 2));
  const int i = std::min(static_cast<int>(v), std::max(0, field.rows - 2));
  const int j1 = std::min(j + 1, field.cols - 1);
  const int i1 = std::min(i + 1, field.rows - 1);
  const double a = u - j, b = v - i;
  return static_cast<float>((1 - b) * ((1 - a) * field(i, j) + a * field(i, j1)) +
                            b * ((1 - a) * field(i1, j) + a * field(i1, j1)));
}

}  // namespace

cv::Mat2f ShearFrame::displacementMetres(cv::Size size) const {
  cv::Mat2f out(size, cv::Vec2f(0.0f, 0.0f));
  if (ux_mm.empty() || cell_px < 1) return out;
  for (int r = 0; r < size.height; ++r) {
    cv::Vec2f* row = out.ptr<cv::Vec2f>(r);
    for (int c = 0; c < size.width; ++c) {
      row[c] = {1e-3f * sampleCells(ux_mm, cell_px, c, r), 1e-3f * sampleCells(uy_mm, cell_px, c, r)};
    }
  }
  return out;
}

ShearField::ShearField(const SensorModel& model, int cell_px) : model_(model) {
  validate(model_);
  if (cell_px < 0) throw Error("ShearField: cell_px = " + std::to_string(cell_px) + " < 0");
  cell_px_ = cell_px > 0 ? cell_px
                         : std::max(1, static_cast<int>(std::lround(kShearCellMm /
                                                                    model_.mm_per_pixel)));
  cell_mm_ = cell_px_ * model_.mm_per_pixel;
  grid_ = {(model_.cols + cell_px_ - 1) / cell_px_, (model_.rows + cell_px_ - 1) / cell_px_};
  displacement_ = std::make_unique<SurfaceDisplacement>(
      grid_.height, grid_.width, cell_mm_, model_.shear.shear_modulus_mpa,
      model_.gel_thickness_mm);
  if (model_.markers.enabled) markers_ = std::make_unique<MarkerPattern>(model_);
  penetration_ = cv::Mat1f::zeros(grid_);
}

void ShearField::compute(const cv::Mat1f& h_sensor_mm, const cv::Rect& covered_box,
                         double normal_force_n, const ShearLoad& load, ShearFrame& out) {
  if (h_sensor_mm.size() != model_.imageSize()) {
    throw Error("ShearField::compute: H_sensor of " + std::to_string(h_sensor_mm.cols) + " x " +
                std::to_string(h_sensor_mm.rows) + " for a " + std::to_string(model_.cols) +
                " x " + std::to_string(model_.rows) + " sensor");
  }
  const double friction = load.friction.value_or(model_.shear.friction);
  // The mean penetration of each cell over the covered box (the rest is zero).
  penetration_.setTo(0.0f);
  const cv::Rect box = covered_box.empty() ? cv::Rect(cv::Point(), h_sensor_mm.size())
                                           : covered_box & cv::Rect(cv::Point(), h_sensor_mm.size());
  const int i0 = box.y / cell_px_, i1 = (box.y + box.height - 1) / cell_px_;
  const int j0 = box.x / cell_px_, j1 = (box.x + box.width - 1) / cell_px_;
  for (int i = i0; i <= i1 && !box.empty(); ++i) {
    const int r0 = i * cell_px_, r1 = std::min(h_sensor_mm.rows, r0 + cell_px_);
    for (int j = j0; j <= j1; ++j) {
      const int c0 = j * cell_px_, c1 = std::min(h_sensor_mm.cols, c0 + cell_px_);
      double sum = 0.0;
      for (int r = r0; r < r1; ++r) {
        const float* row = h_sensor_mm.ptr<float>(r);
        for (int c = c0; c < c1; ++c) sum += row[c];
      }
      penetration_(i, j) = static_cast<float>(sum / ((r1 - r0) * (c1 - c0)));
    }
  }
  out.cell_px = cell_px_;
  out.cell_mm = cell_mm_;
  out.traction = solveContactTraction(penetration_, cell_mm_, normal_force_n, load, friction);
  if (out.traction.contact_cells == 0 || normal_force_n == 0.0 ||
      (load.force_n.isZero() && load.torque_nm == 0.0)) {
    // No tangential traction: the surface stays in place laterally (nu = 1/2).
    out.ux_mm = cv::Mat1f::zeros(grid_);
    out.uy_mm = cv::Mat1f::zeros(grid_);
  } else {
    displacement_->solve(out.traction.qx_mpa, out.traction.qy_mpa, out.ux_mm, out.uy_mm);
  }
  placeMarkers(out);
}

void ShearField::rest(ShearFrame& out) const {
  out.cell_px = cell_px_;
  out.cell_mm = cell_mm_;
  out.traction = ContactTraction{};
  out.ux_mm = cv::Mat1f::zeros(grid_);
  out.uy_mm = cv::Mat1f::zeros(grid_);
  placeMarkers(out);
}

void ShearField::placeMarkers(ShearFrame& out) const {
  out.markers.clear();
  if (!markers_) return;
  const double px_per_mm = 1.0 / model_.mm_per_pixel;
  for (const cv::Point2f& rest : markers_->restPx()) {
    Marker m;
    m.rest_px = rest;
    m.displacement_mm = {sampleCells(out.ux_mm, cell_px_, rest.x, rest.y),
                         sampleCells(out.uy_mm, cell_px_, rest.x, rest.y)};
    m.current_px = {static_cast<float>(rest.x + m.displacement_mm.x * px_per_mm),
                    static_cast<float>(rest.y + m.displacement_mm.y * px_per_mm)};
    out.markers.push_back(m);
  }
}

void ShearField::drawMarkers(cv::Mat3b& image, const ShearFrame& frame) const {
  if (markers_) markers_->draw(image, frame.markers);
}

}  // namespace norm2tex
