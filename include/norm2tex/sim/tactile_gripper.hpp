#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "norm2tex/render/object_texture_cache.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "norm2tex/sim/gripper_sim.hpp"

namespace norm2tex {

/// How a TactileGripper runs: the same choices as the ROS system's contact_sim and
/// tactile_renderer parameters, with the same defaults, so that one configuration gives the
/// same frames in-process and over ROS.
struct TactileGripperOptions {
  double frame_rate_hz = 60.0;      ///< sensor frames per second (contact_sim ~frame_rate)
  double physics_rate_hz = 1000.0;  ///< asked-for physics ticks per second (~physics_rate); the
                                    ///< sim runs whole ticks per frame, as contact_sim does
  /// config/materials/<name>.yaml of the texture (and, with friction < 0, the friction); empty:
  /// no material (textureless, friction kDefaultTactileFriction unless given).
  std::string material_config;
  int variant = 0;                 ///< the material's variant (0 = its own values)
  std::uint64_t material_seed = 0;  ///< seed of the variants (tactile_renderer ~material_seed)
  double beta_mm = -1.0;           ///< texture depth, mm; < 0: the material's; 0: textureless
  double friction = -1.0;          ///< Coulomb coefficient; < 0: the material's
  /// Image noise: frame f gets noise seed noise_seed * 1000003 + f (tactile_renderer's rule);
  /// < 0: no noise.
  std::int64_t noise_seed = 0;
  /// Count f from each episode's first frame instead of from construction: an episode's
  /// images then depend only on its seeds, not on what ran before (what a learning environment
  /// needs: reset(seed) twice, the same frames). The ROS system counts from its start.
  bool noise_per_episode = false;
  /// Render the gel's lateral motion from the physics' tangential force and twist
  /// (frame.shear: the traction, the slip, the surface's displacement, the markers carried).
  /// Always on when the sensor has markers; off otherwise by default (it costs 0.15-0.25 ms a
  /// frame and changes nothing in a marker-less frame).
  bool shear = false;
  /// The episode the gripper starts with (contact_sim ~seed, ~height_offset: NaN = drawn).
  std::uint64_t seed = 0;
  double height_offset_m = std::numeric_limits<double>::quiet_NaN();
};

/// Friction without a material (contact_sim's default).
constexpr double kDefaultTactileFriction = 0.5;

/// Throws Error naming the first option out of range and its valid range.
void validate(const TactileGripperOptions& options);

/// The simulated gripper and both of its DIGITs, advanced a sensor frame at a time: what the
/// ROS system's contact_sim and two tactile_renderers do, in one object and one thread, for
/// learning and scripting without ROS.
///
/// Frames follow contact_sim exactly: physics at whole ticks per frame (rate_hz = ticks x
/// frame_rate), a reset padded to whole frames, frame index = ticks / ticks per frame, and the
/// renderers' per-frame noise seed. Construction starts the options' episode, as contact_sim
/// does when it starts, so a fresh TactileGripper and a freshly launched system reach the same
/// states for the same resets and commands.
///
/// Not thread-safe; distinct grippers may run on distinct threads (TactileGripperBatch).
class TactileGripper {
 public:
  /// `scene`'s gel pad is set from `sensor` (setGelFromSensor). `textures` may be shared by
  /// several grippers (a batch): a variant is then generated once for all of them. Throws Error
  /// for invalid options, scene or sensor, or an unusable object or material.
  TactileGripper(GripperSimConfig scene, const SensorModel& sensor,
                 const TactileGripperOptions& options,
                 std::shared_ptr<ObjectTextureCache> textures = nullptr);

  /// Starts an episode (GripperSim::reset), pads it to whole frames and renders its first
  /// frame. Throws Error (nothing changed) for an offset outside the scene's range.
  EpisodeStart reset(std::uint64_t seed, std::optional<double> height_offset_m = std::nullopt);

  /// Uses `variant` of the material from the next rendered frame on (generated on first use,
  /// then kept by the texture cache). Throws Error without a material.
  void setVariant(int variant);
  /// Starts generating `variant` in the background (returns at once).
  void prefetchVariant(int variant);
  int variant() const { return variant_; }
  /// The noise seed from the next rendered frame on (< 0: no noise).
  void setNoiseSeed(std::int64_t noise_seed) { options_.noise_seed = noise_seed; }

  /// Advances the physics by `frames` sensor frames and renders both sensors at the last.
  void step(int frames = 1);
  /// Advances the physics only (TactileGripperBatch renders the sensors on other threads).
  void stepPhysics(int frames = 1);
  /// Renders one sensor at the current state.
  void render(Finger finger);
  /// The pose a sensor renders the object at: the object frame in its gel frame, metres (as the
  /// renderer node reads it from TF).
  Eigen::Isometry3d objectInGel(Finger finger) const;

  /// The latest rendered frame of a sensor (valid until its next render).
  const TactileFrame& frame(Finger finger) const { return *frames_[index(finger)]; }
  /// The no-contact frame (without noise): what background-subtracted observations subtract.
  const cv::Mat3b& background(Finger finger) const {
    return renderers_[index(finger)]->shader().background();
  }
  /// Frames since construction (contact_sim's SimFrame.frame).
  std::int64_t frameIndex() const { return sim_->ticks() / ticks_per_frame_; }
  int ticksPerFrame() const { return ticks_per_frame_; }
  double frameSeconds() const { return ticks_per_frame_ * sim_->tickSeconds(); }
  double betaMm() const { return beta_mm_; }
  double friction() const { return sim_->config().object.friction; }

  GripperSim& sim() { return *sim_; }
  const GripperSim& sim() const { return *sim_; }
  const SensorModel& sensor() const { return renderers_[0]->model(); }

 private:
  static int index(Finger finger) { return static_cast<int>(finger); }
  void useVariant(int variant);

  TactileGripperOptions options_;
  std::unique_ptr<GripperSim> sim_;
  int ticks_per_frame_ = 1;
  std::shared_ptr<TexturedMesh> mesh_;
  std::shared_ptr<ObjectTextureCache> textures_;
  std::array<std::unique_ptr<TactileRenderer>, 2> renderers_;
  std::array<const TactileFrame*, 2> frames_{};
  std::int64_t episode_first_frame_ = 0;
  double beta_mm_ = 0.0;
  int variant_ = 0;
};

}  // namespace norm2tex
