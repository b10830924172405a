#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "norm2tex/mesh/object_mesh.hpp"
#include "norm2tex/gel/gel_law.hpp"
#include "norm2tex/sim/gel_contact.hpp"
#include "norm2tex/sim/gripper_sim.hpp"
#include "norm2tex/sim/hand_config.hpp"
#include "norm2tex/sim/hand_description.hpp"

class btCollisionShape;

namespace norm2tex {

/// Everything a HandSim is made of.
struct HandSimConfig {
  HandConfig hand;
  ObjectOptions object;
  /// The object frame's pose in the world at construction (and resetObject()'s default).
  Eigen::Isometry3d object_pose = Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 0.1));
  PhysicsOptions physics;
  GelLaw gel_law = GelLaw::taximDefault();
  /// Every mounted DIGIT's gel pad (width along the gel frame's x, height along y) and
  /// thickness, metres: the sensor model's (as GripperSimConfig's).
  double gel_width_m = 0.0192;
  double gel_height_m = 0.0256;
  double gel_thickness_m = 0.0046;
};

/// A joint trajectory as trajectory_msgs/JointTrajectory carries it: joint names, and points of
/// positions at times from its start.
struct JointTrajectoryCommand {
  std::vector<std::string> joint_names;
  std::vector<double> times_s;                 ///< time_from_start of each point, increasing
  std::vector<std::vector<double>> positions;  ///< per point, one per joint name
};

/// Where a mounted gel stands against its link's collision mesh (what loading checked).
struct SensorMountCheck {
  /// How far the gel surface lies in front of the link's collision geometry over the pad,
  /// metres (negative: the geometry pokes through the gel surface); NaN when the link has no
  /// geometry under the pad.
  double gel_in_front_of_mesh_m = 0.0;
};

/// Any hand from its URDF with DIGITs on any links, holding an object, on Bullet.
///
/// The hand is position-controlled, as real hands with servo drives are: every actuated joint
/// has a drive that moves at most its velocity limit towards its target and pushes with at most
/// its effort limit; links are kinematic bodies placed by forward kinematics from the joints'
/// positions, the object is the one dynamic body. The load on a joint is the generalised force
/// of every contact on the links it carries (a gel's force through its contact points, a rigid
/// link's through Bullet's). A drive that pushes against its load stops where the load reaches
/// its effort (one Newton step a tick, with the gels' law as the contact's stiffness), so a
/// grasp's force is the drive's effort; a drive with stiffness k sits back from its position by
/// load / k. Mimic joints follow their master's position, and their load adds to the master's
/// times the multiplier. (GripperSim is the built-in parallel gripper on this class.)
///
/// Each mounted DIGIT gets the package's compliant gel contact (gel law, friction anchors,
/// patch torsion, too_deep), for any pose of its link; the DIGIT's own link meets the object
/// only through its gel (its mesh includes the gel, which is soft); other links collide rigidly.
///
/// Deterministic: the same config and commands give bit-identical trajectories.
class HandSim {
 public:
  /// Loads the URDF, its meshes and the object and builds the world with every joint at its
  /// initial position. Throws Error for an invalid config, URDF, mesh or object, a sensor on a
  /// link that is not in the hand, or a joint whose drive has no effort or velocity limit (in
  /// neither the URDF nor the hand yaml).
  explicit HandSim(const HandSimConfig& config);
  /// The same with the hand given as `description` (loaded or made by the caller, as GripperSim
  /// makes the built-in gripper's with the scene's stroke) instead of loaded from hand.urdf_path,
  /// which then only names it in messages.
  HandSim(const HandSimConfig& config, HandDescription description);
  ~HandSim();
  HandSim(const HandSim&) = delete;
  HandSim& operator=(const HandSim&) = delete;

  const HandDescription& description() const { return description_; }
  const HandSimConfig& config() const { return config_; }
  /// What loading changed or noticed (the description's warnings, gel mount checks).
  const std::vector<std::string>& warnings() const { return warnings_; }

