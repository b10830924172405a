#pragma once

#include <opencv2/core.hpp>

#include "norm2tex/render/sensor_model.hpp"

namespace norm2tex {

/// The elastomer's response to an indentation field. The gel conforms to the object where it
/// touches (the core) but cannot follow a sharp step at the contact's rim: around the contact it
/// is dragged along in a smooth skirt.
///
/// Model (Taxim-style, made cheap): the core is every pixel indented more than
/// core_fraction x the maximum indentation (0 = the whole contact, which keeps the texture
/// everywhere the object touches; Taxim uses 0.4). A pyramid of Gaussian blurs
/// (pyramid_sigmas_mm, coarse to fine; Taxim's kernels give 1.0, 0.5, 0.25, 0.1 mm) spreads the
/// indentation outwards, the core being restored after each level. A level runs at a quarter or
/// half of the image resolution when its sigma still spans 1.5 pixels there (at 0.054 mm/px:
/// 0.5 mm at a quarter, 0.25 mm at half, 0.1 mm at full resolution), and its skirt is upsampled
/// bilinearly for the next, finer level; every blur covers only the deformation's neighbourhood.
/// Against the same pyramid run entirely at full resolution this differs by under 5 % of the
/// maximum indentation (tested; 0.4-4.1 % reached, the former quarter-resolution-only version
/// 0.3-3.7 %), at about 0.7 of that version's cost on a full-gel contact. A last blur of final_sigma_mm stands for
/// the gel's bending stiffness, then the result is clamped to [0, gel thickness] and deformations
/// under 0.1 um are set to exactly 0 (so the gel away from the contact is exactly flat).
class GelModel {
 public:
  explicit GelModel(const SensorModel& model);

  /// `indentation_mm` CV_32FC1 of image size (>= 0); writes the gel's deformation (mm).
  void apply(const cv::Mat1f& indentation_mm, cv::Mat1f& out) const;

 private:
  SensorModel model_;
};

}  // namespace norm2tex
