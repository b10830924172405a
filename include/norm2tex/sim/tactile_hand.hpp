#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "norm2tex/common/parallel_for.hpp"
#include "norm2tex/render/object_texture_cache.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "norm2tex/sim/hand_sim.hpp"

namespace norm2tex {

/// How a TactileHand runs: TactileGripperOptions' choices that are not the gripper's episode,
/// with the same meanings and defaults (hand_sim's and tactile_renderer's parameters).
struct TactileHandOptions {
  double frame_rate_hz = 60.0;      ///< sensor frames per second (hand_sim ~frame_rate)
  double physics_rate_hz = 1000.0;  ///< asked-for physics ticks per second; whole ticks a frame
  /// config/materials/<name>.yaml of the texture (and, with friction < 0, the friction); empty:
  /// no material (textureless, friction kDefaultTactileFriction unless given).
  std::string material_config;
  int variant = 0;                  ///< the material's variant (0 = its own values)
  std::uint64_t material_seed = 0;  ///< seed of the variants
  double beta_mm = -1.0;            ///< texture depth, mm; < 0: the material's; 0: textureless
  double friction = -1.0;           ///< Coulomb coefficient; < 0: the material's
  /// Image noise: frame f gets noise seed noise_seed * 1000003 + f on every sensor
  /// (tactile_renderer's rule); < 0: no noise.
  std::int64_t noise_seed = 0;
  /// Count f from each reset's first frame instead of from construction (an episode's images
  /// then depend only on its seeds and commands).
  bool noise_per_episode = false;
  /// Render the gel's lateral motion from the physics' tangential force and twist
  /// (frame.shear: the traction, the slip, the surface's displacement, the markers carried).
  /// Always on when the sensor has markers; off otherwise by default (it costs 0.15-0.25 ms a
  /// frame and changes nothing in a marker-less frame).
  bool shear = false;
  /// Threads the sensors render on, the caller's included (each sensor's frame is the same
  /// whatever the count): 1 renders them one after another (for hands already run in parallel,
  /// as a batch does); 0: one per core, at most one per sensor.
  int render_threads = 1;
};

/// Throws Error naming the first option out of range and its valid range.
void validate(const TactileHandOptions& options);

/// Any hand (HandSim) and one DIGIT renderer per mounted sensor, advanced a sensor frame at a
/// time: what hand_sim.launch's hand_sim and its tactile_renderers do, in one object and one
/// thread, for learning and scripting without ROS. Modelled on TactileGripper: physics at whole
/// ticks per frame (rate_hz = ticks x frame_rate), resets padded to whole frames, frame index
/// = ticks / ticks per frame, the renderers' per-frame noise seed. The sensors render one after
/// another, or on options.render_threads threads at once (hand_sim.launch renders them in
/// parallel too: a nodelet each).
///
/// Not thread-safe; distinct hands may run on distinct threads.
class TactileHand {
 public:
  /// `sensor` is every mounted DIGIT's model unless the hand yaml gives a sensor its own
  /// (SensorMount::sensor_yaml); the physics' gel pad is `sensor`'s. `textures` may be shared
  /// by several hands. Throws Error for invalid options or sensor, an unusable hand, object or
  /// material. Starts with a reset() (the config's object pose).
  TactileHand(HandSimConfig config, const SensorModel& sensor, const TactileHandOptions& options,
              std::shared_ptr<ObjectTextureCache> textures = nullptr);

  /// Starts again (HandSim::reset: joints, drives and root at their initial values, the object
  /// at rest at `object_in_world`, else at the pose of the previous reset that gave one, else
  /// the config's), pads to whole frames and renders every sensor. Throws Error (nothing
  /// changed) for a pose that is not finite or not rigid.
  void reset(const std::optional<Eigen::Isometry3d>& object_in_world = std::nullopt);

  /// Advances the physics by `frames` sensor frames and renders every sensor at the last.
  /// Throws Error for frames outside [1, 100000].
  void step(int frames = 1);
  /// Advances the physics only.
  void stepPhysics(int frames = 1);
  /// Renders one sensor at the current state.
  void render(int sensor);
  void renderAll();

  int sensorCount() const { return static_cast<int>(renderers_.size()); }
  /// The index of the sensor named `name` (the hand yaml's order); throws Error naming the
  /// sensors for an unknown name.
  int sensorIndex(const std::string& name) const;
  const std::string& sensorName(int sensor) const {
    checkSensor(sensor);
    return sim_->sensor(sensor).name;
  }

  /// The object frame in sensor i's gel frame, metres: what its renderer draws.
  Eigen::Isometry3d objectInGel(int sensor) const;
  /// The latest rendered frame of a sensor (valid until its next render).
  const TactileFrame& frame(int sensor) const {
    checkSensor(sensor);
    return *frames_[sensor];
  }
  /// The no-contact frame (without noise).
  const cv::Mat3b& background(int sensor) const {
    checkSensor(sensor);
    return renderers_[sensor]->shader().background();
  }
  const SensorModel& sensorModel(int sensor) const {
    checkSensor(sensor);
    return renderers_[sensor]->model();
  }

  /// Frames since construction.
  std::int64_t frameIndex() const { return sim_->ticks() / ticks_per_frame_; }
  int ticksPerFrame() const { return ticks_per_frame_; }
  double frameSeconds() const { return ticks_per_frame_ * sim_->tickSeconds(); }
  double betaMm() const { return beta_mm_; }
  double friction() const { return sim_->config().object.friction; }
  int variant() const { return variant_; }
  /// The noise seed from the next rendered frame on (< 0: no noise).
  void setNoiseSeed(std::int64_t noise_seed) { options_.noise_seed = noise_seed; }

  HandSim& sim() { return *sim_; }
  const HandSim& sim() const { return *sim_; }

 private:
  void checkSensor(int sensor) const;

  TactileHandOptions options_;
  std::unique_ptr<HandSim> sim_;
  int ticks_per_frame_ = 1;
  std::shared_ptr<TexturedMesh> mesh_;
  std::shared_ptr<ObjectTextureCache> textures_;
  std::vector<std::unique_ptr<TactileRenderer>> renderers_;
  std::vector<const TactileFrame*> frames_;
  std::int64_t episode_first_frame_ = 0;
  double beta_mm_ = 0.0;
  int variant_ = 0;
  std::unique_ptr<ParallelFor> render_pool_;  ///< null: the sensors render one after another
};

}  // namespace norm2tex
