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
  grid_ = ShearGrid::of(model_, cell_px);
  displacement_ = std::make_unique<SurfaceDisplacement>(
      grid_.size.height, grid_.size.width, grid_.cell_mm, model_.shear.shear_modulus_mpa,
      model_.gel_thickness_mm);
  if (model_.markers.enabled) markers_ = std::make_unique<MarkerPattern>(model_);
  penetration_ = cv::Mat1f::zeros(grid_.size);
}

void ShearField::compute(const cv::Mat1f& h_sensor_mm, const cv::Rect& covered_box,
                         double normal_force_n, const ShearLoad& load, ShearFrame& out) {
  if (h_sensor_mm.size() != model_.imageSize()) {
    throw Error("ShearField::compute: H_sensor of " + std::to_string(h_sensor_mm.cols) + " x " +
                std::to_string(h_sensor_mm.rows) + " for a " + std::to_string(model_.cols) +
                " x " + std::to_string(model_.rows) + " sensor");
  }
  const double friction = load.friction.value_or(model_.shear.friction);
  meanCellPenetration(h_sensor_mm, covered_box, grid_, penetration_);
  out.cell_px = grid_.cell_px;
  out.cell_mm = grid_.cell_mm;
  out.traction = solveContactTraction(penetration_, grid_.cell_mm, normal_force_n, load, friction);
  if (out.traction.contact_cells == 0 || normal_force_n == 0.0 ||
      (load.force_n.isZero() && load.torque_nm == 0.0)) {
    // No tangential traction: the surface stays in place laterally (nu = 1/2).
    out.ux_mm = cv::Mat1f::zeros(grid_.size);
    out.uy_mm = cv::Mat1f::zeros(grid_.size);
  } else {
    displacement_->solve(out.traction.qx_mpa, out.traction.qy_mpa, out.ux_mm, out.uy_mm);
  }
  placeMarkers(out);
}

void ShearField::rest(ShearFrame& out) const {
  out.cell_px = grid_.cell_px;
  out.cell_mm = grid_.cell_mm;
  out.traction = ContactTraction{};
  out.ux_mm = cv::Mat1f::zeros(grid_.size);
  out.uy_mm = cv::Mat1f::zeros(grid_.size);
  placeMarkers(out);
}

void ShearField::placeMarkers(ShearFrame& out) const {
  out.markers.clear();
  if (!markers_) return;
  const double px_per_mm = 1.0 / model_.mm_per_pixel;
  for (const cv::Point2f& rest : markers_->restPx()) {
    Marker m;
    m.rest_px = rest;
    m.displacement_mm = {sampleCells(out.ux_mm, grid_.cell_px, rest.x, rest.y),
                         sampleCells(out.uy_mm, grid_.cell_px, rest.x, rest.y)};
    m.current_px = {static_cast<float>(rest.x + m.displacement_mm.x * px_per_mm),
                    static_cast<float>(rest.y + m.displacement_mm.y * px_per_mm)};
    out.markers.push_back(m);
  }
}

void ShearField::drawMarkers(cv::Mat3b& image, const ShearFrame& frame) const {
  if (markers_) markers_->draw(image, frame.markers);
}

}  // namespace norm2tex
