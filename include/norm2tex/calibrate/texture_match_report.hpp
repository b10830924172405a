#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/calibrate/texture_match.hpp"

namespace norm2tex {

/// The fit as lines of text: beta before and after, the misfit, E*, and per frame its force,
/// press and real / simulated band RMS (for the report image and the tool's output).
std::vector<std::string> describeTextureMatch(const TextureMatchResult& result);

/// A picture of a texture match: the text of describeTextureMatch; for up to `max_frames`
/// frames one row of crops around the contact, real | simulated | real band | simulated band
/// (the band x4 around grey 128); then two plots: the band's radially averaged power spectrum
/// (mean over the frames, log scale) real vs simulated, and band RMS against force (against
/// contact area when no forces were given) real vs simulated.
cv::Mat3b makeTextureMatchReport(const TextureMatchResult& result, const cv::Mat3b& background,
                                 int max_frames = 4);

}  // namespace norm2tex
