#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "norm2tex/mesh/object_mesh.hpp"
#include "norm2tex/sim/gel_contact.hpp"
#include "norm2tex/sim/gripper_sim_config.hpp"

namespace norm2tex {

class HandSim;

enum class Finger { kLeft = 0, kRight = 1 };

/// What one gel feels, after the latest physics tick.
struct GelContactState {
  bool in_contact = false;
  /// Total normal force the object presses into the gel with, N (>= 0).
  double normal_force_n = 0.0;
  /// Tangential force the object applies to the gel, N, in the gel frame (z is ~0).
  Eigen::Vector3d shear_force_n = Eigen::Vector3d::Zero();
  /// Where the normal force acts: the contact points' centroid weighted by their normal forces,
  /// gel frame x, y, metres (0 without contact points).
  Eigen::Vector2d pressure_centre_m = Eigen::Vector2d::Zero();
  /// Twisting moment the object applies to the gel about its +z through pressure_centre_m, N m
  /// (positive turns +x towards +y; ShearLoad::torque_nm): the moment of the contact points'
  /// friction forces (contactResultant). A contact held by one point has none of those: the
  /// torsional friction Bullet gives a lone point (GelPadContacts) is not reported back by its
  /// solver, so such a contact reports 0.
  double twist_moment_nm = 0.0;
  /// Deepest penetration of the object into the undeformed gel surface, metres (>= 0): the
  /// indentation the renderer draws at this pose.
  double penetration_m = 0.0;
  /// The penetration is deeper than the gel law's table reaches (its last point, 2 mm by
  /// default): the force is extrapolated, and past the gel's thickness it stops growing.
  bool too_deep = false;
  /// Pose of the object frame in the gel frame (see SensorModel: +x image right, +y image
  /// down, +z out of the gel).
  Eigen::Isometry3d object_in_gel = Eigen::Isometry3d::Identity();
};

/// What reset() did.
struct EpisodeStart {
  std::uint32_t episode = 0;  ///< counts resets, from 1
  std::uint64_t seed = 0;
  double height_offset_m = 0.0;  ///< object centre above the gel centres
  double grasp_opening = 0.0;    ///< normalised command the fingers closed to
};

/// How the object collides with the gels (GripperSim::collision()).
struct ObjectCollision {
  /// "box", "sphere", "capsule" (exact), "hull" (the convex hull of the mesh's vertices;
  /// cylinders too, whose facets the renderer draws), or "decomposition".
  std::string kind;
  int parts = 1;  ///< convex parts (> 1 for a decomposition)
  /// Deepest hollow of the mesh under its hull within the gel's reach (the gel law's deepest
  /// point) of the sides facing the gels (world +-y), m; computed for "auto" collision only.
  double hull_deviation_m = 0.0;
};

/// A Bullet simulation of a parallel gripper whose two DIGIT gels hold an object: the built-in
/// hand, config/hands/parallel_gripper.urdf and .yaml (compiled into the library), run by
/// HandSim with the scene's stroke, speed, force and stiffness; GripperSim adds the episodes
/// (reset(): seat, grasp, settle) and the drop latch.
///
/// World frame: z up, floor at z = 0. The gripper base sits at (0, 0, base_height) with the
/// world's orientation; the fingers move along its y axis, the left finger at +y (REP-103:
/// x forward, y left). Each finger frame sits at the centre of its undeformed gel surface;
/// its gel frame (the renderer's) is rotated so +z points at the other finger and +y (image
/// down) points down the finger, towards the floor.
///
/// Gel contact: the package computes where the object reaches into each gel pad itself (exact
/// for a box, sphere or capsule and for a convex hull: see gelContactPoints) and hands Bullet
/// at most four points per convex part and gel, kept between ticks as friction anchors: a
/// contact inside the Coulomb cone keeps its anchor, so a held object does not creep. The gels
/// are kinematic bodies with Bullet soft contacts (contact stiffness and damping, solved
/// implicitly). Before every Bullet step each gel's contact stiffness is set to
/// GelLaw::force(d) / sum(d_i) from the penetrations d_i of its points (d = the deepest, at
/// most the gel's thickness), so at rest the object sinks into each gel exactly as deep as the
/// law says for the force it carries.
///
/// Fingers are position-controlled at max_speed, coupled (the right finger's joint mimics the
/// left's: both at the same distance from the centre plane), by one drive whose effort is
/// 2 x max_force: a command narrower than the object indents both gels until together they carry
/// it (max_force each when the object sits still between them), the drive advancing and
/// yielding by one Newton step a tick with the gel law's stiffness (HandSim). With
/// gripper.stiffness_n_per_m = k > 0 the drive is compliant: its stiffness is 2 k, so each
/// finger sits back from the commanded position by F / k (F the mean gel force), reached by one
/// Newton step of the series equilibrium per tick; k = 0 is rigid.
///
/// A two-finger hand of your own (GripperOptions::hand_yaml, scene yaml gripper.hand): its
/// two DIGITs (the first the left finger's) must face each other across the fingers and its
/// gripper.joints be prismatic joints that move the gels along that axis, centred. GripperSim
/// measures the hand at gripper.closed and gripper.open and works in its grip frame: origin
/// midway between the open gels' centres, y from the right gel to the left, z the world's up
/// made square to y (so the grip axis must be 30 degrees or more from vertical). The gripper
/// section of config() then holds the hand's values: the gaps measured, base_height_m the grip
/// frame's height, force, speed and stiffness per finger from its drives (a drive moving both
/// fingers through a mimic joint counts half). Episodes, openings and the drop latch are as
/// for the built-in gripper, in that frame; the gels' heights across it are their pads'
/// extents along z.
///
/// Deterministic: the same config, reset seeds and commands give bit-identical trajectories.
class GripperSim {
 public:
  /// Loads the object (loadObjectMesh) and builds the world with the object seated at the
  /// lowest height offset of heightOffsetRange() and the fingers open; call reset() to start an episode.
  /// Throws Error for an invalid config, an unreadable mesh, an object wider than max_gap (or
  /// too thin for the closed gripper to reach the grip), or one whose sides miss the gel pads
  /// at every height offset of the scene; with a hand, for a hand yaml HandSim refuses, and
  /// for a hand that is not a parallel gripper as described above (naming what is not).
  explicit GripperSim(const GripperSimConfig& config);
  ~GripperSim();
  GripperSim(const GripperSim&) = delete;
  GripperSim& operator=(const GripperSim&) = delete;

