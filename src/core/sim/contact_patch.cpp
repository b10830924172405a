#include "norm2tex/sim/contact_patch.hpp"

namespace norm2tex {

ContactPatchMeter::ContactPatchMeter(const SensorModel& model)
    : model_(model), rasterizer_(model) {}

ContactPatch ContactPatchMeter::measure(const TexturedMesh& mesh,
                                        const Eigen::Isometry3d& object_in_gel) {
  rasterizer_.rasterize(mesh, object_in_gel, 0.0, false, raster_);
  ContactPatch patch;
  double sum_x = 0.0, sum_y = 0.0, deepest_mm = 0.0;
  const cv::Rect box = raster_.covered_box;
  for (int r = box.y; r < box.y + box.height; ++r) {
    const float* h = raster_.h_sensor_mm.ptr<float>(r);
    for (int c = box.x; c < box.x + box.width; ++c) {
      if (!(h[c] > 0.0f)) continue;
      const cv::Point2d xy = model_.pixelToGelMm(r, c);
      sum_x += xy.x;
      sum_y += xy.y;
      deepest_mm = std::max(deepest_mm, static_cast<double>(h[c]));
      ++patch.pixels;
    }
  }
  if (patch.pixels > 0) {
    const double pixel_m = model_.mm_per_pixel * 1e-3;
    patch.area_m2 = patch.pixels * pixel_m * pixel_m;
    patch.centroid_m = Eigen::Vector2d(sum_x, sum_y) * 1e-3 / patch.pixels;
    patch.max_indentation_m = deepest_mm * 1e-3;
  }
  return patch;
}

}  // namespace norm2tex
