#pragma once

#include <cstdint>
#include <string>

#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/gel/gel_law.hpp"

namespace norm2tex {

/// The parallel gripper: a base fixed in the world and two fingers on one prismatic axis,
/// coupled so they stay centred. Each finger carries a DIGIT whose gel faces the other finger.
struct GripperOptions {
  /// A two-finger hand of your own (scene yaml gripper.hand: a hand yaml, docs/hands.md) instead
  /// of the built-in gripper; empty: the built-in one. With a hand the fields below are the
  /// hand's, measured by GripperSim from its URDF and yaml (the yaml may not give them).
  std::string hand_yaml;
  double base_height_m = 0.20;  ///< gel centres above the world's floor (z = 0), metres
  /// Gap between the two undeformed gel surfaces at opening 0 (closed) and 1 (fully open), m.
  double min_gap_m = 0.0;
  double max_gap_m = 0.040;
  /// Force limit per gel: the drive closes both fingers with at most twice this (the sum of the
  /// gels' forces), so a squeeze stops where each gel carries it.
  double max_force_n = 35.0;
  double max_speed_m_s = 0.02;  ///< finger speed (each finger), metres per second
  /// Stiffness of each finger's drive (servo position loop, linkage, printed finger) in series
  /// with its gel, N/m: a finger sits back from its commanded position by F / stiffness, F the
  /// gel's normal force. 0: rigid position control (the fingers are where the command puts
  /// them).
  double stiffness_n_per_m = 0.0;
};

/// The object between the gels.
struct ObjectOptions {
  std::string name = "cube";
  /// A mesh file (OBJ, STL, PLY, DAE, glTF/GLB) or a primitive: "box:<x>x<y>x<z>" or
  /// "sphere:<r>" in millimetres (see loadObjectMesh).
  std::string mesh = "box:30x30x30";
  double scale = 1.0;     ///< mesh file units to metres (0.001 for millimetres)
  double mass_kg = 0.10;  ///< the paper's cube: ~30 mm of PLA, 100 g with its insert
  /// "auto": an exact box, sphere or capsule when the mesh is one (loadObjectMesh), else the
  /// convex hull of its vertices, or a convex decomposition when the hull bridges a hollow
  /// deeper than 0.15 mm on a side facing the gels (see GripperSim::collision()). "box" (the
  /// bounding box), "hull" and "decomposition" (HACD convex parts, computed once at
  /// construction) force one.
  std::string collision = "auto";
  double friction = 0.5;  ///< Coulomb coefficient against the gel (from the material config)
  std::string material = "wood";  ///< label only: the material the friction came from
};

/// Bullet world settings.
struct PhysicsOptions {
  double rate_hz = 1000.0;     ///< physics ticks per second of simulated time
  int substeps = 1;            ///< Bullet steps per tick (dt = 1 / (rate_hz * substeps))
  int solver_iterations = 50;  ///< sequential-impulse iterations per Bullet step, at most ...
  /// ... until no contact's velocity changes by more than this in an iteration (m/s; 1e-6 is
  /// 1 nm per 1 ms tick); 0 = always every iteration.
  double solver_tolerance_m_s = 1e-6;
  double gravity_m_s2 = 9.81;  ///< along -z of the world
  double gel_damping = 5.0;    ///< contact damping of the gel, N s / m (per contact point)
  double friction_erp = 0.2;   ///< how fast a sticking contact recovers its anchor, per step
};

/// How an episode starts (GripperSim::reset).
struct EpisodeOptions {
  /// Object centre above the gel centre, drawn uniformly in [low, high] metres (the paper:
  /// 0-2.5 cm).
  double height_offset_low_m = 0.0;
  double height_offset_high_m = 0.025;
  /// Opening the fingers close to before control is handed over (the scene's fixed grasp); a
  /// value < 0 means: close until both gels touch the object, then on until each gel is
  /// indented `grasp_indentation_m` (or carries `grasp_force_n` when that is > 0).
  double grasp_opening = -1.0;
  double grasp_indentation_m = 1.0e-3;
  double grasp_force_n = 0.0;
  double settle_s = 0.5;  ///< simulated seconds under gravity before control is handed over
};

struct GripperSimConfig {
  GripperOptions gripper;
  ObjectOptions object;
  PhysicsOptions physics;
  EpisodeOptions episode;
  GelLaw gel_law = GelLaw::taximDefault();
  /// Gel pad: width (along the gel frame's x), height (y) and thickness, metres: the sensor
  /// model's gel pad and thickness (setGelFromSensor). The camera images the pad's middle.
  double gel_width_m = 0.0192;
  double gel_height_m = 0.0256;
  double gel_thickness_m = 0.0046;
};

/// Sets the gel pad to the sensor's (gel.pad_width_mm x pad_height_mm) and its thickness. The
/// pad is larger than the imaged area (cols x rows x mm_per_pixel, about 13 x 17 mm at the
/// measured scale): an object can rest on the gel outside the camera's view.
void setGelFromSensor(const SensorModel& sensor, GripperSimConfig& config);

/// Throws Error naming the first field out of range (its yaml key) and its valid range.
void validate(const GripperSimConfig& config);

/// Reads a scene yaml (sections gripper, object, physics, episode, gel.law; every key optional,
/// unknown keys are errors). A relative object mesh path is resolved against the yaml's
/// directory. Throws Error naming the file and the key at fault.
GripperSimConfig loadGripperSimConfig(const std::string& yaml_path);

}  // namespace norm2tex
