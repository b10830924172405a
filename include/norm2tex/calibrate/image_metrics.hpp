#pragma once

#include <opencv2/core.hpp>

namespace norm2tex {

/// How alike two 8-bit frames are, by the measures tactile simulators report against real
/// frames (SSIM, PSNR) and the plain mean absolute difference.
struct ImageSimilarity {
  double ssim = 0.0;           ///< mean of the SSIM map over the frame (border excluded, below)
  double ssim_in_mask = 0.0;   ///< mean of the SSIM map over the mask's pixels (same border)
  double psnr_db = 0.0;        ///< 10 log10(255^2 / MSE); +infinity for identical frames
  double mean_abs_diff = 0.0;  ///< mean |a - b| over pixels and channels, grey levels
};

/// SSIM's window and constants (Wang, Bovik, Sheikh, Simoncelli 2004): a Gaussian window of
/// sigma 1.5 truncated at 3.5 sigma (11 x 11), K1 = 0.01, K2 = 0.03, dynamic range L = 255.
constexpr double kSsimSigma = 1.5;
constexpr int kSsimWindow = 11;
constexpr double kSsimK1 = 0.01, kSsimK2 = 0.03, kSsimRange = 255.0;

/// The SSIM map of two 8-bit frames of the same size and channel count (1-4 channels), one value
/// per pixel (CV_64FC1): SSIM computed per channel and averaged over the channels. Matches
/// scikit-image's structural_similarity(a, b, channel_axis=2, gaussian_weights=True, sigma=1.5,
/// use_sample_covariance=False, data_range=255), whose colour result is the per-channel mean:
/// local means and (population) variances by a Gaussian filter, borders reflected (scipy's
/// 'reflect' = OpenCV's BORDER_REFLECT). Throws Error for empty frames, frames of different
/// size or type, frames that are not 8-bit, or frames smaller than the window.
cv::Mat1d structuralSimilarityMap(const cv::Mat& a, const cv::Mat& b);

/// Mean of `ssim_map` over the pixels where `mask` is non-zero, leaving out the border of
/// (kSsimWindow - 1) / 2 pixels whose windows leave the frame, as scikit-image's mean SSIM does
/// (so an all-ones mask gives the frame's SSIM). An empty `mask` means every pixel. Throws Error
/// for a mask of another size or type than CV_8UC1, or one with no pixel inside that border.
double meanSsimOver(const cv::Mat1d& ssim_map, const cv::Mat& mask = cv::Mat());

/// SSIM of the whole frame (the mean of structuralSimilarityMap off the border).
double structuralSimilarity(const cv::Mat& a, const cv::Mat& b);

/// PSNR in dB for a peak of 255 over all pixels and channels; +infinity when a == b. Same input
/// checks as structuralSimilarityMap (except the window size).
double peakSignalToNoiseRatio(const cv::Mat& a, const cv::Mat& b);

/// Mean |a - b| over all pixels and channels, grey levels. Same input checks as PSNR.
double meanAbsoluteDifference(const cv::Mat& a, const cv::Mat& b);

/// All four measures at once (the SSIM map computed once); `mask` (CV_8UC1, non-zero = inside,
/// empty = everything) selects the pixels of ssim_in_mask.
ImageSimilarity compareImages(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask = cv::Mat());

}  // namespace norm2tex
