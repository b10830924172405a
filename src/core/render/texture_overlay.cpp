#include "norm2tex/render/texture_overlay.hpp"

#include <algorithm>
#include <cmath>

#include "norm2tex/common/error.hpp"

namespace norm2tex {

TextureOverlay::TextureOverlay(std::shared_ptr<const HeightAtlas> atlas, double beta_mm)
    : atlas_(std::move(atlas)), beta_mm_(beta_mm) {
  if (!(beta_mm_ >= 0.0) || !std::isfinite(beta_mm_) || beta_mm_ > 10.0) {
    throw Error("beta = " + std::to_string(beta_mm) + " mm is out of range; valid: [0, 10] mm");
  }
  if (!atlas_ || atlas_->empty()) throw Error("TextureOverlay: no height atlas");
  double max_height = 0.0;
  cv::minMaxLoc(atlas_->heights(), nullptr, &max_height, nullptr, nullptr, atlas_->valid());
  reach_mm_ = beta_mm_ * std::max(0.0, max_height);
}

void TextureOverlay::apply(const ContactRaster& raster, double thickness_mm, cv::Mat1f& h_final,
                           cv::Mat1f* h_local) const {
  const auto prepare = [&raster](cv::Mat1f& buffer) {
    if (buffer.size() != raster.gap_mm.size()) buffer = cv::Mat1f::zeros(raster.gap_mm.size());
  };
  prepare(h_final);
  if (h_local != nullptr) prepare(*h_local);
  if (raster.covered_box.empty()) return;
  if (raster.uv.size() != raster.gap_mm.size()) throw Error("TextureOverlay: raster has no UVs");
  const float beta = static_cast<float>(beta_mm_);
  const float thickness = static_cast<float>(thickness_mm);
  const cv::Rect box = raster.covered_box;
  for (int r = box.y; r < box.y + box.height; ++r) {
    const float* gap = raster.gap_mm.ptr<float>(r);
    const cv::Vec2f* uv = raster.uv.ptr<cv::Vec2f>(r);
    float* out = h_final.ptr<float>(r);
    float* local = h_local != nullptr ? h_local->ptr<float>(r) : nullptr;
    for (int c = box.x; c < box.x + box.width; ++c) {
      if (!std::isfinite(gap[c])) {
        out[c] = 0.0f;
        if (local != nullptr) local[c] = 0.0f;
        continue;
      }
      const float height = atlas_->sampleFinite(uv[c][0], uv[c][1]);
      out[c] = std::clamp(-gap[c] + beta * height, 0.0f, thickness);
      if (local != nullptr) local[c] = height;
    }
  }
}

}  // namespace norm2tex
