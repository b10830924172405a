#include "norm2tex/calibrate/calibration_report.hpp"

#include <algorithm>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

constexpr int kTile = 160;
constexpr double kCropRadii = 1.6;
constexpr int kLineHeight = 16;

std::string format(const char* pattern, double a, double b = 0.0, double c = 0.0, double d = 0.0,
                   double e = 0.0, double f = 0.0) {
  char text[256];
  std::snprintf(text, sizeof(text), pattern, a, b, c, d, e, f);
  return text;
}

// A square crop of `image` around `centre`, padded with grey where it leaves the image.
cv::Mat3b cropTile(const cv::Mat3b& image, cv::Point2d centre, double half) {
  const int h = std::max(4, cvRound(half));
  cv::Mat3b padded;
  cv::copyMakeBorder(image, padded, h, h, h, h, cv::BORDER_CONSTANT, cv::Scalar(128, 128, 128));
  const cv::Rect rect(cvRound(centre.x), cvRound(centre.y), 2 * h, 2 * h);
  cv::Mat3b tile;
  cv::resize(padded(rect), tile, cv::Size(kTile, kTile), 0, 0, cv::INTER_LINEAR);
  return tile;
}

// The medians of the frame measures (render vs real frame, PressFrameComparison) of a set.
std::string describeFrameMedians(const std::vector<PressFrameComparison>& frames,
                                 ImageSimilarity PressFrameComparison::*measures) {
  if (frames.empty()) return "frames: none";
  const ImageSimilarity m = medianSimilarity(frames, measures);
  return format("frames, median SSIM %.3f (contact %.3f), PSNR %.1f dB, |diff| %.1f", m.ssim,
                m.ssim_in_mask, m.psnr_db, m.mean_abs_diff);
}

}  // namespace

std::vector<std::string> describeFitQuality(const CalibrationResult& r) {
  const FitQuality& q = r.held_out;
  std::vector<std::string> lines = {
      format("scale %.4f mm/px (%.1f px/mm), rim shadow sigma %.2f mm", r.fit.geometry.mm_per_pixel,
             1.0 / r.fit.geometry.mm_per_pixel, r.fit.shading.shadow_sigma_mm),
      r.training_presses > 0
          ? format("fit on %.0f presses explains %.2f of their variance; %.0f held out:",
                   r.training_presses, r.fit.variance_explained, q.presses)
          : format("nothing fitted (judged); %.0f presses held out:", q.presses),
      format("  variance explained %.2f", q.variance_explained),
      format("  contact mean |diff| real %.1f sim %.1f; 95th pct real %.1f sim %.1f",
             q.real_contact_mean, q.sim_contact_mean, q.real_contact_p95, q.sim_contact_p95),
      format("  darkest rim sector real %.1f sim %.1f grey levels", q.real_rim_darkest,
             q.sim_rim_darkest),
      format("  brightened side B/G/R deg real %.0f %.0f %.0f sim %.0f %.0f %.0f",
             q.real_side_deg[0], q.real_side_deg[1], q.real_side_deg[2], q.sim_side_deg[0],
             q.sim_side_deg[1], q.sim_side_deg[2]),
      "  " + describeFrameMedians(r.held_out_frames, &PressFrameComparison::similarity),
      "  bare background " +
          describeFrameMedians(r.held_out_frames, &PressFrameComparison::bare_background),
  };
  if (!r.training_frames.empty()) {
    lines.push_back("fitted presses' " +
                    describeFrameMedians(r.training_frames, &PressFrameComparison::similarity));
  }
  if (r.markers.found()) {
    const MarkerOptions& m = r.model.markers;
    lines.push_back(format("markers: %.0f found, a %.0f x %.0f grid at %.3f mm, dots %.3f mm "
                           "taking %.2f of the light",
                           static_cast<double>(r.markers.centres_px.size()), m.rows, m.cols,
                           m.pitch_mm, m.dot_diameter_mm, m.darkness) +
                    format(", centred at (%.3f, %.3f) mm; filled in before the fit",
                           m.offset_mm[0], m.offset_mm[1]));
  }
  return lines;
}

std::vector<std::string> describeScaleSearch(const ShadingFit& fit) {
  const ScaleSearch& search = fit.scale_search;
  if (search.profile.empty()) return {};
  std::vector<std::string> lines = {
      "scale searched (mm/px: variance explained, radius factor; detected circles):"};
  // Three grid points a line keeps the lines short enough for a terminal.
  for (size_t i = 0; i < search.profile.size(); i += 3) {
    std::string line = " ";
    for (size_t j = i; j < std::min(i + 3, search.profile.size()); ++j) {
      const ScaleProfilePoint& p = search.profile[j];
      line += format("  %.4f: %.3f, %.2f", p.mm_per_pixel, p.variance_explained, p.radius_factor);
    }
    lines.push_back(line);
  }
  // Only the spread under this response model: a real unit's response differs from it, and that
  // can move the best scale further (ScaleSearch).
  lines.push_back(
      format("scales within %.2f of the best: %.4f-%.4f mm/px (fit about as well; a "
             "response unlike the model's can move the best further)",
             kScaleIndifference, search.range_min, search.range_max));
  return lines;
}

cv::Mat3b makeCalibrationReport(const CalibrationResult& result, int max_presses) {
  const int rows = std::min<int>(max_presses, static_cast<int>(result.held_out_presses.size()));
  if (rows <= 0) throw Error("makeCalibrationReport: no held-out presses to show");
  const std::vector<std::string> lines = describeFitQuality(result);
  const int header = kLineHeight * (static_cast<int>(lines.size()) + 2);
  cv::Mat3b report(header + rows * kTile, 3 * kTile, cv::Vec3b(255, 255, 255));
  for (size_t i = 0; i < lines.size(); ++i) {
    cv::putText(report, lines[i], cv::Point(4, kLineHeight * static_cast<int>(i + 1) - 3),
                cv::FONT_HERSHEY_PLAIN, 0.8, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  const char* titles[3] = {"real", "calibrated render", "real - render (x2)"};
  for (int t = 0; t < 3; ++t) {
    cv::putText(report, titles[t], cv::Point(t * kTile + 4, header - 4), cv::FONT_HERSHEY_PLAIN,
                0.9, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  cv::Mat3f background;
  result.background.convertTo(background, CV_32F);
  for (int i = 0; i < rows; ++i) {
    const PressObservation& press = result.held_out_presses[i];
    cv::Mat3b real, difference;
    cv::Mat3f(background + press.diff).convertTo(real, CV_8U);
    const cv::Mat3b render = renderedPressFrame(result.background, result.held_out_simulated[i]);
    cv::Mat3f(2.0 * (press.diff - result.held_out_simulated[i]) + cv::Scalar::all(128.0))
        .convertTo(difference, CV_8U);
    const double half = kCropRadii * result.held_out_radii_px[i];
    const cv::Mat3b* images[3] = {&real, &render, &difference};
    for (int t = 0; t < 3; ++t) {
      cropTile(*images[t], press.circle.centre_px, half)
          .copyTo(report(cv::Rect(t * kTile, header + i * kTile, kTile, kTile)));
    }
  }
  return report;
}

}  // namespace norm2tex
