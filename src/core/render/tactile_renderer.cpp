#include "norm2tex/render/tactile_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

cv::Mat3b backgroundFor(const SensorModel& model) {
  validate(model);
  return model.background_image.empty() ? makeSyntheticBackground(model)
                                        : loadBackground(model.background_image, model.imageSize());
}

}  // namespace

cv::Mat1f TactileFrame::depthMetres() const {
  cv::Mat1f metres;
  gel_mm.convertTo(metres, CV_32F, 1e-3);
  return metres;
}

TactileRenderer::TactileRenderer(const SensorModel& model)
    : TactileRenderer(model, backgroundFor(model),
                      model.background_image.empty() ? BackgroundSource::kSynthetic
                                                     : BackgroundSource::kCaptured) {}

TactileRenderer::TactileRenderer(const SensorModel& model, cv::Mat3b background,
                                 BackgroundSource source)
    : model_(model),
      rasterizer_(model),
      gel_(model),
      shader_(model, std::move(background), source) {
  if (model_.conformity.enabled) conformity_.emplace(model_.conformity, model_.mm_per_pixel);
  if (model_.markers.enabled) shear_ = std::make_unique<ShearField>(model_);
}

std::string TactileRenderer::setObject(std::shared_ptr<const TexturedMesh> mesh,
                                       std::shared_ptr<const HeightAtlas> atlas, double beta_mm) {
  if (!mesh) throw Error("TactileRenderer::setObject: no mesh");
  if (!(beta_mm >= 0.0 && beta_mm <= 10.0)) {
    throw Error("beta = " + std::to_string(beta_mm) + " mm is out of range; valid: [0, 10] mm");
  }
  overlay_.reset();
  mesh_ = std::move(mesh);
  if (!atlas || beta_mm == 0.0) return "";  // textureless: no UV raster, no overlay
  overlay_.emplace(std::move(atlas), beta_mm);
  if (!mesh_->hasUvs()) {
    const std::string name =
        mesh_->sourcePath().empty() ? "the mesh" : "'" + mesh_->sourcePath() + "'";
    return "texture needs UVs but " + name + " has none: rendering H_sensor only";
  }
  return "";
}

const TactileFrame& TactileRenderer::render(const Eigen::Isometry3d& object_in_gel,
                                            std::int64_t noise_seed,
                                            std::optional<double> normal_force_n,
                                            const std::optional<ShearLoad>& shear) {
  if (!mesh_) throw Error("TactileRenderer::render: no object set");
  if (normal_force_n && !(std::isfinite(*normal_force_n) && *normal_force_n >= 0.0)) {
    throw Error("TactileRenderer::render: normal force = " + std::to_string(*normal_force_n) +
                " N is not valid; valid: a finite force >= 0 N");
  }
  const bool textured = overlay_.has_value() && mesh_->hasUvs();
  rasterizer_.rasterize(*mesh_, object_in_gel, textured ? overlay_->reachMm() : 0.0, textured,
                        frame_.raster);
  const cv::Mat1f* h_final = &frame_.raster.h_sensor_mm;
  if (textured) {
    // The overlay writes only the covered box: clear what the previous frame wrote.
    if (!overlay_box_.empty() && h_final_.size() == model_.imageSize()) {
      h_final_(overlay_box_).setTo(0.0f);
      frame_.h_local(overlay_box_).setTo(0.0f);
    }
    overlay_->apply(frame_.raster, model_.gel_thickness_mm, h_final_, &frame_.h_local);
    overlay_box_ = frame_.raster.covered_box;
    h_final = &h_final_;
    frame_.conformity.reset();
    if (conformity_) frame_.conformity = applyConformity(normal_force_n);
  } else {
    frame_.h_local.release();
    h_final_.release();
    overlay_box_ = cv::Rect();
    frame_.conformity.reset();
  }
  frame_.textured = textured;
  cv::compare(*h_final, 0.0f, frame_.contact_mask, cv::CMP_GT);
  gel_.apply(*h_final, frame_.gel_mm);
  frame_.image = shader_.shade(frame_.gel_mm, noise_seed);
  if (shear && !shear_) shear_ = std::make_unique<ShearField>(model_);
  if (shear) {
    if (!frame_.shear) frame_.shear.emplace();
    shear_->compute(frame_.raster.h_sensor_mm, frame_.raster.covered_box,
                    pressForce(normal_force_n), *shear, *frame_.shear);
  } else if (shear_ && shear_->hasMarkers()) {
    if (!frame_.shear) frame_.shear.emplace();
    shear_->rest(*frame_.shear);
  } else {
    frame_.shear.reset();
  }
  if (frame_.shear) shear_->drawMarkers(frame_.image, *frame_.shear);
  return frame_;
}

double TactileRenderer::pressForce(std::optional<double> normal_force_n) const {
  if (normal_force_n) return *normal_force_n;
  const cv::Rect box = frame_.raster.covered_box;
  if (box.empty()) return 0.0;
  double deepest_mm = 0.0;
  cv::minMaxLoc(frame_.raster.h_sensor_mm(box), nullptr, &deepest_mm);
  return gel_law_.force(deepest_mm * 1e-3);
}

ConformityStats TactileRenderer::applyConformity(std::optional<double> normal_force_n) {
  const cv::Rect box = frame_.raster.covered_box;
  const cv::Mat1f& h_sensor = frame_.raster.h_sensor_mm;
  if (box.empty()) return ConformityStats{};
  const double force_n = pressForce(normal_force_n);
  // H_final again, as the overlay computes it, from the followed relief instead of the full one.
  return conformity_->applyToFinal(h_sensor, frame_.h_local, overlay_->betaMm(), box, force_n,
                                   frame_.raster.gap_mm, model_.gel_thickness_mm, h_final_);
}

}  // namespace norm2tex
