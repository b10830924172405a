#pragma once

#include <opencv2/core.hpp>

#include "norm2tex/render/sensor_model.hpp"

namespace norm2tex {

/// A synthetic no-contact frame of `size` with the look `look` (SyntheticBackgroundOptions says
/// the formula). Deterministic (no noise). With the default look, a DIGIT's: reddish upper-left,
/// green on the right, blue-violet lower side, mean BGR near (99, 105, 99); targets vs reached
/// (BGR means, thirds of the image): global (99, 105, 99) -> (98.5, 105.1, 99.0); top-left
/// (117, 106, 133) -> (114.6, 101.7, 132.6); top-right (105, 117, 73) -> (103.4, 116.4, 75.3);
/// bottom-centre (98, 92, 70) -> (97.7, 92.5, 66.6); centre (102, 123, 134) -> (103.6, 120.7,
/// 130.5). Throws Error for a non-positive size or a look that validate() would reject.
cv::Mat3b makeSyntheticBackground(const SyntheticBackgroundOptions& look, cv::Size size);

/// The model's own synthetic frame: its synthetic_background at its image size.
cv::Mat3b makeSyntheticBackground(const SensorModel& model);

/// Throws Error naming the first field of `look` out of range (as "synthetic_background.KEY").
void validate(const SyntheticBackgroundOptions& look);

}  // namespace norm2tex
