#include "norm2tex/calibrate/image_metrics.hpp"

#include <cmath>
#include <limits>
#include <string>

#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

constexpr int kBorder = (kSsimWindow - 1) / 2;

std::string describe(const cv::Mat& image) {
  return std::to_string(image.cols) + " x " + std::to_string(image.rows) + " with " +
         std::to_string(image.channels()) + " channel(s) of depth " +
         std::to_string(image.depth());
}

void checkPair(const cv::Mat& a, const cv::Mat& b, const char* what) {
  if (a.empty() || b.empty()) throw Error(std::string(what) + ": an image is empty");
  if (a.depth() != CV_8U || b.depth() != CV_8U) {
    throw Error(std::string(what) + ": images must be 8-bit (grey levels 0-255); got " +
                describe(a) + " and " + describe(b));
  }
  if (a.channels() > 4) {
    throw Error(std::string(what) + ": images of 1 to 4 channels only; got " + describe(a));
  }
  if (a.size() != b.size() || a.channels() != b.channels()) {
    throw Error(std::string(what) + ": images differ in size or channels: " + describe(a) +
                " and " + describe(b));
  }
}

// The local mean of `x` (every channel) under the SSIM window. scipy.ndimage.gaussian_filter(
// sigma=1.5, truncate=3.5) uses the 11-tap kernel exp(-x^2 / 2 sigma^2), normalised: the kernel
// OpenCV builds for ksize 11 and sigma 1.5 in double precision.
cv::Mat windowMean(const cv::Mat& x) {
  cv::Mat mean;
  cv::GaussianBlur(x, mean, cv::Size(kSsimWindow, kSsimWindow), kSsimSigma, kSsimSigma,
                   cv::BORDER_REFLECT);
  return mean;
}

double meanSquaredDifference(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat da, db;
  a.convertTo(da, CV_64F);
  b.convertTo(db, CV_64F);
  const double norm = cv::norm(da, db, cv::NORM_L2);
  return norm * norm / static_cast<double>(a.total() * a.channels());
}

}  // namespace

cv::Mat1d structuralSimilarityMap(const cv::Mat& a, const cv::Mat& b) {
  checkPair(a, b, "SSIM");
  if (a.rows < kSsimWindow || a.cols < kSsimWindow) {
    throw Error("SSIM: images of " + describe(a) + " are smaller than the " +
                std::to_string(kSsimWindow) + " x " + std::to_string(kSsimWindow) + " window");
  }
  // All channels filtered at once (five blurs, not five per channel): the calibration compares
  // two frames per press.
  const int channels = a.channels();
  cv::Mat x, y;
  a.convertTo(x, CV_64F);
  b.convertTo(y, CV_64F);
  const cv::Mat ux = windowMean(x), uy = windowMean(y);
  const cv::Mat uxx = windowMean(x.mul(x)), uyy = windowMean(y.mul(y));
  const cv::Mat uxy = windowMean(x.mul(y));
  const double c1 = (kSsimK1 * kSsimRange) * (kSsimK1 * kSsimRange);
  const double c2 = (kSsimK2 * kSsimRange) * (kSsimK2 * kSsimRange);
  cv::Mat1d map(a.size());
  for (int r = 0; r < a.rows; ++r) {
    const double *mx = ux.ptr<double>(r), *my = uy.ptr<double>(r);
    const double *mxx = uxx.ptr<double>(r), *myy = uyy.ptr<double>(r), *mxy = uxy.ptr<double>(r);
    for (int c = 0; c < a.cols; ++c) {
      double sum = 0.0;
      for (int k = c * channels; k < (c + 1) * channels; ++k) {
        // Wang et al. 2004, eq. 13, with population variances, for one channel.
        const double vx = mxx[k] - mx[k] * mx[k], vy = myy[k] - my[k] * my[k];
        const double vxy = mxy[k] - mx[k] * my[k];
        sum += (2.0 * mx[k] * my[k] + c1) * (2.0 * vxy + c2) /
               ((mx[k] * mx[k] + my[k] * my[k] + c1) * (vx + vy + c2));
      }
      map(r, c) = sum / channels;
    }
  }
  return map;
}

double meanSsimOver(const cv::Mat1d& ssim_map, const cv::Mat& mask) {
  if (ssim_map.empty()) throw Error("SSIM: the map is empty");
  if (!mask.empty() && (mask.size() != ssim_map.size() || mask.type() != CV_8UC1)) {
    throw Error("SSIM: the mask is " + describe(mask) + " but must be one 8-bit channel of " +
                std::to_string(ssim_map.cols) + " x " + std::to_string(ssim_map.rows) +
                ", the images' size");
  }
  // scikit-image averages the map without the border whose windows leave the frame.
  double sum = 0.0;
  long count = 0;
  for (int r = kBorder; r < ssim_map.rows - kBorder; ++r) {
    const double* row = ssim_map[r];
    const unsigned char* inside = mask.empty() ? nullptr : mask.ptr<unsigned char>(r);
    for (int c = kBorder; c < ssim_map.cols - kBorder; ++c) {
      if (inside && inside[c] == 0) continue;
      sum += row[c];
      ++count;
    }
  }
  if (count == 0) {
    throw Error("SSIM: the mask has no pixel farther than " + std::to_string(kBorder) +
                " px from the image border");
  }
  return sum / static_cast<double>(count);
}

double structuralSimilarity(const cv::Mat& a, const cv::Mat& b) {
  return meanSsimOver(structuralSimilarityMap(a, b));
}

double peakSignalToNoiseRatio(const cv::Mat& a, const cv::Mat& b) {
  checkPair(a, b, "PSNR");
  const double mse = meanSquaredDifference(a, b);
  if (mse == 0.0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(kSsimRange * kSsimRange / mse);
}

double meanAbsoluteDifference(const cv::Mat& a, const cv::Mat& b) {
  checkPair(a, b, "mean |diff|");
  cv::Mat da, db;
  a.convertTo(da, CV_64F);
  b.convertTo(db, CV_64F);
  return cv::norm(da, db, cv::NORM_L1) / static_cast<double>(a.total() * a.channels());
}

ImageSimilarity compareImages(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  const cv::Mat1d map = structuralSimilarityMap(a, b);
  ImageSimilarity similarity;
  similarity.ssim = meanSsimOver(map);
  similarity.ssim_in_mask = meanSsimOver(map, mask);
  similarity.psnr_db = peakSignalToNoiseRatio(a, b);
  similarity.mean_abs_diff = meanAbsoluteDifference(a, b);
  return similarity;
}

}  // namespace norm2tex
