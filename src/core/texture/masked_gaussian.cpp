#include "norm2tex/texture/masked_gaussian.hpp"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "norm2tex/common/error.hpp"

namespace norm2tex {

cv::Mat3f maskedGaussianNormals(const cv::Mat3f& normals, const cv::Mat1b& mask, double sigma) {
  if (normals.size() != mask.size()) throw Error("maskedGaussianNormals: size mismatch");
  cv::Mat3f result(normals.size(), cv::Vec3f(0.0f, 0.0f, 0.0f));
  if (sigma <= 0.0) {
    normals.copyTo(result, mask);
    return result;
  }
  cv::Mat1f weight;
  mask.convertTo(weight, CV_32F, 1.0 / 255.0);
  cv::threshold(weight, weight, 0.0, 1.0, cv::THRESH_BINARY);
  cv::Mat3f weighted(normals.size());
  cv::Mat weight3;
  cv::merge(std::vector<cv::Mat>{weight, weight, weight}, weight3);
  cv::multiply(normals, weight3, weighted);

  const int radius = static_cast<int>(std::ceil(3.0 * sigma));
  const cv::Size kernel(2 * radius + 1, 2 * radius + 1);
  // Zero padding: texels beyond the patch are "not in the island", exactly like masked ones.
  // blur(n * m) / blur(m) differs from blur(n * m) by a positive scale per texel, which the
  // renormalisation below removes, so blur(m) is never computed.
  cv::Mat3f blurred;
  cv::GaussianBlur(weighted, blurred, kernel, sigma, sigma, cv::BORDER_CONSTANT);

  for (int r = 0; r < normals.rows; ++r) {
    const uchar* ok = mask.ptr<uchar>(r);
    const cv::Vec3f* sum = blurred.ptr<cv::Vec3f>(r);
    const cv::Vec3f* original = normals.ptr<cv::Vec3f>(r);
    cv::Vec3f* out = result.ptr<cv::Vec3f>(r);
    for (int c = 0; c < normals.cols; ++c) {
      if (!ok[c]) continue;
      const float length = static_cast<float>(cv::norm(sum[c]));
      out[c] = length > 1e-12f ? sum[c] / length : original[c];
    }
  }
  return result;
}

}  // namespace norm2tex
