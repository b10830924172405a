#include "norm2tex/calibrate/texture_band.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <opencv2/imgproc.hpp>

#include "norm2tex/calibrate/qvga_scale.hpp"
#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

constexpr int kTileQvgaPx = 16;
constexpr double kQuietTileShare = 0.04;
constexpr double kMinContactStep = 4.0;  // grey levels of |B| + |G| + |R|, blurred
constexpr int kMinContactQvgaPx = 200;
constexpr int kMinMeasuredQvgaPx = 300;
constexpr int kMinNoiseQvgaPx = 1500;

double scaleOf(const cv::Mat& image) { return qvgaScale(image.size()); }

cv::Mat1f blurred(const cv::Mat1f& image, double sigma) {
  cv::Mat1f out;
  cv::GaussianBlur(image, out, cv::Size(), sigma, sigma, cv::BORDER_REFLECT);
  return out;
}

cv::Mat1f magnitude(const cv::Mat3f& diff) {
  cv::Mat1f m(diff.size());
  for (int r = 0; r < diff.rows; ++r) {
    const cv::Vec3f* d = diff.ptr<cv::Vec3f>(r);
    float* out = m.ptr<float>(r);
    for (int c = 0; c < diff.cols; ++c)
      out[c] = std::abs(d[c][0]) + std::abs(d[c][1]) + std::abs(d[c][2]);
  }
  return m;
}

// The level and spread of m where nothing touches: the quietest 4 % of the tiles (at least 4). A
// contact covers most of some tiles and none of others; unlike the frame's median this holds
// until the contact covers about 95 % of the image.
cv::Vec2d quietLevel(const cv::Mat1f& m) {
  const int tile = std::max(4, cvRound(kTileQvgaPx * scaleOf(m)));
  std::vector<std::pair<double, cv::Rect>> tiles;
  for (int r = 0; r + tile <= m.rows; r += tile) {
    for (int c = 0; c + tile <= m.cols; c += tile) {
      const cv::Rect rect(c, r, tile, tile);
      tiles.emplace_back(cv::mean(m(rect))[0], rect);
    }
  }
  std::sort(tiles.begin(), tiles.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  const size_t quiet = std::max<size_t>(4, static_cast<size_t>(kQuietTileShare * tiles.size()));
  double sum = 0.0, sum2 = 0.0, count = 0.0;
  for (size_t i = 0; i < std::min(quiet, tiles.size()); ++i) {
    const cv::Mat1f block = m(tiles[i].second);
    for (float v : block) sum += v, sum2 += double(v) * v, ++count;
  }
  const double mean = sum / count;
  return {mean, std::sqrt(std::max(0.0, sum2 / count - mean * mean))};
}

// The largest connected region of `above`, its holes filled (a groove of the texture or the flat
// middle of a press barely changes the colour).
cv::Mat1b largestRegion(const cv::Mat1b& above) {
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(above.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  cv::Mat1b region(above.size(), 0);
  if (contours.empty()) return region;
  const auto largest = std::max_element(
      contours.begin(), contours.end(),
      [](const auto& a, const auto& b) { return cv::contourArea(a) < cv::contourArea(b); });
  cv::drawContours(region, contours, static_cast<int>(largest - contours.begin()), 255,
                   cv::FILLED);
  return region;
}

cv::Mat1b insideBorder(cv::Size size, int border) {
  cv::Mat1b mask(size, 0);
  const cv::Rect inner(border, border, size.width - 2 * border, size.height - 2 * border);
  if (inner.width > 0 && inner.height > 0) mask(inner).setTo(255);
  return mask;
}

cv::Mat1b eroded(const cv::Mat1b& mask, double radius_px) {
  const int r = std::max(1, cvRound(radius_px));
  cv::Mat1b out;
  cv::erode(mask, out, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * r + 1, 2 * r + 1}));
  return out;
}

