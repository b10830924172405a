#include "norm2tex/render/texture_overlay.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

constexpr float kNoSurface = std::numeric_limits<float>::infinity();

}  // namespace

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
  // Per row: which pixels have the surface over them, H_local there (SIMD look-up), then
  // H_final. Reused per thread: the renderer calls this every frame.
  thread_local std::vector<unsigned char> covered_buffer;
  thread_local std::vector<float> heights_buffer;
  covered_buffer.resize(box.width);
  heights_buffer.resize(box.width);
  // Plain pointers: through the thread_local vectors the compiler reloads their data on every
  // byte written (a char may alias anything) and the loops stay scalar.
  unsigned char* const covered = covered_buffer.data();
  float* const heights = heights_buffer.data();
  for (int r = box.y; r < box.y + box.height; ++r) {
    const float* gap = raster.gap_mm.ptr<float>(r) + box.x;
    const cv::Vec2f* uv = raster.uv.ptr<cv::Vec2f>(r) + box.x;
    float* out = h_final.ptr<float>(r) + box.x;
    float* local = h_local != nullptr ? h_local->ptr<float>(r) + box.x : nullptr;
    // Branch-free, so the compiler vectorises both loops. The gap is finite or +infinity (no
    // surface over the pixel; the rasterizer never writes NaN), and -infinity clamps to 0.
    // The next row's texels start loading while this row is sampled.
    if (r + 1 < box.y + box.height) {
      atlas_->prefetchRow(raster.uv.ptr<cv::Vec2f>(r + 1) + box.x, box.width);
    }
    for (int i = 0; i < box.width; ++i) covered[i] = gap[i] < kNoSurface;
    atlas_->sampleFiniteRow(uv, covered, box.width, heights);
    for (int i = 0; i < box.width; ++i) {
      out[i] = std::min(std::max(beta * heights[i] - gap[i], 0.0f), thickness);
    }
    if (local != nullptr) std::copy_n(heights, box.width, local);
  }
}

}  // namespace norm2tex
