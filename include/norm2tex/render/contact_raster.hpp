#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace norm2tex {

/// What the ContactRasterizer sees of the object, per sensor pixel (image size, row-major).
struct ContactRaster {
  /// Object surface height above the undeformed gel surface along +z, mm: negative where the
  /// object penetrates the gel. +inf where no surface within reach lies over the pixel.
  cv::Mat1f gap_mm;
  /// UV (first channel) of the surface point at each pixel with a finite gap; (0, 0) elsewhere.
  /// Only filled when UVs were requested and the mesh has them.
  cv::Mat2f uv;
  /// Triangle index of that surface point, -1 where none.
  cv::Mat1i face;
  /// H_sensor: indentation of the gel, mm, positive into the gel: clamp(-gap, 0, thickness).
  cv::Mat1f h_sensor_mm;
  /// Bounding box of the pixels with a finite gap (empty when nothing is within reach).
  cv::Rect covered_box;
  /// Triangles that reached the rasterizer after culling (for diagnostics and benchmarks).
  int triangles_rasterized = 0;
  /// Pixel centres found inside a triangle, before the depth test, summed over triangles: equal
  /// to the covered pixel count when every pixel lies under exactly one triangle (a watertight
  /// surface seen from one side). For diagnostics and tests.
  long pixel_hits = 0;
  /// Scratch of the rasterizer (culled triangle indices), kept here so that one rasterizer can
  /// serve several threads, each with its own ContactRaster, without reallocating per frame.
  std::vector<int> candidates;
};

}  // namespace norm2tex
