#include "norm2tex/shear/shear_grid.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "norm2tex/common/error.hpp"

namespace norm2tex {

ShearGrid ShearGrid::of(const SensorModel& model, int cell_px) {
  if (cell_px < 0) throw Error("shear grid: cell_px = " + std::to_string(cell_px) + " < 0");
  ShearGrid grid;
  grid.cell_px = cell_px > 0 ? cell_px
                             : std::max(1, static_cast<int>(std::lround(kDefaultCellMm /
                                                                        model.mm_per_pixel)));
  grid.cell_mm = grid.cell_px * model.mm_per_pixel;
  grid.image = model.imageSize();
  grid.size = {(model.cols + grid.cell_px - 1) / grid.cell_px,
               (model.rows + grid.cell_px - 1) / grid.cell_px};
  return grid;
}

void meanCellPenetration(const cv::Mat1f& h_sensor_mm, const cv::Rect& covered_box,
                         const ShearGrid& grid, cv::Mat1f& out) {
  if (h_sensor_mm.size() != grid.image) {
    throw Error("shear grid: H_sensor of " + std::to_string(h_sensor_mm.cols) + " x " +
                std::to_string(h_sensor_mm.rows) + " px for a " + std::to_string(grid.image.width) +
                " x " + std::to_string(grid.image.height) + " px sensor");
  }
  const int cell = grid.cell_px;
  out.create(grid.size);
  out.setTo(0.0f);
  const cv::Rect whole(cv::Point(), h_sensor_mm.size());
  const cv::Rect box = covered_box.empty() ? whole : covered_box & whole;
  if (box.empty()) return;
  const int i0 = box.y / cell, i1 = (box.y + box.height - 1) / cell;
  const int j0 = box.x / cell, j1 = (box.x + box.width - 1) / cell;
  for (int i = i0; i <= i1; ++i) {
    const int r0 = i * cell, r1 = std::min(h_sensor_mm.rows, r0 + cell);
    for (int j = j0; j <= j1; ++j) {
      const int c0 = j * cell, c1 = std::min(h_sensor_mm.cols, c0 + cell);
      double sum = 0.0;
      for (int r = r0; r < r1; ++r) {
        const float* row = h_sensor_mm.ptr<float>(r);
        for (int c = c0; c < c1; ++c) sum += row[c];
      }
      out(i, j) = static_cast<float>(sum / ((r1 - r0) * (c1 - c0)));
    }
  }
}

}  // namespace norm2tex
