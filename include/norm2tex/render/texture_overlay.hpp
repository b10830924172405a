#pragma once

#include <memory>

#include <opencv2/core.hpp>

#include "norm2tex/render/contact_raster.hpp"
#include "norm2tex/texture/height_atlas.hpp"

namespace norm2tex {

/// The Norm2Tex overlay: H_local = H_global sampled at each pixel's UV, and
/// H_final = H_sensor + beta * H_local.
///
/// The texture is treated as part of the object's surface: where the object's surface is over
/// a pixel (finite gap), H_final = clamp(-gap + beta * H_local, 0, thickness). Inside the
/// contact this is exactly H_sensor + beta * H_local; at the rim a bump of the texture can
/// touch where the smooth surface does not, and a groove deeper than the indentation leaves the
/// gel untouched, as a real textured object would. Because H_local follows the UVs, the
/// texture moves with the object.
class TextureOverlay {
 public:
  /// `beta_mm` >= 0 (0 disables the texture); throws Error otherwise or for an empty atlas.
  TextureOverlay(std::shared_ptr<const HeightAtlas> atlas, double beta_mm);

  /// How far above the gel a textured surface can still touch: beta * max(H_global, 0), mm.
  double reachMm() const { return reach_mm_; }
  double betaMm() const { return beta_mm_; }

  /// Writes H_final (mm) and, if given, H_local for every pixel of `raster.covered_box`
  /// (0 where no surface). Outside that box both must already be 0: buffers of the wrong size
  /// are (re)allocated and zeroed here; reusing callers clear only what they last wrote, which
  /// spares two full-image writes per frame. `raster` must hold UVs.
  void apply(const ContactRaster& raster, double thickness_mm, cv::Mat1f& h_final,
             cv::Mat1f* h_local = nullptr) const;

 private:
  std::shared_ptr<const HeightAtlas> atlas_;
  double beta_mm_;
  double reach_mm_;
};

}  // namespace norm2tex
