#include "norm2tex/sim/tactile_hand.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <thread>

#include "norm2tex/common/error.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/render/object_texture.hpp"
#include "norm2tex/sim/contact_shear_load.hpp"
#include "norm2tex/sim/tactile_gripper.hpp"
#include "sim/tactile_options.hpp"

namespace norm2tex {
void validate(const TactileHandOptions& o) {
  detail::validateTactileOptions(o, "tactile hand option");
  if (o.render_threads < 0 || o.render_threads > 256) {
    throw Error("tactile hand option render_threads = " + std::to_string(o.render_threads) +
                " is out of range; valid: [0, 256] (0: one per core)");
  }
}

TactileHand::TactileHand(HandSimConfig config, const SensorModel& sensor,
                         const TactileHandOptions& options,
                         std::shared_ptr<ObjectTextureCache> textures)
    : options_(options), textures_(std::move(textures)), variant_(options.variant) {
  validate(options_);
  validate(sensor);
  // As TactileGripper: the material's friction and beta unless given.
  const detail::TactileSetup setup =
      detail::resolveTactileOptions(options_, kDefaultTactileFriction);
  config.object.friction = setup.friction;
  if (setup.material) config.object.material = setup.material->name;
  config.gel_width_m = sensor.gel_pad_width_mm * 1e-3;
  config.gel_height_m = sensor.gel_pad_height_mm * 1e-3;
  config.gel_thickness_m = sensor.gel_thickness_mm * 1e-3;
  ticks_per_frame_ = setup.ticks_per_frame;
  config.physics.rate_hz = setup.physics_rate_hz;
  sim_ = std::make_unique<HandSim>(config);
  mesh_ = std::make_shared<TexturedMesh>(sim_->object().mesh);
  for (int s = 0; s < sim_->sensorCount(); ++s) {
    // A sensor's own model (the hand yaml's `sensor`) wins, as in hand_sim.launch.
    const std::string& own = sim_->sensor(s).sensor_yaml;
    renderers_.push_back(own.empty() ? std::make_unique<TactileRenderer>(sensor)
                                     : std::make_unique<TactileRenderer>(loadSensorModel(own)));
  }
  frames_.assign(renderers_.size(), nullptr);
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const int threads =
      std::min(sensorCount(), options_.render_threads == 0 ? cores : options_.render_threads);
  if (threads > 1) render_pool_ = std::make_unique<ParallelFor>(threads);

  beta_mm_ = setup.beta_mm;
  if (beta_mm_ > 0.0) {
    if (!textures_) textures_ = std::make_shared<ObjectTextureCache>(detail::kKeptVariants);
    const std::shared_ptr<const ObjectTexture> texture = detail::objectTextureVariant(
        *textures_, options_.material_config, options_.material_seed, variant_, mesh_);
    for (auto& renderer : renderers_) renderer->setObject(mesh_, texture->atlas, beta_mm_);
  } else {
    for (auto& renderer : renderers_) renderer->setObject(mesh_);
  }
  reset();
}

int TactileHand::sensorIndex(const std::string& name) const {
  std::string names;
  for (int s = 0; s < sensorCount(); ++s) {
    if (sim_->sensor(s).name == name) return s;
    names += (names.empty() ? "" : ", ") + sim_->sensor(s).name;
  }
  throw Error("sensor '" + name + "' is not in the hand; its sensors: " + names);
}

void TactileHand::checkSensor(int sensor) const {
  if (sensor < 0 || sensor >= sensorCount()) {
    throw Error("sensor index " + std::to_string(sensor) + " refused; valid: [0, " +
                std::to_string(sensorCount() - 1) + "]");
  }
}

void TactileHand::reset(const std::optional<Eigen::Isometry3d>& object_in_world) {
  sim_->reset(object_in_world ? &*object_in_world : nullptr);
  // Pad to whole frames: every frame stays on the physics clock's grid.
  const std::int64_t ticks = sim_->ticks();
  sim_->step(static_cast<int>((ticks_per_frame_ - ticks % ticks_per_frame_) % ticks_per_frame_));
  episode_first_frame_ = frameIndex();
  renderAll();
}

void TactileHand::stepPhysics(int frames) {
  if (frames < 1 || frames > 100000) {
    throw Error("step frames = " + std::to_string(frames) + " refused; valid: [1, 100000]");
  }
  sim_->step(frames * ticks_per_frame_);
}

void TactileHand::render(int sensor) {
  checkSensor(sensor);
  const std::int64_t frame =
      options_.noise_per_episode ? frameIndex() - episode_first_frame_ : frameIndex();
  const std::int64_t noise_seed =
      options_.noise_seed < 0 ? -1 : options_.noise_seed * 1000003 + frame;
  TactileRenderer& renderer = *renderers_[sensor];
  const GelContactState& contact = sim_->contact(sensor);
  std::optional<ShearLoad> shear;
  if (options_.shear || renderer.model().markers.enabled) shear = shearLoadOf(contact, friction());
  frames_[sensor] = &renderer.render(objectInGel(sensor), noise_seed, contact.normal_force_n, shear);
}

void TactileHand::renderAll() {
  // Each sensor has a renderer of its own and reads the physics only: they may run at once.
  if (render_pool_) {
    render_pool_->run(sensorCount(), [this](int s) { render(s); });
  } else {
    for (int s = 0; s < sensorCount(); ++s) render(s);
  }
}

Eigen::Isometry3d TactileHand::objectInGel(int sensor) const {
  checkSensor(sensor);
  return sim_->gelInWorld(sensor).inverse() * sim_->objectInWorld();
}

void TactileHand::step(int frames) {
  stepPhysics(frames);
  renderAll();
}

}  // namespace norm2tex
