#include "norm2tex/render/gel_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

// Each pyramid level runs at 1/f of the image resolution, f the largest of kFactors at which
// its sigma still spans kMinReducedSigmaPx reduced pixels: the blurs are wide (0.1 to 0.5 mm =
// 2 to 9 pixels at 0.054 mm/px), the blurred skirt is smooth, and a level at half resolution
// costs an eighth (a quarter of the pixels, half the taps). The skirt is upsampled bilinearly
// when the next level is finer; the core is restored at every resolution.
constexpr int kFactors[] = {4, 2};
constexpr double kMinReducedSigmaPx = 1.5;
constexpr float kNegligibleMm = 1e-4f;

int reductionFor(double sigma_px) {
  for (const int factor : kFactors) {
    if (sigma_px / factor >= kMinReducedSigmaPx) return factor;
  }
  return 1;
}

cv::Size kernelFor(double sigma_px) {
  const int radius = std::max(1, static_cast<int>(std::ceil(3.0 * sigma_px)));
  return {2 * radius + 1, 2 * radius + 1};
}

// The helpers below are single passes over the image: the GelModel used to chain OpenCV
// calls (compare, boundingRect, masked copies, min, masked set), a dozen full-image passes and
// temporaries that cost about as much as the blurs.

/// The bounding box of per-row spans [first, last], grown one row at a time.
struct SpanBox {
  int top = -1, bottom = -1, left = std::numeric_limits<int>::max(), right = -1;
  void add(int row, int first, int last) {
    if (top < 0) top = row;
    bottom = row;
    left = std::min(left, first);
    right = std::max(right, last);
  }
  cv::Rect rect() const {
    return top < 0 ? cv::Rect() : cv::Rect(left, top, right - left + 1, bottom - top + 1);
  }
};

/// The largest value of `field` (NaNs aside), as cv::minMaxLoc finds it, a vector at a time:
/// minMaxLoc also tracks where the extremes are, which cost ~30 us a frame here.
float largestValue(const cv::Mat1f& field) {
  constexpr int kLanes = cv::v_float32x4::nlanes;
  float largest = -std::numeric_limits<float>::infinity();
  cv::v_float32x4 lanes[4];
  for (cv::v_float32x4& lane : lanes) lane = cv::v_setall_f32(largest);
  for (int r = 0; r < field.rows; ++r) {
    const float* row = field.ptr<float>(r);
    int c = 0;
    for (; c + 4 * kLanes <= field.cols; c += 4 * kLanes) {
      for (int k = 0; k < 4; ++k) lanes[k] = cv::v_max(lanes[k], cv::v_load(row + c + k * kLanes));
    }
    for (; c < field.cols; ++c) largest = row[c] > largest ? row[c] : largest;
  }
  for (const cv::v_float32x4& lane : lanes) largest = std::max(largest, cv::v_reduce_max(lane));
  return largest;
}

/// Bounding box of the values above kNegligibleMm (empty when none).
cv::Rect deformationBox(const cv::Mat1f& field) {
  SpanBox box;
  for (int r = 0; r < field.rows; ++r) {
    const float* row = field.ptr<float>(r);
    int first = 0;
    while (first < field.cols && !(row[first] > kNegligibleMm)) ++first;
    if (first == field.cols) continue;
    int last = field.cols - 1;
    while (!(row[last] > kNegligibleMm)) --last;
    box.add(r, first, last);
  }
  return box.rect();
}

/// out = keep ? a : b for one row; both sides read, so it compiles to vector blends, not to a
/// branch per pixel. out may be a or b (the callers update a row in place), so no __restrict
/// on them: each element is read before it is written.
void selectRow(const uchar* __restrict keep, const float* a, const float* b, float* out,
               int count) {
  for (int c = 0; c < count; ++c) {
    const float from_a = a[c], from_b = b[c];
    out[c] = keep[c] ? from_a : from_b;
  }
}

/// out = in where core is set (the contact core restored).
void restoreCore(const cv::Mat1f& in, const cv::Mat1b& core, cv::Mat1f& out) {
  for (int r = 0; r < in.rows; ++r) {
    float* target = out.ptr<float>(r);
    selectRow(core.ptr<uchar>(r), in.ptr<float>(r), target, target, in.cols);
  }
}

/// Bounding box of the pixels of `box` outside the core (empty when the core covers it).
cv::Rect outsideCoreBox(const cv::Mat1b& core, const cv::Rect& box) {
  SpanBox outside;
  const auto width = static_cast<std::size_t>(box.width);
  for (int r = box.y; r < box.y + box.height; ++r) {
    // A core row is mostly 255: memchr/memrchr find its first and last 0 a vector at a time.
    const uchar* row = core.ptr<uchar>(r) + box.x;
    const auto* first = static_cast<const uchar*>(std::memchr(row, 0, width));
    if (first == nullptr) continue;
    const auto* last = static_cast<const uchar*>(memrchr(row, 0, width));
    outside.add(r, box.x + static_cast<int>(first - row), box.x + static_cast<int>(last - row));
  }
  return outside.rect();
}