  /// Height offsets (object centre above the gel centres, m) reset() accepts and draws from:
  /// the scene's episode.height_offset_mm where the object's sides, within the gel's reach
  /// of its extent along the grip axis, overlap the gel pads by 1 mm or more.
  std::pair<double, double> heightOffsetRange() const { return height_offset_range_; }

  /// Re-seats the object at `height_offset_m` (or, when absent, one drawn uniformly from
  /// heightOffsetRange() with `seed`), centred on its extent along the grip axis between gels
  /// opened 1 mm wider than it on each side, and grasps it without gravity on it: the fingers
  /// close until both gels touch, then to the grip that indents each by
  /// episode.grasp_indentation_m (or carries episode.grasp_force_n), measured on the object's
  /// real surface; with episode.grasp_opening >= 0 they close to that opening instead. Then
  /// the object settles under gravity for episode.settle_s. Simulated time keeps running
  /// through it. Throws Error (and changes nothing) for NaN or an offset outside the scene's
  /// [episode.height_offset_low_m, height_offset_high_m] or heightOffsetRange(); throws Error
  /// naming the offset when the closing gels still miss the object (the fingers are then left
  /// open).
  EpisodeStart reset(std::uint64_t seed, std::optional<double> height_offset_m = std::nullopt);

  /// Normalised opening command, 0 = closed (gap min_gap) ... 1 = open (gap max_gap). Throws
  /// Error (and changes nothing) for NaN or values outside [0, 1].
  void setOpening(double opening);
  /// Adds `delta` to the current command, clamped to [0, 1]. Throws Error (and changes
  /// nothing) for NaN or |delta| > 1.
  void addOpening(double delta);
  double commandedOpening() const { return command_; }
  /// Where the fingers are now, as a normalised opening (may lag the command, stop short of
  /// it at the force limit, or sit wider than it on a compliant drive).
  double opening() const;
  /// Gap between the undeformed gel surfaces for a normalised opening, metres.
  double gapForOpening(double opening) const;

