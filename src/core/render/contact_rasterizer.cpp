#include "norm2tex/render/contact_rasterizer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

bool isFinite(const Eigen::Isometry3d& pose) { return pose.matrix().allFinite(); }

/// (Re)allocates the raster for `size`; otherwise clears only what the last frame touched.
void resetRaster(cv::Size size, bool want_uv, ContactRaster& out) {
  if (out.gap_mm.size() != size) {
    out.gap_mm.create(size);
    out.face.create(size);
    out.h_sensor_mm.create(size);
    out.gap_mm.setTo(kInfinity);
    out.face.setTo(-1);
    out.h_sensor_mm.setTo(0.0f);
    out.uv.release();
    out.covered_box = cv::Rect();
  } else if (!out.covered_box.empty()) {
    out.gap_mm(out.covered_box).setTo(kInfinity);
    out.face(out.covered_box).setTo(-1);
    out.h_sensor_mm(out.covered_box).setTo(0.0f);
  }
  if (want_uv) {
    if (out.uv.size() != size) {
      out.uv.create(size);
      out.uv.setTo(cv::Vec2f(0, 0));
    } else if (!out.covered_box.empty()) {
      out.uv(out.covered_box).setTo(cv::Vec2f(0, 0));
    }
  }
  out.covered_box = cv::Rect();
  out.triangles_rasterized = 0;
}

}  // namespace

ContactRasterizer::ContactRasterizer(const SensorModel& model) : model_(model) {
  validate(model_);
  gel_surface_mm_.create(model_.rows, model_.cols);
  const double radius = model_.gel_curvature_radius_mm;
  for (int r = 0; r < model_.rows; ++r) {
    for (int c = 0; c < model_.cols; ++c) {
      if (radius <= 0.0) {
        gel_surface_mm_(r, c) = 0.0f;
        continue;
      }
      const cv::Point2d p = model_.pixelToGelMm(r, c);
      const double r2 = std::min(p.x * p.x + p.y * p.y, radius * radius);
      gel_surface_mm_(r, c) = static_cast<float>(std::sqrt(radius * radius - r2) - radius);
    }
  }
}

