#pragma once

#include <opencv2/core.hpp>

namespace norm2tex {

/// Share of the height variance over the valid texels that lies at wavelengths longer than
/// `wavelength_texels`, in [0, 1]: the drift that percentile normalisation would spend its
/// range on. Measured with the cosine transform of the map (valid texels minus their mean,
/// invalid texels 0): sum of squared coefficients of frequency below 1 / wavelength over the
/// sum of all but the constant one. 0 for a flat map. Throws Error on mismatched input.
double longWavelengthVarianceFraction(const cv::Mat1f& height, const cv::Mat1b& valid,
                                      double wavelength_texels);

}  // namespace norm2tex