/// Gaussian blur of `field` restricted to the bounding box of its non-negligible values, grown
/// by the kernel: the rest of the image is 0 and stays 0. With `core`, pixels inside it keep
/// their values (the caller's field holds the core's own there) and only the neighbourhood of
/// the others is blurred: a contact over most of the gel leaves a thin rim to compute. Same
/// values as blurring the whole box and restoring the core: the kernel never reaches the smaller
/// region's inner edges from a written pixel.
void blurAroundDeformation(double sigma_px, cv::Mat1f& field, const cv::Mat1b* core = nullptr) {
  const cv::Size kernel = kernelFor(sigma_px);
  cv::Rect box = deformationBox(field);
  if (box.empty()) return;
  box.x -= kernel.width;
  box.y -= kernel.height;
  box.width += 2 * kernel.width;
  box.height += 2 * kernel.height;
  box &= cv::Rect(0, 0, field.cols, field.rows);
  if (core == nullptr) {
    // In place, the border replicated from the box itself (as from a copy of it): OpenCV's
    // filter reads a row into its ring buffer before it writes the rows that need it.
    cv::Mat1f region = field(box);
    cv::GaussianBlur(region, region, kernel, sigma_px, sigma_px,
                     cv::BORDER_REPLICATE | cv::BORDER_ISOLATED);
    return;
  }
  const cv::Rect written = outsideCoreBox(*core, box);
  if (written.empty()) return;
  const int radius = kernel.width / 2;
  const cv::Rect read = cv::Rect(written.x - radius, written.y - radius, written.width + 2 * radius,
                                 written.height + 2 * radius) &
                        box;
  cv::Mat1f blurred;
  cv::GaussianBlur(field(read), blurred, kernel, sigma_px, sigma_px,
                   cv::BORDER_REPLICATE | cv::BORDER_ISOLATED);
  for (int r = written.y; r < written.y + written.height; ++r) {
    float* target = field.ptr<float>(r) + written.x;
    selectRow(core->ptr<uchar>(r) + written.x, target,
              blurred.ptr<float>(r - read.y) + (written.x - read.x), target, written.width);
  }
}

}  // namespace

GelModel::GelModel(const SensorModel& model) : model_(model) { validate(model_); }

void GelModel::apply(const cv::Mat1f& indentation_mm, cv::Mat1f& out) const {
  if (indentation_mm.size() != model_.imageSize()) throw Error("GelModel: wrong image size");
  const double max_indentation = largestValue(indentation_mm);
  out.create(indentation_mm.size());
  if (max_indentation <= 0.0) {  // no contact: the gel is flat
    out.setTo(0.0f);
    return;
  }
  const cv::Mat1b core = indentation_mm > model_.gel.core_fraction * max_indentation;

  // The input and its core at the current level's resolution (factor 1: the image's own).
  cv::Mat1f level_in;
  cv::Mat1b level_core;
  cv::Mat1f current;
  int current_factor = 0;
  for (const double sigma_mm : model_.gel.pyramid_sigmas_mm) {
    int factor = reductionFor(sigma_mm / model_.mm_per_pixel);
    if (current_factor > 0) factor = std::min(factor, current_factor);  // never coarser again
    const cv::Size size(std::max(1, indentation_mm.cols / factor),
                        std::max(1, indentation_mm.rows / factor));
    if (factor != current_factor) {
      if (factor == 1) {
        level_in = indentation_mm;
        level_core = core;
      } else {
        cv::resize(indentation_mm, level_in, size, 0, 0, cv::INTER_AREA);
        // Core where more than half of the pixels are: an area average of 0/255 over n pixels
        // is 255 k / n, rounded; k = n/2 gives at most 128.
        cv::Mat1b core_share;
        cv::resize(core, core_share, size, 0, 0, cv::INTER_AREA);
        level_core = core_share > 128;
      }
      if (current.empty()) {
        current = level_in.clone();
      } else {
        cv::resize(current.clone(), current, size, 0, 0, cv::INTER_LINEAR);
        restoreCore(level_in, level_core, current);
      }
      current_factor = factor;
    }
    const double level_mm_per_pixel = model_.mm_per_pixel * indentation_mm.cols / size.width;
    // current holds level_in on the core (restored at every change of resolution), and the
    // blur keeps it there.
    blurAroundDeformation(sigma_mm / level_mm_per_pixel, current, &level_core);
  }
  if (current.empty()) {
    indentation_mm.copyTo(out);
  } else if (current_factor > 1) {
    cv::resize(current, out, indentation_mm.size(), 0, 0, cv::INTER_LINEAR);
    restoreCore(indentation_mm, core, out);
  } else if (out.isSubmatrix()) {
    current.copyTo(out);
  } else {
    out = current;  // the finest level is the result: taken over, not copied
  }

  // The bending blur at full resolution, only where the gel moved.
  if (model_.gel.final_sigma_mm > 0.0) {
    blurAroundDeformation(model_.gel.final_sigma_mm / model_.mm_per_pixel, out);
  }
  // Clamped to the thickness. The blurs leave a faint tail across the whole image; below 0.1 um
  // it is invisible (under a hundredth of a grey level) but would make every pixel "in contact"
  // for the shader.
  const float thickness = static_cast<float>(model_.gel_thickness_mm);
  for (int r = 0; r < out.rows; ++r) {
    float* row = out.ptr<float>(r);
    for (int c = 0; c < out.cols; ++c) {
      const float value = std::min(row[c], thickness);
      row[c] = value < kNegligibleMm ? 0.0f : value;
    }
  }
}

}  // namespace norm2tex