double bandRms(const cv::Mat3f& band, const cv::Mat1b& mask) {
  double sum = 0.0;
  int count = 0;
  for (int r = 0; r < band.rows; ++r) {
    const cv::Vec3f* b = band.ptr<cv::Vec3f>(r);
    const uchar* m = mask.ptr<uchar>(r);
    for (int c = 0; c < band.cols; ++c) {
      if (!m[c]) continue;
      sum += b[c].dot(b[c]);
      ++count;
    }
  }
  return count > 0 ? std::sqrt(sum / count) : 0.0;
}

// Radially averaged power of the band over `mask`'s bounding box, zero outside the mask, per
// pixel of the mask. The mask's hard edge leaks some power across bins; real and simulated
// frames are treated alike, so the comparison is fair.
std::vector<double> radialSpectrum(const cv::Mat3f& band, const cv::Mat1b& mask, int bins) {
  std::vector<double> power(bins, 0.0), counts(bins, 0.0);
  const cv::Rect box = cv::boundingRect(mask);
  const int pixels = cv::countNonZero(mask);
  if (box.area() == 0 || pixels == 0) return power;
  const int h = cv::getOptimalDFTSize(box.height), w = cv::getOptimalDFTSize(box.width);
  std::vector<cv::Mat1f> channels;
  cv::split(band(box), channels);
  cv::Mat1f total(h, w, 0.0f);
  for (cv::Mat1f& channel : channels) {
    cv::Mat1f padded(h, w, 0.0f);
    channel.copyTo(padded(cv::Rect(0, 0, box.width, box.height)), mask(box));
    cv::Mat spectrum;
    cv::dft(padded, spectrum, cv::DFT_COMPLEX_OUTPUT);
    std::vector<cv::Mat1f> parts;
    cv::split(spectrum, parts);
    total += parts[0].mul(parts[0]) + parts[1].mul(parts[1]);
  }
  for (int r = 0; r < h; ++r) {
    const double fy = (r <= h / 2 ? r : r - h) / static_cast<double>(h);
    for (int c = 0; c < w; ++c) {
      const double fx = (c <= w / 2 ? c : c - w) / static_cast<double>(w);
      const int bin = static_cast<int>(std::hypot(fx, fy) / 0.5 * bins);
      if (bin >= bins) continue;
      power[bin] += total(r, c);
      counts[bin] += 1.0;
    }
  }
  // Parseval: sum |F|^2 = N sum x^2 over the padded box; per mask pixel and per frequency sample.
  for (int k = 0; k < bins; ++k) {
    if (counts[k] > 0) power[k] /= counts[k] * pixels;
  }
  return power;
}

}  // namespace

cv::Mat3f textureBandPass(const cv::Mat3f& diff, const TextureBandOptions& options) {
  const double scale = scaleOf(diff);
  cv::Mat3f fine, coarse;
  cv::GaussianBlur(diff, fine, cv::Size(), options.fine_sigma_px * scale,
                   options.fine_sigma_px * scale, cv::BORDER_REFLECT);
  cv::GaussianBlur(diff, coarse, cv::Size(), options.coarse_sigma_px * scale,
                   options.coarse_sigma_px * scale, cv::BORDER_REFLECT);
  return fine - coarse;
}

NoContactLevel measureNoContactLevel(const cv::Mat3f& diff, const TextureBandOptions& options) {
  const double scale = scaleOf(diff);
  const cv::Mat1b inner = insideBorder(diff.size(), cvRound(options.border_px * scale));
  cv::Scalar mean, deviation;
  cv::meanStdDev(blurred(magnitude(diff), options.detection_sigma_px * scale), mean, deviation,
                 inner);
  return {bandRms(textureBandPass(diff, options), inner), mean[0], deviation[0]};
}

std::vector<double> spectrumBinFrequencies(const TextureBandOptions& options) {
  std::vector<double> f;
  for (int k = 0; k < options.spectrum_bins; ++k) f.push_back(0.5 * k / options.spectrum_bins);
  return f;
}

