#pragma once

#include <Eigen/Geometry>

#include "norm2tex/mesh/textured_mesh.hpp"
#include "norm2tex/render/contact_raster.hpp"
#include "norm2tex/render/contact_rasterizer.hpp"
#include "norm2tex/render/sensor_model.hpp"

namespace norm2tex {

/// The contact as the sensor sees it: where the object's render mesh lies below the undeformed
/// gel surface, over the sensor's imaged area (the same geometry the renderer draws as H_sensor).
struct ContactPatch {
  int pixels = 0;        ///< sensor pixels in contact
  double area_m2 = 0.0;  ///< pixels times the pixel's area on the gel, m^2
  Eigen::Vector2d centroid_m = Eigen::Vector2d::Zero();  ///< gel frame x, y of the contact, m
  double max_indentation_m = 0.0;                        ///< deepest H_sensor, m
};

/// Measures ContactPatch for one sensor; keeps its raster buffers between calls (so one meter
/// per thread).
class ContactPatchMeter {
 public:
  explicit ContactPatchMeter(const SensorModel& model);
  /// `object_in_gel`: the object frame in the gel frame, metres. Throws Error on a non-finite
  /// pose.
  ContactPatch measure(const TexturedMesh& mesh, const Eigen::Isometry3d& object_in_gel);

 private:
  SensorModel model_;
  ContactRasterizer rasterizer_;
  ContactRaster raster_;
};

}  // namespace norm2tex
