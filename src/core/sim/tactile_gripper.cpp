#include "norm2tex/sim/tactile_gripper.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "norm2tex/common/error.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/render/object_texture.hpp"
#include "sim/tactile_options.hpp"

namespace norm2tex {
namespace {

/// Variants a gripper keeps generated when it has a cache of its own (the paper rotates 24).
constexpr std::size_t kKeptVariants = 32;

}  // namespace

void validate(const TactileGripperOptions& o) {
  detail::validateTactileOptions(o, "tactile gripper option");
}

TactileGripper::TactileGripper(GripperSimConfig scene, const SensorModel& sensor,
                               const TactileGripperOptions& options,
                               std::shared_ptr<ObjectTextureCache> textures)
    : options_(options), textures_(std::move(textures)), variant_(options.variant) {
  validate(options_);
  validate(sensor);
  std::optional<MaterialConfig> material;
  if (!options_.material_config.empty()) material = loadMaterialConfig(options_.material_config);
  // As contact_sim: the material's friction unless one is given.
  scene.object.friction = options_.friction >= 0.0 ? options_.friction
                          : material               ? material->friction
                                                   : kDefaultTactileFriction;
  if (material) scene.object.material = material->name;
  setGelFromSensor(sensor, scene);
  // Whole physics ticks per sensor frame, so every frame is a physics state (as contact_sim).
  ticks_per_frame_ =
      std::max(1, static_cast<int>(std::lround(options_.physics_rate_hz / options_.frame_rate_hz)));
  scene.physics.rate_hz = ticks_per_frame_ * options_.frame_rate_hz;
  sim_ = std::make_unique<GripperSim>(scene);
  mesh_ = std::make_shared<TexturedMesh>(sim_->object().mesh);
  for (auto& renderer : renderers_) renderer = std::make_unique<TactileRenderer>(sensor);

  // As tactile_renderer: the material's beta unless one is given; beta 0 renders textureless
  // (nothing to generate).
  beta_mm_ = material ? (options_.beta_mm >= 0.0 ? options_.beta_mm : material->beta_mm) : 0.0;
  if (beta_mm_ > 0.0) {
    if (!textures_) textures_ = std::make_shared<ObjectTextureCache>(kKeptVariants);
    if (!mesh_->hasUvs()) {
      // A mesh without UVs is unwrapped for its texture: done here on this gripper's own mesh,
      // so that every gripper sharing the cache renders the same (unwrapped) mesh.
      TextureSource source;
      source.material_config = options_.material_config;
      source.variant = variant_;
      source.seed = options_.material_seed;
      auto texture = std::make_shared<ObjectTexture>(loadObjectTexture(source, *mesh_));
      textures_->get(textureKey(variant_), [&] { return *texture; });
    }
    useVariant(variant_);
  } else {
    for (auto& renderer : renderers_) renderer->setObject(mesh_);
  }
  // contact_sim starts its first episode when it starts.
  reset(options_.seed, std::isnan(options_.height_offset_m)
                           ? std::nullopt
                           : std::optional<double>(options_.height_offset_m));
}

std::string TactileGripper::textureKey(int variant) const {
  return options_.material_config + "#" + std::to_string(options_.material_seed) + "/" +
         std::to_string(variant);
}

void TactileGripper::useVariant(int variant) {
  TextureSource source;
  source.material_config = options_.material_config;
  source.variant = variant;
  source.seed = options_.material_seed;
  std::shared_ptr<const TexturedMesh> mesh = mesh_;
  const ObjectTextureCache::Lookup lookup = textures_->get(textureKey(variant), [source, mesh] {
    TexturedMesh copy = *mesh;  // has UVs: left as it is
    return loadObjectTexture(source, copy);
  });
  for (auto& renderer : renderers_) renderer->setObject(mesh_, lookup.texture->atlas, beta_mm_);
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
  TextureSource source;
  source.material_config = options_.material_config;
  source.variant = variant;
  source.seed = options_.material_seed;
  std::shared_ptr<const TexturedMesh> mesh = mesh_;
  textures_->prefetch(textureKey(variant), [source, mesh] {
    TexturedMesh copy = *mesh;
    return loadObjectTexture(source, copy);
  });
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
  frames_[index(finger)] = &renderers_[index(finger)]->render(objectInGel(finger), noise_seed,
                                                              sim_->contact(finger).normal_force_n);
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