  /// Advances `ticks` physics ticks of 1 / physics.rate_hz each.
  void step(int ticks = 1);
  double tickSeconds() const { return 1.0 / config_.physics.rate_hz; }
  /// Ticks since construction (resets keep counting: simulated time never goes back).
  std::int64_t ticks() const;

  const GelContactState& contact(Finger finger) const;
  Eigen::Isometry3d objectInWorld() const;
  /// The gripper base in the world: (0, 0, base_height) unrotated; a hand's root link pose.
  Eigen::Isometry3d baseInWorld() const;
  /// Finger frame in the base frame: (0, +-position, 0), no rotation; on a hand, the pose of
  /// the link that carries the finger's DIGIT.
  Eigen::Isometry3d fingerInBase(Finger finger) const;
  /// The built-in gripper's gel frame in its finger frame (a fixed rotation).
  static Eigen::Isometry3d gelInFinger(Finger finger);
  /// The gel frame in the finger frame fingerInBase() places: gelInFinger() for the built-in
  /// gripper, the DIGIT's mount on its link for a hand (HandSim::gelInLink).
  Eigen::Isometry3d gelInFingerFrame(Finger finger) const;
  /// The grip frame in the world (see the class comment): (0, 0, base_height) unrotated for the
  /// built-in gripper.
  Eigen::Isometry3d gripInWorld() const { return grip_in_world_; }
  /// True for a hand of your own (GripperOptions::hand_yaml), false for the built-in gripper.
  bool hasOwnHand() const { return !config_.gripper.hand_yaml.empty(); }
  /// The hand that runs it (the built-in gripper's or yours).
  const HandSim& hand() const { return *hand_; }
  Eigen::Isometry3d gelInWorld(Finger finger) const;
  /// Prismatic joint position of a finger: distance of its undeformed gel surface from the
  /// centre plane, metres (both fingers are equal: they are coupled). Where the finger is, not
  /// where it is commanded: a compliant drive leaves it further out. On a hand: half the gap
  /// between its undeformed gel surfaces along the grip axis.
  double fingerPosition() const;
  /// Latched once the object has left both gels and fallen below their lower edge at the end of
  /// a tick; cleared by reset().
  bool dropped() const { return dropped_; }

  const GripperSimConfig& config() const { return config_; }
  const ObjectMesh& object() const;
  /// Convex pieces the object collides as: 1 for a box or a hull, more for a decomposition.
  int collisionPartCount() const { return collision().parts; }
  const ObjectCollision& collision() const;

 private:
  /// Runs a hand of your own: builds it, measures its grip frame and stroke, and fills the
  /// config's gripper section with them.
  void useOwnHand();
  /// The gripper joints' targets for a normalised opening.
  std::vector<double> jointTargets(double opening) const;
  /// The gripper joints' positions at opening 1.
  std::vector<double> openJointPositions() const;
  /// Ticks the drives need to reach the command's targets from where they are.
  int ticksToArrive() const;
  void findHeightOffsetRange();
  /// The object frame's pose with its body (its bounds' centre) `offset_m` above the gel
  /// centres, unrotated.
  Eigen::Isometry3d seatedObjectPose(double offset_m) const;
  /// Sets the command and the drive's target: the finger joint at half the gap.
  void command(double opening);
  /// Closes from the open seat until both gels touch, then to the configured grip.
  double closeOnTheObject(double offset_m);
  /// How far a finger sits back from its drive when its gel is indented `depth`, m (0: rigid).
  double drivePreload(double depth) const;
  double objectWidthM() const;

  GripperSimConfig config_;
  std::unique_ptr<HandSim> hand_;
  int finger_joint_ = 0;  ///< the built-in left finger's joint, the drive's (the right mimics it)
  /// The joints the opening drives: the built-in gripper's finger_left_joint, or the hand's
  /// gripper.joints.
  std::vector<std::string> gripper_joints_;
  std::vector<int> gripper_joint_indices_;
  Eigen::Isometry3d grip_in_world_ = Eigen::Isometry3d::Identity();
  /// Half the gel pads' extent along the grip frame's z (the lower of the two gels').
  double pad_half_height_m_ = 0.0;
  std::pair<double, double> height_offset_range_;
  double command_ = 1.0;
  std::uint32_t episode_ = 0;
  bool dropped_ = false;
};

}  // namespace norm2tex
