#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/shear/contact_traction.hpp"
#include "norm2tex/shear/shear_field.hpp"

namespace norm2tex {
namespace cli {

/// Draws what a ShearFrame holds onto a rendered frame, for the docs' figures: each marker's
/// motion as an arrow from its rest position, `gain` times its length (1: true scale), and the
/// outline of the contact's stick region (green) and of the contact (white).
void drawShearAnnotations(cv::Mat3b& image, const ShearFrame& shear, double gain);

/// Parses "FX,FY[,T]" (N, N, N m) into a ShearLoad; throws UsageError naming `option`.
ShearLoad parseShearLoad(const std::string& text, const std::string& option);

/// Splits "A;B;C" into its parts.
std::vector<std::string> splitLoads(const std::string& text);

}  // namespace cli
}  // namespace norm2tex