  /// Names of the joints a command may name: movable and not mimic.
  const std::vector<std::string>& actuatedJoints() const { return actuated_names_; }
  /// Position of every joint of description().joints (fixed: 0).
  const std::vector<double>& jointPositions() const { return q_; }
  double jointPosition(const std::string& name) const;
  /// Where each joint's drive has brought it (fixed and mimic joints: 0): its target approached
  /// at the velocity limit, held back at the effort limit. A joint with a drive stiffness sits
  /// back from it by load / stiffness.
  const std::vector<double>& driveJointPositions() const { return drive_q_; }
  /// The generalised force the contacts exert on each joint (N or N m), after the last tick.
  const std::vector<double>& jointLoads() const { return load_; }
  /// The drive's effort and velocity limits and stiffness per joint (URDF or yaml).
  double jointEffort(int joint) const { return drives_[joint].effort; }
  double jointVelocity(int joint) const { return drives_[joint].velocity; }
  double jointStiffness(int joint) const { return drives_[joint].stiffness; }

  /// Sets targets for named actuated joints (the others keep theirs); stops any trajectory.
  /// Targets outside the URDF limits are clamped: returns the names of those clamped. Throws
  /// Error (nothing changed) for an unknown, fixed or mimic joint name, a size mismatch or a
  /// value that is not finite.
  std::vector<std::string> setJointTargets(const std::vector<std::string>& names,
                                           const std::vector<double>& positions);
  /// Follows a trajectory from now: targets move linearly from where they are to each point at
  /// its time. Same errors as setJointTargets, and for times that are not finite, negative or
  /// not increasing; clamping likewise (names returned).
  std::vector<std::string> setTrajectory(const JointTrajectoryCommand& trajectory);
  /// The target of every joint (fixed: 0; mimic: from its master's).
  const std::vector<double>& jointTargets() const { return target_; }
  /// The parallel-gripper opening (HandConfig::gripper): 0 closed ... 1 open. Throws Error when
  /// the hand yaml names no gripper joints, or for an opening outside [0, 1].
  void setOpening(double opening);
  /// The gripper joints' positions (HandConfig::gripper_joints) at a normalised opening:
  /// closed + opening x (open - closed), each; empty when the hand names none.
  std::vector<double> gripperJointPositions(double opening) const;

  /// Moves the hand's root (a floating hand moved by its arm): at once, or, with `duration_s` >
  /// 0, along a straight line (and the shortest rotation) at constant speed over that much
  /// simulated time (an arm streaming poses at the frame rate moves the hand smoothly; a jump
  /// would leave a held object behind). Throws Error for a pose that is not finite or not a
  /// rotation, or a negative duration.
  void setBasePose(const Eigen::Isometry3d& base_in_world, double duration_s = 0.0);
  Eigen::Isometry3d basePose() const { return base_pose_; }

  /// Starts again: every joint, drive and target at its initial position (no trajectory), the
  /// root at hand.base_pose, the object at rest at `object_in_world` (config.object_pose when
  /// null), the world rebuilt. Simulated time keeps running; the object's collision stays as
  /// construction made it. Throws Error for a pose that is not finite or not a rotation
  /// (nothing changed).
  void reset(const Eigen::Isometry3d* object_in_world = nullptr);
  /// As reset(), with the named actuated joints, their drives and their targets at `positions`
  /// (clamped to their limits) instead of their initial positions. Throws Error (nothing
  /// changed) as reset() and as setJointTargets for the names and positions.
  void reset(const Eigen::Isometry3d& object_in_world, const std::vector<std::string>& joint_names,
             const std::vector<double>& joint_positions);
  /// Puts the object at `object_in_world` at rest (with gravity on or off for it).
  void resetObject(const Eigen::Isometry3d& object_in_world, bool gravity = true);
  void setObjectGravity(bool on);

  /// Advances `ticks` physics ticks of 1 / physics.rate_hz each.
  void step(int ticks = 1);
  double tickSeconds() const { return 1.0 / config_.physics.rate_hz; }
  std::int64_t ticks() const { return ticks_; }

