#include "norm2tex/texture/normal_map.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/error_messages.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/huge_pages.hpp"
#include "norm2tex/common/image_io.hpp"

namespace norm2tex {
namespace {

std::string lowerCase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

double fullScale(int depth) {
  switch (depth) {
    case CV_8U:
      return 255.0;
    case CV_16U:
      return 65535.0;
    case CV_32F:
      return 1.0;
    default:
      throw Error("normal map has unsupported pixel depth (" + std::to_string(depth) +
                  "); use 8- or 16-bit integer or 32-bit float channels");
  }
}

std::string describeChannels(int channels) {
  if (channels == 1) return "1 channel (grayscale)";
  if (channels == 2) return "2 channels (grayscale + alpha)";
  return std::to_string(channels) + " channels";
}

/// n = normalize(2c - 1) per texel, straight from the image's own pixel type (no float copy of
/// the image: a 2048^2 RGBA map would be 64 MB of temporaries). Alpha, when present and no
/// explicit mask was given, is the validity mask.
template <typename T>
void decodeTexels(const cv::Mat& image, const NormalMapOptions& options, bool alpha_is_mask,
                  cv::Mat3f& normals, cv::Mat1b& valid) {
  const float scale = static_cast<float>(1.0 / fullScale(image.depth()));
  const int channels = image.channels();
  const bool use_alpha = channels == 4 && alpha_is_mask;
  const float alpha_threshold = static_cast<float>(options.alpha_threshold);
  // OpenCV order is B, G, R. OpenGL's +Y points towards row 0, so the image-frame y (towards
  // increasing rows) is -green for OpenGL and +green for DirectX.
  const float y_sign = options.convention == NormalConvention::kOpenGL ? -1.0f : 1.0f;
  const float min_nz = static_cast<float>(options.min_nz);
  for (int r = 0; r < image.rows; ++r) {
    const T* pixel = image.ptr<T>(r);
    cv::Vec3f* n = normals.ptr<cv::Vec3f>(r);
    uchar* ok = valid.ptr<uchar>(r);
    for (int c = 0; c < image.cols; ++c, pixel += channels) {
      if (use_alpha) ok[c] = pixel[3] * scale >= alpha_threshold ? 255 : 0;
      const float x = 2.0f * (pixel[2] * scale) - 1.0f;
      const float y = y_sign * (2.0f * (pixel[1] * scale) - 1.0f);
      const float z = 2.0f * (pixel[0] * scale) - 1.0f;
      const float length = std::sqrt(x * x + y * y + z * z);
      // NaN fails every comparison, so a NaN texel (float TIFF) is masked here too.
      if (!(length > 1e-6f) || !(z / length > min_nz) || !ok[c]) {
        n[c] = cv::Vec3f(0.0f, 0.0f, 0.0f);
        ok[c] = 0;
        continue;
      }
      n[c] = cv::Vec3f(x / length, y / length, z / length);
    }
  }
}
}  // namespace

NormalConvention parseNormalConvention(const std::string& text) {
  const std::string value = lowerCase(text);
  if (value == "opengl" || value == "gl") return NormalConvention::kOpenGL;
  if (value == "directx" || value == "dx") return NormalConvention::kDirectX;
  throw Error("unknown normal map convention '" + text + "'; valid: opengl, directx");
}

std::string toString(NormalConvention convention) {
  return convention == NormalConvention::kOpenGL ? "opengl" : "directx";
}

void validate(const NormalMapOptions& options) {
  detail::requireParameter(options.min_nz >= 0.0 && options.min_nz < 1.0, "min_nz", options.min_nz,
                           "[0, 1)");
  detail::requireParameter(options.alpha_threshold >= 0.0 && options.alpha_threshold <= 1.0,
                           "alpha_threshold", options.alpha_threshold, "[0, 1]");
}

NormalMap::NormalMap(cv::Mat3f normals, cv::Mat1b valid)
    : normals_(std::move(normals)), valid_(std::move(valid)) {}

int NormalMap::validCount() const { return cv::countNonZero(valid_); }

NormalMap NormalMap::load(const std::string& path, const NormalMapOptions& options,
                          const std::string& mask_path) {
  const cv::Mat image = readImage(path, cv::IMREAD_UNCHANGED, "normal map");
  cv::Mat mask;
  if (!mask_path.empty()) mask = readImage(mask_path, cv::IMREAD_UNCHANGED, "mask image");
  try {
    return fromImage(image, options, mask);
  } catch (const Error& e) {
    throw Error("normal map '" + path + "': " + e.what());
  }
}

NormalMap NormalMap::fromImage(const cv::Mat& image, const NormalMapOptions& options,
                               const cv::Mat& mask) {
  validate(options);
  if (image.empty() || image.rows == 0 || image.cols == 0) throw Error("image is empty (0 x 0)");
  if (image.channels() != 3 && image.channels() != 4) {
    throw Error("a normal map needs 3 (RGB) or 4 (RGBA) channels, this image has " +
                describeChannels(image.channels()));
  }
  fullScale(image.depth());  // rejects unsupported depths

  // Maps of several megatexels: huge pages make their first touch ~30x cheaper.
  cv::Mat1b valid;
  createWithHugePages(valid, image.rows, image.cols);
  valid.setTo(255);
  if (!mask.empty()) {
    if (mask.size() != image.size()) {
      throw Error("mask is " + std::to_string(mask.cols) + "x" + std::to_string(mask.rows) +
                  " but the normal map is " + std::to_string(image.cols) + "x" +
                  std::to_string(image.rows));
    }
    cv::Mat gray = mask;
    if (mask.channels() == 3) cv::cvtColor(mask, gray, cv::COLOR_BGR2GRAY);
    if (mask.channels() == 4) cv::cvtColor(mask, gray, cv::COLOR_BGRA2GRAY);
    if (gray.channels() != 1) throw Error("mask must have 1, 3 or 4 channels");
    valid = gray != 0;
  }

  cv::Mat3f normals;
  createWithHugePages(normals, image.rows, image.cols);
  switch (image.depth()) {
    case CV_8U:
      decodeTexels<uchar>(image, options, mask.empty(), normals, valid);
      break;
    case CV_16U:
      decodeTexels<ushort>(image, options, mask.empty(), normals, valid);
      break;
    default:
      decodeTexels<float>(image, options, mask.empty(), normals, valid);
  }
  return NormalMap(std::move(normals), std::move(valid));
}

void normalsToGradients(const cv::Mat3f& normals, const cv::Mat1b& valid, double min_nz,
                        cv::Mat1f& dx, cv::Mat1f& dy) {
  dx.create(normals.size());
  dy.create(normals.size());
  const float threshold = static_cast<float>(min_nz);
  for (int r = 0; r < normals.rows; ++r) {
    const cv::Vec3f* n = normals.ptr<cv::Vec3f>(r);
    const uchar* ok = valid.ptr<uchar>(r);
    float* gx = dx.ptr<float>(r);
    float* gy = dy.ptr<float>(r);
    for (int c = 0; c < normals.cols; ++c) {
      if (ok[c] && n[c][2] > threshold) {
        gx[c] = -n[c][0] / n[c][2];
        gy[c] = -n[c][1] / n[c][2];
      } else {
        gx[c] = 0.0f;
        gy[c] = 0.0f;
      }
    }
  }
}

}  // namespace norm2tex
