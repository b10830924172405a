#include "norm2tex/calibrate/texture_match_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <opencv2/imgproc.hpp>

#include "norm2tex/calibrate/qvga_scale.hpp"
#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

constexpr int kTile = 160;
constexpr int kLineHeight = 16;
constexpr int kPlotWidth = 2 * kTile, kPlotHeight = 220;
constexpr double kCropHalfQvgaPx = 48.0;  // 2.5 mm: a few periods of most textures
constexpr double kBandGain = 4.0;
const cv::Scalar kRealColour(40, 40, 200), kSimColour(200, 90, 20), kInk(0, 0, 0);

std::string format(const char* pattern, double a, double b = 0.0, double c = 0.0, double d = 0.0,
                   double e = 0.0) {
  char text[256];
  std::snprintf(text, sizeof(text), pattern, a, b, c, d, e);
  return text;
}

void text(cv::Mat3b& image, const std::string& line, cv::Point at, double size = 0.8) {
  cv::putText(image, line, at, cv::FONT_HERSHEY_PLAIN, size, kInk, 1, cv::LINE_AA);
}

cv::Mat3b cropTile(const cv::Mat3b& image, cv::Point2d centre, double half) {
  const int h = std::max(4, cvRound(half));
  cv::Mat3b padded;
  cv::copyMakeBorder(image, padded, h, h, h, h, cv::BORDER_CONSTANT, cv::Scalar::all(128));
  cv::Mat3b tile;
  cv::resize(padded(cv::Rect(cvRound(centre.x), cvRound(centre.y), 2 * h, 2 * h)), tile,
             cv::Size(kTile, kTile), 0, 0, cv::INTER_NEAREST);
  return tile;
}

cv::Mat3b bandImage(const cv::Mat3b& image, const cv::Mat3b& background) {
  cv::Mat3f a, b;
  image.convertTo(a, CV_32F);
  background.convertTo(b, CV_32F);
  cv::Mat3b out;
  cv::Mat3f(kBandGain * textureBandPass(a - b) + cv::Scalar::all(128.0)).convertTo(out, CV_8U);
  return out;
}

struct Series {
  std::vector<double> x, y;
  cv::Scalar colour;
  bool points;  // markers, else a line
};

// A plot of `series` in `area`, axes from the data, with a title and axis labels.
void drawPlot(cv::Mat3b& canvas, cv::Rect area, const std::vector<Series>& series,
              const std::string& title, const std::string& x_label, const std::string& y_label) {
  const int left = 46, bottom = 30, top = 20, right = 10;
  const cv::Rect box(area.x + left, area.y + top, area.width - left - right,
                     area.height - top - bottom);
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (const Series& s : series) {
    for (size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, s.x[i]), x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, s.y[i]), y1 = std::max(y1, s.y[i]);
    }
  }
  if (!(x1 > x0)) x0 -= 0.5, x1 += 0.5;
  if (!(y1 > y0)) y0 -= 0.5, y1 += 0.5;
  const double pad = 0.08 * (y1 - y0);
  y0 -= pad, y1 += pad;
  cv::rectangle(canvas, box, cv::Scalar::all(160));
  text(canvas, title, {area.x + 4, area.y + 13});
  text(canvas, x_label, {box.x + box.width / 2 - 40, area.y + area.height - 6});
  text(canvas, format("%.3g", y1), {area.x + 2, box.y + 10}, 0.7);
  text(canvas, format("%.3g", y0), {area.x + 2, box.y + box.height}, 0.7);
  text(canvas, format("%.3g", x0), {box.x, box.y + box.height + 12}, 0.7);
  text(canvas, format("%.3g", x1), {box.x + box.width - 30, box.y + box.height + 12}, 0.7);
  text(canvas, y_label, {area.x + 2, box.y + box.height / 2}, 0.7);
  const auto at = [&](double x, double y) {
    return cv::Point(box.x + cvRound((x - x0) / (x1 - x0) * box.width),
                     box.y + box.height - cvRound((y - y0) / (y1 - y0) * box.height));
  };
  for (const Series& s : series) {
    for (size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.y[i])) continue;
      if (s.points) {
        cv::circle(canvas, at(s.x[i], s.y[i]), 4, s.colour, 2, cv::LINE_AA);
      } else if (i > 0 && std::isfinite(s.y[i - 1])) {
        cv::line(canvas, at(s.x[i - 1], s.y[i - 1]), at(s.x[i], s.y[i]), s.colour, 2,
                 cv::LINE_AA);
      }
    }
  }
}