  int sensorCount() const { return static_cast<int>(config_.hand.sensors.size()); }
  const SensorMount& sensor(int index) const { return config_.hand.sensors[index]; }
  const SensorMountCheck& sensorCheck(int index) const { return checks_[index]; }
  const GelContactState& contact(int sensor) const { return contacts_[sensor]; }
  /// Whether the object reaches into the sensor's gel pad where it is now (contact() tells what
  /// the last tick measured).
  bool objectReachesIntoGel(int sensor) const;
  Eigen::Isometry3d linkInWorld(int link) const { return link_poses_[link]; }
  Eigen::Isometry3d gelInWorld(int sensor) const;
  /// The sensor's gel frame in its link frame.
  Eigen::Isometry3d gelInLink(int sensor) const;
  Eigen::Isometry3d objectInWorld() const;
  const ObjectMesh& object() const { return object_; }
  const ObjectCollision& collision() const { return collision_; }

 private:
  struct World;
  struct Drive {
    double effort = 0.0;
    double velocity = 0.0;
    double stiffness = 0.0;
  };
  struct Trajectory {
    std::vector<int> joints;
    std::vector<double> start;  ///< targets when it was set
    std::vector<double> times_s;
    std::vector<std::vector<double>> positions;
    double start_s = 0.0;
  };

  void resolveDrives();
  /// The object's collision, once: resets rebuild the world but reuse its (stateless) shapes.
  void makeCollision();
  void buildWorld();
  /// reset()'s work, `joints` (indices) at `positions`, after the arguments were checked.
  void restart(const Eigen::Isometry3d* object_in_world, const std::vector<int>& joints,
               const std::vector<double>& positions);
  void checkMounts();
  std::vector<int> validateNames(const std::vector<std::string>& names) const;
  double clampToLimits(int joint, double value, bool& clamped) const;
  void advanceTrajectory();
  void advanceBase();
  void moveJoints(double dt);
  void forwardKinematics();
  void placeBodies();
  void measureContacts(double dt);
  /// Adds the generalised force of `force` (world, on link `link`) at `point` to every joint
  /// that carries the link; and, when `normal_stiffness` > 0, that contact's stiffness along
  /// `normal` to the joints' contact stiffness.
  void addLoad(int link, const Eigen::Vector3d& point, const Eigen::Vector3d& force,
               const Eigen::Vector3d& normal, double normal_stiffness);

  HandSimConfig config_;
  HandDescription description_;
  std::vector<std::string> warnings_;
  std::vector<Drive> drives_;
  std::vector<std::string> actuated_names_;
  std::vector<int> actuated_;
  std::vector<int> sensor_links_;
  std::vector<SensorMountCheck> checks_;
  /// Per joint: the position, the drive's position, the target, the contacts' load and their
  /// stiffness in the joint's coordinate.
  std::vector<double> q_, drive_q_, target_, load_, contact_stiffness_;
  std::vector<double> initial_q_;
  std::vector<Eigen::Isometry3d> link_poses_;
  /// Per link: the joints from the root to it (movable only).
  std::vector<std::vector<int>> link_joints_;
  Eigen::Isometry3d base_pose_ = Eigen::Isometry3d::Identity();
  /// A base motion in progress: from, to, and its ticks done / in all.
  Eigen::Isometry3d base_from_ = Eigen::Isometry3d::Identity(),
                    base_to_ = Eigen::Isometry3d::Identity();
  int base_tick_ = 0, base_ticks_ = 0;
  Trajectory trajectory_;
  bool following_trajectory_ = false;

  ObjectMesh object_;
  Eigen::Isometry3d object_in_body_ = Eigen::Isometry3d::Identity();
  ObjectCollision collision_;
  /// The object's Bullet shape (for the floor and its inertia) is back(); any shapes before it
  /// are its convex parts. Declared before world_, whose bodies use them.
  std::vector<std::unique_ptr<btCollisionShape>> object_shapes_;
  /// What the gels touch, in the body frame: convex parts, or one capsule (a sphere: a == b).
  std::vector<ConvexPolytope> contact_parts_;
  std::optional<Capsule> contact_capsule_;
  std::unique_ptr<World> world_;
  std::vector<GelContactState> contacts_;
  std::int64_t ticks_ = 0;
};

/// Reads a hand yaml and makes the rest of a HandSimConfig from a scene yaml's object, physics
/// and gel law (loadGripperSimConfig) and the sensor's gel pad.
HandSimConfig makeHandSimConfig(const std::string& hand_yaml, const GripperSimConfig& scene);
/// The same for a hand config already read.
HandSimConfig makeHandSimConfig(HandConfig hand, const GripperSimConfig& scene);

}  // namespace norm2tex