void ContactRasterizer::rasterize(const TexturedMesh& mesh, const Eigen::Isometry3d& object_in_gel,
                                  double reach_mm, bool want_uv, ContactRaster& out) const {
  if (!isFinite(object_in_gel)) throw Error("object pose is not finite (NaN or infinity)");
  if (!(reach_mm >= 0.0) || !std::isfinite(reach_mm)) throw Error("reach_mm must be >= 0");
  want_uv = want_uv && mesh.hasUvs();
  resetRaster(model_.imageSize(), want_uv, out);

  // Cull in metres, in the gel frame: the gel's footprint (plus a pixel), up to reach_mm above.
  const double half_w = 0.5e-3 * (model_.gelWidthMm() + 2.0 * model_.mm_per_pixel);
  const double half_h = 0.5e-3 * (model_.gelHeightMm() + 2.0 * model_.mm_per_pixel);
  const Eigen::AlignedBox3f region(
      Eigen::Vector3f(static_cast<float>(-half_w), static_cast<float>(-half_h), -1e6f),
      Eigen::Vector3f(static_cast<float>(half_w), static_cast<float>(half_h),
                      static_cast<float>(1e-3 * reach_mm)));
  const Eigen::Isometry3f pose = object_in_gel.cast<float>();
  candidates_.clear();
  mesh.queryTriangles(pose, region, candidates_);

  // Gel-frame mm -> continuous pixel coordinates with pixel centres at integers.
  const float px_per_m = static_cast<float>(1e3 / model_.mm_per_pixel);
  const float col0 = 0.5f * model_.cols - 0.5f, row0 = 0.5f * model_.rows - 0.5f;
  const float reach = static_cast<float>(reach_mm);
  const auto& vertices = mesh.vertices();
  const auto& uvs = mesh.uvs();
  int min_r = model_.rows, max_r = -1, min_c = model_.cols, max_c = -1;

  for (const int t : candidates_) {
    const Eigen::Vector3i& tri = mesh.triangles()[t];
    Eigen::Vector3f p[3];
    for (int k = 0; k < 3; ++k) p[k] = pose * vertices[tri[k]];
    // Pixel-space x (column), y (row) and height z (mm) of the three corners.
    float x[3], y[3], z[3];
    for (int k = 0; k < 3; ++k) {
      x[k] = p[k].x() * px_per_m + col0;
      y[k] = p[k].y() * px_per_m + row0;
      z[k] = p[k].z() * 1e3f;
    }
    if (std::min({z[0], z[1], z[2]}) > reach) continue;  // the gel surface is at or below 0
    const float area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
    if (std::abs(area) < 1e-8f) continue;  // seen edge-on: its neighbours cover these pixels
    const int c_begin = std::max(0, static_cast<int>(std::ceil(std::min({x[0], x[1], x[2]}))));
    const int c_end =
        std::min(model_.cols - 1, static_cast<int>(std::floor(std::max({x[0], x[1], x[2]}))));
    const int r_begin = std::max(0, static_cast<int>(std::ceil(std::min({y[0], y[1], y[2]}))));
    const int r_end =
        std::min(model_.rows - 1, static_cast<int>(std::floor(std::max({y[0], y[1], y[2]}))));
    if (c_begin > c_end || r_begin > r_end) continue;
    ++out.triangles_rasterized;

    // Barycentric weights are affine in (column, row): w_k = a_k * column + b_k * row + c_k.
    const float inv = 1.0f / area;
    float a[3], b[3], c0[3];
    for (int k = 0; k < 3; ++k) {
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      a[k] = (y[i] - y[j]) * inv;
      b[k] = (x[j] - x[i]) * inv;
      c0[k] = (x[i] * y[j] - x[j] * y[i]) * inv;
    }
    Eigen::Vector2f uv[3] = {Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero(),
                             Eigen::Vector2f::Zero()};
    if (want_uv) {
      for (int k = 0; k < 3; ++k) uv[k] = uvs[tri[k]];
    }
    for (int r = r_begin; r <= r_end; ++r) {
      float* gap_row = out.gap_mm.ptr<float>(r);
      int* face_row = out.face.ptr<int>(r);
      const float* gel_row = gel_surface_mm_.ptr<float>(r);
      cv::Vec2f* uv_row = want_uv ? out.uv.ptr<cv::Vec2f>(r) : nullptr;
      for (int col = c_begin; col <= c_end; ++col) {
        const float w0 = a[0] * col + b[0] * r + c0[0];
        const float w1 = a[1] * col + b[1] * r + c0[1];
        const float w2 = 1.0f - w0 - w1;
        // Small tolerance so pixel centres exactly on a shared edge are never dropped.
        if (w0 < -1e-6f || w1 < -1e-6f || w2 < -1e-6f) continue;
        const float gap = w0 * z[0] + w1 * z[1] + w2 * z[2] - gel_row[col];
        if (gap >= gap_row[col] || gap > reach) continue;
        gap_row[col] = gap;
        face_row[col] = t;
        if (uv_row != nullptr) {
          const Eigen::Vector2f q = w0 * uv[0] + w1 * uv[1] + w2 * uv[2];
          uv_row[col] = cv::Vec2f(q.x(), q.y());
        }
        min_r = std::min(min_r, r);
        max_r = std::max(max_r, r);
        min_c = std::min(min_c, col);
        max_c = std::max(max_c, col);
      }
    }
  }
  if (max_r < 0) return;
  out.covered_box = cv::Rect(min_c, min_r, max_c - min_c + 1, max_r - min_r + 1);

  const float thickness = static_cast<float>(model_.gel_thickness_mm);
  for (int r = min_r; r <= max_r; ++r) {
    const float* gap_row = out.gap_mm.ptr<float>(r);
    float* h_row = out.h_sensor_mm.ptr<float>(r);
    for (int col = min_c; col <= max_c; ++col) {
      h_row[col] = gap_row[col] < 0.0f ? std::min(-gap_row[col], thickness) : 0.0f;
    }
  }
}

}  // namespace norm2tex
