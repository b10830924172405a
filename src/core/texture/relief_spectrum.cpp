#include "norm2tex/texture/relief_spectrum.hpp"

#include <cmath>

#include "norm2tex/common/error.hpp"
#include "texture/cosine_transform.hpp"

namespace norm2tex {

double longWavelengthVarianceFraction(const cv::Mat1f& height, const cv::Mat1b& valid,
                                      double wavelength_texels) {
  if (height.empty() || height.size() != valid.size()) {
    throw Error("longWavelengthVarianceFraction: height and mask must be non-empty, one size");
  }
  if (!(wavelength_texels > 0.0)) throw Error("longWavelengthVarianceFraction: wavelength <= 0");
  const int rows = detail::CosineTransform::transformLength(height.rows);
  const int cols = detail::CosineTransform::transformLength(height.cols);
  cv::Mat1f values(rows, cols, 0.0f);
  const float mean = static_cast<float>(cv::mean(height, valid)[0]);
  cv::subtract(height, mean, values(cv::Rect(0, 0, height.cols, height.rows)), valid);
  detail::CosineTransform transform;
  const cv::Mat1f& spectrum = transform.forward(values);  // transposed: row u, column v
  // Cosine index k of an axis of length n is the frequency k / (2 n) cycles per texel.
  const double cutoff = 1.0 / wavelength_texels;
  double long_energy = 0.0, total = 0.0;
  for (int u = 0; u < spectrum.rows; ++u) {
    const float* row = spectrum.ptr<float>(u);
    const double fu = u / (2.0 * cols);
    for (int v = 0; v < spectrum.cols; ++v) {
      if (u == 0 && v == 0) continue;
      const double fv = v / (2.0 * rows);
      // The unnormalised DCT weighs the first coefficient of each axis double: undo it.
      const double weight = (u == 0 ? 0.5 : 1.0) * (v == 0 ? 0.5 : 1.0);
      const double energy = weight * static_cast<double>(row[v]) * row[v];
      total += energy;
      if (fu * fu + fv * fv < cutoff * cutoff) long_energy += energy;
    }
  }
  return total > 0.0 ? long_energy / total : 0.0;
}

}  // namespace norm2tex
