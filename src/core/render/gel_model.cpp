#include "norm2tex/render/gel_model.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

// The pyramid runs at 1/kLowResFactor of the image resolution: its blurs are wide (0.25 to
// 2 mm = 3 to 25 pixels at QVGA), so the low-resolution skirt loses nothing visible.
constexpr int kLowResFactor = 4;
constexpr float kNegligibleMm = 1e-4f;
// Levels narrower than this (in low-resolution pixels) run at full resolution instead.
constexpr double kMinLowResSigmaPx = 1.5;

cv::Size kernelFor(double sigma_px) {
  const int radius = std::max(1, static_cast<int>(std::ceil(3.0 * sigma_px)));
  return {2 * radius + 1, 2 * radius + 1};
}

/// Gaussian blur of `field` restricted to the bounding box of its non-negligible values, grown
/// by the kernel: the rest of the image is 0 and stays 0.
void blurAroundDeformation(double sigma_px, cv::Mat1f& field) {
  const cv::Size kernel = kernelFor(sigma_px);
  cv::Rect box = cv::boundingRect(field > kNegligibleMm);
  if (box.empty()) return;
  box.x -= kernel.width;
  box.y -= kernel.height;
  box.width += 2 * kernel.width;
  box.height += 2 * kernel.height;
  box &= cv::Rect(0, 0, field.cols, field.rows);
  cv::Mat1f region = field(box);
  cv::GaussianBlur(region.clone(), region, kernel, sigma_px, sigma_px, cv::BORDER_REPLICATE);
}

}  // namespace

GelModel::GelModel(const SensorModel& model) : model_(model) { validate(model_); }

void GelModel::apply(const cv::Mat1f& indentation_mm, cv::Mat1f& out) const {
  if (indentation_mm.size() != model_.imageSize()) throw Error("GelModel: wrong image size");
  double max_indentation = 0.0;
  cv::minMaxLoc(indentation_mm, nullptr, &max_indentation);
  out.create(indentation_mm.size());
  if (max_indentation <= 0.0) {  // no contact: the gel is flat
    out.setTo(0.0f);
    return;
  }
  const cv::Mat1b core = indentation_mm > model_.gel.core_fraction * max_indentation;

  // Coarse levels at low resolution, restoring the (low-resolution) core after each.
  const cv::Size low_size(std::max(1, indentation_mm.cols / kLowResFactor),
                          std::max(1, indentation_mm.rows / kLowResFactor));
  const double low_mm_per_pixel = model_.mm_per_pixel * indentation_mm.cols / low_size.width;
  std::vector<double> fine_sigmas_mm;
  cv::Mat1f low_in, low;
  cv::Mat1b low_core;
  for (const double sigma_mm : model_.gel.pyramid_sigmas_mm) {
    const double sigma_px = sigma_mm / low_mm_per_pixel;
    if (sigma_px < kMinLowResSigmaPx) {
      fine_sigmas_mm.push_back(sigma_mm);
      continue;
    }
    if (low.empty()) {
      cv::resize(indentation_mm, low_in, low_size, 0, 0, cv::INTER_AREA);
      cv::Mat1f core_fraction;
      cv::resize(cv::Mat1f(core / 255), core_fraction, low_size, 0, 0, cv::INTER_AREA);
      low_core = core_fraction > 0.5f;
      low = low_in.clone();
    }
    cv::GaussianBlur(low, low, kernelFor(sigma_px), sigma_px, sigma_px, cv::BORDER_REPLICATE);
    low_in.copyTo(low, low_core);
  }
  if (low.empty()) {
    indentation_mm.copyTo(out);
  } else {
    cv::resize(low, out, indentation_mm.size(), 0, 0, cv::INTER_LINEAR);
    indentation_mm.copyTo(out, core);
  }

  // Fine levels and the bending blur at full resolution, only where the gel moved.
  for (const double sigma_mm : fine_sigmas_mm) {
    blurAroundDeformation(sigma_mm / model_.mm_per_pixel, out);
    indentation_mm.copyTo(out, core);
  }
  if (model_.gel.final_sigma_mm > 0.0) {
    blurAroundDeformation(model_.gel.final_sigma_mm / model_.mm_per_pixel, out);
  }
  cv::min(out, model_.gel_thickness_mm, out);
  // The blurs leave a faint tail across the whole image; below 0.1 um it is invisible (under a
  // hundredth of a grey level) but would make every pixel "in contact" for the shader.
  out.setTo(0.0f, out < kNegligibleMm);
}

}  // namespace norm2tex
