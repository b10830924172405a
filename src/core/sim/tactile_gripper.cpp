#include "norm2tex/sim/tactile_gripper.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "norm2tex/common/error.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/render/object_texture.hpp"
#include "norm2tex/sim/contact_shear_load.hpp"
#include "sim/tactile_options.hpp"

namespace norm2tex {
void validate(const TactileGripperOptions& o) {
  detail::validateTactileOptions(o, "tactile gripper option");
}

TactileGripper::TactileGripper(GripperSimConfig scene, const SensorModel& sensor,
                               const TactileGripperOptions& options,
                               std::shared_ptr<ObjectTextureCache> textures)
    : options_(options), textures_(std::move(textures)), variant_(options.variant) {
  validate(options_);
  validate(sensor);
  // As contact_sim and tactile_renderer: the material's friction and beta unless given.
  const detail::TactileSetup setup = detail::resolveTactileOptions(options_, kDefaultTactileFriction);
  scene.object.friction = setup.friction;
  if (setup.material) scene.object.material = setup.material->name;
  setGelFromSensor(sensor, scene);
  ticks_per_frame_ = setup.ticks_per_frame;
  scene.physics.rate_hz = setup.physics_rate_hz;
  sim_ = std::make_unique<GripperSim>(scene);
  mesh_ = std::make_shared<TexturedMesh>(sim_->object().mesh);
  for (auto& renderer : renderers_) renderer = std::make_unique<TactileRenderer>(sensor);

  // Beta 0 renders textureless (nothing to generate).
  beta_mm_ = setup.beta_mm;
  if (beta_mm_ > 0.0) {
    if (!textures_) textures_ = std::make_shared<ObjectTextureCache>(detail::kKeptVariants);
    useVariant(variant_);
  } else {
    for (auto& renderer : renderers_) renderer->setObject(mesh_);
  }
  // contact_sim starts its first episode when it starts.
  reset(options_.seed, std::isnan(options_.height_offset_m)
                           ? std::nullopt
                           : std::optional<double>(options_.height_offset_m));
}

void TactileGripper::useVariant(int variant) {
  const std::shared_ptr<const ObjectTexture> texture = detail::objectTextureVariant(
      *textures_, options_.material_config, options_.material_seed, variant, mesh_);
  for (auto& renderer : renderers_) renderer->setObject(mesh_, texture->atlas, beta_mm_);
  variant_ = variant;
}

void TactileGripper::setVariant(int variant) {
  if (variant < 0)
    throw Error("texture variant " + std::to_string(variant) + " refused; valid: >= 0");
  if (beta_mm_ <= 0.0) {
    if (options_.material_config.empty()) {
      throw Error("texture variant " + std::to_string(variant) +
                  " refused: the gripper has no material");
    }
    variant_ = variant;  // textureless (beta 0): nothing to draw
    return;
  }
  if (variant != variant_) useVariant(variant);
}

void TactileGripper::prefetchVariant(int variant) {
  if (beta_mm_ <= 0.0 || variant < 0) return;
  detail::prefetchObjectTextureVariant(*textures_, options_.material_config, options_.material_seed,
                                       variant, mesh_);
}

EpisodeStart TactileGripper::reset(std::uint64_t seed, std::optional<double> height_offset_m) {
  const EpisodeStart start = sim_->reset(seed, height_offset_m);
  // Pad the settle to whole frames: every frame stays on the physics clock's grid.
  const std::int64_t ticks = sim_->ticks();
  sim_->step(static_cast<int>((ticks_per_frame_ - ticks % ticks_per_frame_) % ticks_per_frame_));
  episode_first_frame_ = frameIndex();
  render(Finger::kLeft);
  render(Finger::kRight);
  return start;
}

void TactileGripper::stepPhysics(int frames) {
  if (frames < 1 || frames > 100000) {
    throw Error("step frames = " + std::to_string(frames) + " refused; valid: [1, 100000]");
  }
  sim_->step(frames * ticks_per_frame_);
}

void TactileGripper::render(Finger finger) {
  const std::int64_t frame =
      options_.noise_per_episode ? frameIndex() - episode_first_frame_ : frameIndex();
  const std::int64_t noise_seed =
      options_.noise_seed < 0 ? -1 : options_.noise_seed * 1000003 + frame;
  // The gel's normal force from the physics: it sets how much of the texture the gel follows
  // (GelConformity) when the sensor's conformity is on.
  TactileRenderer& renderer = *renderers_[index(finger)];
  const GelContactState& contact = sim_->contact(finger);
  std::optional<ShearLoad> shear;
  if (options_.shear || renderer.model().markers.enabled) shear = shearLoadOf(contact, friction());
  frames_[index(finger)] =
      &renderer.render(objectInGel(finger), noise_seed, contact.normal_force_n, shear);
}

Eigen::Isometry3d TactileGripper::objectInGel(Finger finger) const {
  return sim_->gelInWorld(finger).inverse() * sim_->objectInWorld();
}

void TactileGripper::step(int frames) {
  stepPhysics(frames);
  render(Finger::kLeft);
  render(Finger::kRight);
}

}  // namespace norm2tex
