#pragma once

#include <Eigen/Geometry>

#include "norm2tex/mesh/textured_mesh.hpp"
#include "norm2tex/render/contact_raster.hpp"
#include "norm2tex/render/contact_rasterizer.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/shear/contact_traction.hpp"
#include "norm2tex/shear/shear_grid.hpp"

namespace norm2tex {

/// The contact as the sensor sees it: where the object's render mesh lies below the undeformed
/// gel surface, over the sensor's imaged area (the same geometry the renderer draws as H_sensor).
struct ContactPatch {
  int pixels = 0;        ///< sensor pixels in contact
  double area_m2 = 0.0;  ///< pixels times the pixel's area on the gel, m^2
  Eigen::Vector2d centroid_m = Eigen::Vector2d::Zero();  ///< gel frame x, y of the contact, m
  double max_indentation_m = 0.0;                        ///< deepest H_sensor, m
  /// Fraction of the contact's area that slips under the load measure() was given
  /// (ContactTraction::slip_fraction: 0 in full stick, 1 in gross slip); 0 without a load,
  /// without contact or without a normal force.
  double slip_fraction = 0.0;
};

/// Measures ContactPatch for one sensor; keeps its raster buffers between calls (so one meter
/// per thread).
class ContactPatchMeter {
 public:
  explicit ContactPatchMeter(const SensorModel& model);
  /// `object_in_gel`: the object frame in the gel frame, metres. Throws Error on a non-finite
  /// pose.
  ContactPatch measure(const TexturedMesh& mesh, const Eigen::Isometry3d& object_in_gel);
  /// The same, and how much of it slips under the contact's normal force (N) and tangential
  /// load: solveContactTraction on the patch's penetration, over cells of about kSlipCellMm,
  /// with the load's friction, else the sensor model's. Throws Error also for a bad force or
  /// load (solveContactTraction's).
  ContactPatch measure(const TexturedMesh& mesh, const Eigen::Isometry3d& object_in_gel,
                       double normal_force_n, const ShearLoad& load);

  /// The side of the cells the slip is solved on, mm (2 px at a DIGIT's QVGA scale). Finer than
  /// the renderer's shear grid (ShearGrid::kDefaultCellMm), whose 0.4 mm cells carry the
  /// surface's smooth displacement well but resolve a thin slip annulus poorly: a ball's slip
  /// at 0.2 of the friction limit is Mindlin's 0.14 to 0.02 on these cells, and 0.25-0.28 on
  /// 0.4 mm ones. The renderer's slip (TactileMarkers) is therefore coarser than this.
  static constexpr double kSlipCellMm = 0.1;

 private:
  SensorModel model_;
  ContactRasterizer rasterizer_;
  ContactRaster raster_;
  ShearGrid grid_;
  cv::Mat1f penetration_;  // per cell of grid_, mm
};

}  // namespace norm2tex
