#pragma once

#include <Eigen/Geometry>

#include "norm2tex/mesh/textured_mesh.hpp"
#include "norm2tex/render/contact_raster.hpp"
#include "norm2tex/render/sensor_model.hpp"

namespace norm2tex {

/// Renders the object orthographically along the gel normal into the sensor grid: for every
/// pixel the lowest object surface over it (the side facing the gel), its UV and face.
///
/// Only triangles that the mesh's BVH places near the gel (inside the gel's footprint, at most
/// `reach_mm` above the gel surface) are rasterized, so large meshes stay fast. Pixel centres
/// follow SensorModel::pixelToGelMm; a pixel is covered when its centre lies inside the
/// projected triangle. Watertight: corners are snapped to 1/256 pixel and the edge functions
/// evaluated exactly in 64-bit integers, with the top-left rule for centres exactly on an edge,
/// so a pixel under an edge shared by two triangles is drawn by exactly one of them (no holes,
/// no double cover). Corners further than 2^22 pixels from the image (a triangle hundreds of
/// metres across) fall back to floating point.
///
/// rasterize() is const and thread-safe: several threads may share one rasterizer, each with
/// its own ContactRaster.
class ContactRasterizer {
 public:
  explicit ContactRasterizer(const SensorModel& model);

  /// `object_in_gel`: pose of the object frame in the gel frame (metres). `reach_mm` >= 0:
  /// surfaces up to this far above the gel are kept (texture can still touch there).
  /// `want_uv`: interpolate UVs (skip for the textureless path). Throws Error on a non-finite
  /// pose. Reuses `out`'s buffers between calls.
  void rasterize(const TexturedMesh& mesh, const Eigen::Isometry3d& object_in_gel, double reach_mm,
                 bool want_uv, ContactRaster& out) const;

  /// Height of the undeformed gel surface at each pixel, mm (0 for a flat gel; a dome of the
  /// model's curvature radius, 0 at the centre and negative towards the edges, otherwise).
  const cv::Mat1f& gelSurfaceMm() const { return gel_surface_mm_; }

 private:
  SensorModel model_;
  cv::Mat1f gel_surface_mm_;
};

}  // namespace norm2tex