TextureBand measureTextureBand(const cv::Mat3f& diff, const NoContactLevel& no_contact,
                               const std::string& frame_name, const TextureBandOptions& options) {
  if (diff.empty()) throw Error("frame '" + frame_name + "': empty image");
  const double scale = scaleOf(diff), area_scale = scale * scale;
  const cv::Mat1f m = blurred(magnitude(diff), options.detection_sigma_px * scale);
  const cv::Vec2d quiet = quietLevel(m);
  const double step = std::max(options.threshold_sigmas * quiet[1], kMinContactStep);
  double peak = 0.0;
  cv::minMaxLoc(m, nullptr, &peak);
  if (peak < quiet[0] + step && !(no_contact.magnitude > 0.0 &&
                                   quiet[0] > 2.0 * no_contact.magnitude + kMinContactStep)) {
    throw Error("frame '" + frame_name + "': no contact found (the largest change from the " +
                "background, " + std::to_string(cvRound(peak - quiet[0])) +
                " grey levels summed over B, G, R, is within the noise, threshold " +
                std::to_string(cvRound(step)) + "); is it a no-contact frame?");
  }
  TextureBand out;
  const cv::Mat1b inner = insideBorder(diff.size(), cvRound(options.border_px * scale));
  // A face pressed flat onto the whole gel leaves no quiet tile: all of them then stand out of
  // the sensor's own no-contact level.
  const bool everywhere =
      no_contact.magnitude > 0.0 &&
      quiet[0] > std::max(2.0 * no_contact.magnitude,
                          no_contact.magnitude + std::max(options.threshold_sigmas *
                                                              no_contact.spread,
                                                          kMinContactStep));
  out.contact = everywhere ? cv::Mat1b(diff.size(), 255) : largestRegion(m > quiet[0] + step);
  out.contact_pixels = cv::countNonZero(out.contact);
  out.contact_fraction = out.contact_pixels / static_cast<double>(diff.total());
  if (out.contact_pixels < kMinContactQvgaPx * area_scale) {
    throw Error("frame '" + frame_name + "': no contact found (the largest region that differs " +
                "from the background has " + std::to_string(out.contact_pixels) +
                " pixels; need >= " + std::to_string(cvRound(kMinContactQvgaPx * area_scale)) +
                ")");
  }
  out.measured = eroded(out.contact, options.rim_erosion_px * scale) & inner;
  out.measured_pixels = cv::countNonZero(out.measured);
  if (out.measured_pixels < kMinMeasuredQvgaPx * area_scale) {
    throw Error("frame '" + frame_name + "': the contact (" +
                std::to_string(out.contact_pixels) + " pixels) leaves only " +
                std::to_string(out.measured_pixels) + " pixels away from its rim; need >= " +
                std::to_string(cvRound(kMinMeasuredQvgaPx * area_scale)) +
                " (press a larger part of the sample onto the gel)");
  }
  const cv::Moments moments = cv::moments(out.measured, true);
  out.contact_centre = {moments.m10 / moments.m00, moments.m01 / moments.m00};

  const cv::Mat3f band = textureBandPass(diff, options);
  out.raw_rms = bandRms(band, out.measured);
  cv::Mat1b free_of_contact;
  cv::bitwise_not(out.contact, free_of_contact);
  free_of_contact = eroded(free_of_contact, options.noise_clearance_px * scale) & inner;
  out.noise_from_frame = cv::countNonZero(free_of_contact) >= kMinNoiseQvgaPx * area_scale;
  out.noise_rms = out.noise_from_frame ? bandRms(band, free_of_contact) : no_contact.band_rms;
  out.rms = std::sqrt(std::max(0.0, out.raw_rms * out.raw_rms - out.noise_rms * out.noise_rms));
  out.spectrum = radialSpectrum(band, out.measured, options.spectrum_bins);
  return out;
}

}  // namespace norm2tex