std::vector<double> meanLogSpectrum(const TextureMatchResult& result, bool real) {
  std::vector<double> mean;
  for (const FrameMatch& frame : result.frames) {
    const std::vector<double>& s = real ? frame.real.spectrum : frame.sim.spectrum;
    mean.resize(s.size(), 0.0);
    for (size_t k = 0; k < s.size(); ++k) mean[k] += s[k] / result.frames.size();
  }
  for (double& v : mean) v = v > 0.0 ? std::log10(v) : NAN;
  return mean;
}

}  // namespace

std::vector<std::string> describeTextureMatch(const TextureMatchResult& r) {
  std::vector<std::string> lines = {
      format("beta %.4g mm (started at %.4g mm); misfit %.1f %% (was %.1f %%), RMS of ln(sim/real)",
             r.beta_mm, r.start_beta_mm, 100.0 * r.misfit, 100.0 * r.start_misfit),
      std::string("conformity ") + (r.conformity ? "on" : "off") + "; " + r.contact_modulus_note,
  };
  for (const FrameMatch& f : r.frames) {
    const std::string name = std::filesystem::path(f.name).filename().string();
    lines.push_back(name + format(": %.2f N", f.force_n) +
                   (f.force_given ? " (given)" : " (gel law)") +
                   format(", press %.3f mm, tilt %.1f deg; band RMS real %.2f sim %.2f, ",
                          f.press_mm, f.tilt_deg, f.real.rms, f.sim.rms) +
                   format("noise %.2f; contact %.0f px", f.real.noise_rms, f.real.contact_pixels));
  }
  for (const std::string& warning : r.warnings) lines.push_back("warning: " + warning);
  return lines;
}

cv::Mat3b makeTextureMatchReport(const TextureMatchResult& result, const cv::Mat3b& background,
                                 int max_frames) {
  const int rows = std::min<int>(max_frames, static_cast<int>(result.frames.size()));
  if (rows <= 0) throw Error("makeTextureMatchReport: no frames to show");
  const std::vector<std::string> lines = describeTextureMatch(result);
  const int header = kLineHeight * (static_cast<int>(lines.size()) + 2);
  const int width = 4 * kTile;
  cv::Mat3b report(header + rows * kTile + kPlotHeight, width, cv::Vec3b(255, 255, 255));
  for (size_t i = 0; i < lines.size(); ++i) {
    text(report, lines[i], {4, kLineHeight * static_cast<int>(i + 1) - 3});
  }
  const char* titles[4] = {"real", "simulated", "real band x4", "simulated band x4"};
  for (int t = 0; t < 4; ++t) text(report, titles[t], {t * kTile + 4, header - 4}, 0.9);
  const double half = kCropHalfQvgaPx * qvgaScale(background.size());
  for (int i = 0; i < rows; ++i) {
    const FrameMatch& f = result.frames[i];
    const cv::Mat3b tiles[4] = {
        cropTile(f.real_image, f.real.contact_centre, half),
        cropTile(f.sim_image, f.sim.contact_centre, half),
        cropTile(bandImage(f.real_image, background), f.real.contact_centre, half),
        cropTile(bandImage(f.sim_image, background), f.sim.contact_centre, half)};
    for (int t = 0; t < 4; ++t) {
      tiles[t].copyTo(report(cv::Rect(t * kTile, header + i * kTile, kTile, kTile)));
    }
  }
  const int plots_y = header + rows * kTile;
  const std::vector<double> frequencies = spectrumBinFrequencies();
  std::vector<double> centres;
  for (double f : frequencies) centres.push_back(f + 0.25 / frequencies.size());
  drawPlot(report, {0, plots_y, kPlotWidth, kPlotHeight},
           {{centres, meanLogSpectrum(result, true), kRealColour, false},
            {centres, meanLogSpectrum(result, false), kSimColour, false}},
           "band spectrum: real (red) sim (blue)", "cycles / pixel", "log10 P");
  const bool forces = result.frames.front().force_given;
  Series real{{}, {}, kRealColour, true}, sim{{}, {}, kSimColour, true};
  for (const FrameMatch& f : result.frames) {
    const double x = forces ? f.force_n : f.real.contact_pixels;
    real.x.push_back(x), real.y.push_back(f.real.rms);
    sim.x.push_back(forces ? f.force_n : f.sim.contact_pixels), sim.y.push_back(f.sim.rms);
  }
  drawPlot(report, {kPlotWidth, plots_y, kPlotWidth, kPlotHeight}, {real, sim},
           "band RMS: real (red) sim (blue)", forces ? "force (N)" : "contact area (px)",
           "grey");
  return report;
}

}  // namespace norm2tex
