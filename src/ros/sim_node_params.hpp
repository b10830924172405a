#pragma once
// What the simulation nodes (contact_sim, hand_sim) read alike from their private parameters,
// and the scene those parameters make.

#include <cstdint>
#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/gripper_sim_config.hpp"

namespace norm2tex {

/// Friction against the gels with ~material none and no ~friction (the scene default's).
constexpr double kDefaultFriction = 0.5;

/// The private parameters every simulation node has (docs/ros.md).
struct SimNodeParams {
  bool synchronous = false;  ///< ~mode: "real_time" | "synchronous"
  std::string scene;         ///< ~scene: scene yaml (object, physics, gel law)
  std::string mesh;          ///< ~mesh: replaces the scene's object mesh when set
  double scale = 1.0;        ///< ~scale of ~mesh (0.001 for millimetres)
  std::string sensor;        ///< ~sensor: sensor yaml (gel pad and thickness)
  /// ~material: config/materials/<material>.yaml gives the friction and beta; "none": no
  /// material (the renderers use a texture file or the mesh's own texture)
  std::string material;
  std::string material_config;  ///< the yaml resolved from ~material; "" for none
  /// ~friction: Coulomb coefficient against the gels; < 0: the material's (kDefaultFriction
  /// with ~material none)
  double friction = -1.0;
  double beta = -1.0;            ///< ~beta [mm], a label; < 0: the material's beta_mm
  double physics_rate = 1000.0;  ///< ~physics_rate [Hz], rounded to whole ticks per frame
  double frame_rate = 60.0;      ///< ~frame_rate [Hz]: sensor frames (TF, contacts, clock)
  /// ~renderers: the sensors whose FrameRendered each synchronous frame waits for.
  std::vector<std::string> renderers;
  double render_timeout = 5.0;  ///< ~render_timeout [s of wall time] for each FrameRendered
  /// ~ready_timeout [s of wall time] for the renderers to start (texture bakes included)
  double ready_timeout = 60.0;
};

/// Reads and validates them; throws Error naming the parameter and its valid range at fault.
void readSimNodeParams(const ros::NodeHandle& private_nh, SimNodeParams& params);

/// The scene as the parameters make it.
struct SimNodeScene {
  /// The scene yaml with ~mesh, ~scale, the friction and the material's name in its object,
  /// the sensor's gel pad, and physics at ticks_per_frame x ~frame_rate.
  GripperSimConfig config;
  SensorModel sensor;
  double friction = 0.0;  ///< the object's friction against the gels
  /// What the renderers draw, a label: ~beta, the material's beta_mm, or a texture file's
  /// default (kFileTextureBetaMm).
  double beta_mm = 0.0;
  /// Whole physics ticks per sensor frame, so every frame's stamp is a physics state.
  int ticks_per_frame = 1;
  std::int64_t frame_period_ns = 0;
};

/// Throws Error for an unreadable scene, sensor, mesh or material.
SimNodeScene makeSimNodeScene(const SimNodeParams& params);

}  // namespace norm2tex
