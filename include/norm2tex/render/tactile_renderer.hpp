#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "norm2tex/render/contact_rasterizer.hpp"
#include "norm2tex/render/digit_shader.hpp"
#include "norm2tex/render/gel_conformity.hpp"
#include "norm2tex/render/gel_model.hpp"
#include "norm2tex/texture/height_atlas.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/render/texture_overlay.hpp"
#include "norm2tex/mesh/textured_mesh.hpp"
#include "norm2tex/gel/gel_law.hpp"
#include "norm2tex/shear/shear_field.hpp"

namespace norm2tex {

/// One rendered DIGIT frame and the fields behind it.
struct TactileFrame {
  cv::Mat3b image;         ///< bgr8, what the DIGIT publishes
  cv::Mat1f gel_mm;        ///< the gel's deformation after GelModel (indentation, mm)
  cv::Mat1b contact_mask;  ///< 255 where the object touches the gel (H_final > 0)
  ContactRaster raster;    ///< H_sensor, UVs, faces
  cv::Mat1f h_local;       ///< H_local where textured, else empty
  bool textured = false;   ///< whether the overlay ran
  /// What the conformity model computed (set when it ran: conformity on and textured).
  std::optional<ConformityStats> conformity;
  /// The gel's lateral motion (set when render() was given a shear load, or the sensor has
  /// markers: then at rest without a load).
  std::optional<ShearFrame> shear;

  /// gel_mm in metres (32FC1), as published on the depth topic.
  cv::Mat1f depthMetres() const;
};

/// The whole pipeline for one sensor: pose -> ContactRasterizer (H_sensor) -> TextureOverlay
/// (H_final = H_sensor + beta H_local) -> GelModel -> DigitShader. Holds its buffers; not
/// thread-safe (use one per thread or sensor).
class TactileRenderer {
 public:
  /// Background: the model's background_image if set (captured), else the synthetic one.
  explicit TactileRenderer(const SensorModel& model);
  TactileRenderer(const SensorModel& model, cv::Mat3b background, BackgroundSource source);

  /// The object to render. `atlas` may be null or `beta_mm` 0: textureless. Returns a warning
  /// (empty if none), e.g. when texture was asked for but the mesh has no UVs.
  std::string setObject(std::shared_ptr<const TexturedMesh> mesh,
                        std::shared_ptr<const HeightAtlas> atlas = nullptr, double beta_mm = 0.0);

  /// Renders the object at `object_in_gel` (metres, gel frame). `noise_seed` < 0: no noise.
  /// `normal_force_n`: the contact's normal force (N), which sets how much of the texture the
  /// gel follows when the model's conformity is on; without it, the gel law's force for the
  /// deepest indentation. `shear`: the contact's tangential load, which moves the gel's surface
  /// sideways (ShearField: frame.shear) and carries the markers; without it the surface stays
  /// in place. Throws Error for a non-finite pose, a negative or non-finite force or load, or
  /// when no object was set.
  const TactileFrame& render(const Eigen::Isometry3d& object_in_gel, std::int64_t noise_seed,
                             std::optional<double> normal_force_n = std::nullopt,
                             const std::optional<ShearLoad>& shear = std::nullopt);

  /// The force-indentation law that gives the force of a press when render() is given none
  /// (default: GelLaw::taximDefault(), the scenes' default law).
  void setGelLaw(GelLaw law) { gel_law_ = std::move(law); }
  const GelLaw& gelLaw() const { return gel_law_; }

  const SensorModel& model() const { return model_; }
  const DigitShader& shader() const { return shader_; }

 private:
  // GelConformity on the overlay's relief; rewrites h_final_ over the covered box.
  ConformityStats applyConformity(std::optional<double> normal_force_n);
  // The force of this press: the given one, else the gel law's for the deepest H_sensor.
  double pressForce(std::optional<double> normal_force_n) const;

  SensorModel model_;
  ContactRasterizer rasterizer_;
  GelModel gel_;
  DigitShader shader_;
  std::shared_ptr<const TexturedMesh> mesh_;
  std::optional<TextureOverlay> overlay_;
  std::optional<GelConformity> conformity_;  // set when model.conformity.enabled
  std::unique_ptr<ShearField> shear_;          // made on the first load, or at once with markers
  GelLaw gel_law_ = GelLaw::taximDefault();
  TactileFrame frame_;
  cv::Mat1f h_final_;
  cv::Rect overlay_box_;  // what the overlay wrote last frame
};

}  // namespace norm2tex
