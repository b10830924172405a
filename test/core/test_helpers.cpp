#include "test_helpers.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "norm2tex/texture/normal_encoding.hpp"

namespace norm2tex {
namespace test {

double correlation(const cv::Mat1f& a, const cv::Mat1f& b, const cv::Mat1b& mask) {
  double n = 0, sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  for (int r = 0; r < a.rows; ++r) {
    for (int c = 0; c < a.cols; ++c) {
      if (!mask(r, c)) continue;
      const double x = a(r, c), y = b(r, c);
      n += 1;
      sa += x;
      sb += y;
      saa += x * x;
      sbb += y * y;
      sab += x * y;
    }
  }
  const double cov = sab - sa * sb / n;
  const double va = saa - sa * sa / n, vb = sbb - sb * sb / n;
  return cov / std::sqrt(va * vb);
}

cv::Mat1f withoutMeanSlope(const AnalyticSurface& surface, const cv::Mat1b& mask) {
  const double mx = cv::mean(surface.dx, mask)[0], my = cv::mean(surface.dy, mask)[0];
  cv::Mat1f result(surface.height.size());
  for (int r = 0; r < result.rows; ++r) {
    for (int c = 0; c < result.cols; ++c) {
      result(r, c) = static_cast<float>(surface.height(r, c) - mx * c - my * r);
    }
  }
  return result;
}

double maskedStdDev(const cv::Mat1f& a, const cv::Mat1b& mask) {
  cv::Scalar mean, stddev;
  cv::meanStdDev(a, mean, stddev, mask);
  return stddev[0];
}

NormalMap quantisedNormalMap(const AnalyticSurface& surface, const cv::Mat1b& mask, int depth,
                             NormalConvention convention) {
  const cv::Mat image = encodeNormalMap(surface.dx, surface.dy, convention, depth, mask);
  NormalMapOptions options;
  options.convention = convention;
  return NormalMap::fromImage(image, options, mask);
}

TexturedMesh makeHelicoidRamp() {
  const double pi = 3.14159265358979323846;
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
  const int steps = 90;
  for (int i = 0; i <= steps; ++i) {
    const double a = 3.0 * pi * i / steps, z = 0.001 * i / steps;
    for (double radius : {0.005, 0.01}) {
      vertices.emplace_back(radius * std::cos(a), radius * std::sin(a), z);
    }
  }
  for (int i = 0; i < steps; ++i) {
    const int a = 2 * i, b = a + 1, c = a + 2, d = a + 3;
    triangles.emplace_back(a, b, d);
    triangles.emplace_back(a, d, c);
  }
  return TexturedMesh(vertices, triangles);
}

ScratchDirectory::ScratchDirectory() {
  std::string pattern = (std::filesystem::temp_directory_path() / "norm2tex_test_XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
  root_ = pattern;
}

ScratchDirectory::~ScratchDirectory() {
  std::error_code ec;
  std::filesystem::permissions(root_, std::filesystem::perms::owner_all, ec);
  std::filesystem::remove_all(root_, ec);
}

std::string ScratchDirectory::path(const std::string& name) const {
  return (std::filesystem::path(root_) / name).string();
}

}  // namespace test
}  // namespace norm2tex
