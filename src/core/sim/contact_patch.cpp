#include "norm2tex/sim/contact_patch.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace norm2tex {

ContactPatchMeter::ContactPatchMeter(const SensorModel& model)
    : model_(model),
      rasterizer_(model),
      grid_(ShearGrid::of(
          model, std::max(1, static_cast<int>(std::lround(kSlipCellMm / model.mm_per_pixel))))) {}

ContactPatch ContactPatchMeter::measure(const TexturedMesh& mesh,
                                        const Eigen::Isometry3d& object_in_gel) {
  rasterizer_.rasterize(mesh, object_in_gel, 0.0, false, raster_);
  ContactPatch patch;
  // Sums of pixel indices: pixelToGelMm is affine, so the centroid maps once at the end
  // (per-pixel mapping was most of this function's cost on full-gel contacts).
  double sum_r = 0.0, sum_c = 0.0;
  float deepest_mm = 0.0f;
  const cv::Rect box = raster_.covered_box;
  for (int r = box.y; r < box.y + box.height; ++r) {
    const float* h = raster_.h_sensor_mm.ptr<float>(r);
    std::int64_t row_pixels = 0, row_sum_c = 0;
    for (int c = box.x; c < box.x + box.width; ++c) {
      const bool touching = h[c] > 0.0f;
      row_pixels += touching;
      row_sum_c += touching ? c : 0;
      deepest_mm = std::max(deepest_mm, h[c]);
    }
    patch.pixels += static_cast<int>(row_pixels);
    sum_r += static_cast<double>(row_pixels) * r;
    sum_c += static_cast<double>(row_sum_c);
  }
  if (patch.pixels > 0) {
    const double pixel_m = model_.mm_per_pixel * 1e-3;
    patch.area_m2 = patch.pixels * pixel_m * pixel_m;
    const cv::Point2d centroid_mm = model_.pixelToGelMm(sum_r / patch.pixels, sum_c / patch.pixels);
    patch.centroid_m = Eigen::Vector2d(centroid_mm.x, centroid_mm.y) * 1e-3;
    patch.max_indentation_m = static_cast<double>(deepest_mm) * 1e-3;
  }
  return patch;
}

ContactPatch ContactPatchMeter::measure(const TexturedMesh& mesh,
                                        const Eigen::Isometry3d& object_in_gel,
                                        double normal_force_n, const ShearLoad& load) {
  ContactPatch patch = measure(mesh, object_in_gel);
  const double friction = load.friction.value_or(model_.shear.friction);
  // Checked with or without contact: a bad load is the caller's mistake either way.
  if (patch.pixels == 0) {
    solveContactTraction(cv::Mat1f(), grid_.cell_mm, normal_force_n, load, friction);
    return patch;
  }
  meanCellPenetration(raster_.h_sensor_mm, raster_.covered_box, grid_, penetration_);
  patch.slip_fraction =
      solveContactTraction(penetration_, grid_.cell_mm, normal_force_n, load, friction)
          .slip_fraction;
  return patch;
}

}  // namespace norm2tex
