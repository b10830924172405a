#include "norm2tex/sim/gripper_sim.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "norm2tex/common/error.hpp"
#include "norm2tex/sim/hand_sim.hpp"
#include "sim/parallel_gripper_files.hpp"

namespace norm2tex {
namespace {

// The open gripper must clear the object by this much on each side.
constexpr double kSeatClearance = 1e-3;
// After the fingers reach the grasp command, the contact settles this long before gravity.
constexpr double kGraspHoldS = 0.1;
// An object's side must overlap the gel pads by this much (height) at a height offset reset()
// accepts.
constexpr double kMinPadOverlap = 1e-3;
// The built-in hand (config/hands/parallel_gripper.urdf): the left finger's joint is the
// drive's, the right finger's mimics it; its sensors are the left gel's, then the right's.
const char* const kFingerJoint = "finger_left_joint";
const char* const kMimicJoint = "finger_right_joint";
const char* const kBuiltInUrdf = "config/hands/parallel_gripper.urdf (built in)";
const char* const kBuiltInYaml = "config/hands/parallel_gripper.yaml (built in)";

// Uniform in [0, 1) from a 64-bit engine, the same on every platform
// (std::uniform_real_distribution is not specified bit for bit).
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// The built-in hand's URDF with the scene's stroke: each finger's joint (its gel surface's
// distance from the centre plane) between half the closed and half the open gap.
HandDescription builtInHandDescription(const GripperOptions& gripper) {
  // No meshes to find: the gels are the hand's only geometry.
  PackagePaths no_packages;
  no_packages.use_ros_package_path = false;
  HandDescription description =
      parseHandDescription(detail::kParallelGripperUrdf, kBuiltInUrdf, ".", no_packages);
  for (const char* name : {kFingerJoint, kMimicJoint}) {
    const int j = description.jointIndex(name);
    if (j < 0) {
      throw Error(std::string(kBuiltInUrdf) + " has no joint '" + name +
                  "' (a bug: please report it)");
    }
    description.joints[j].lower = gripper.min_gap_m / 2.0;
    description.joints[j].upper = gripper.max_gap_m / 2.0;
  }
  return description;
}

// The built-in hand holding the scene's object, with the scene's gripper, physics and gels.
HandSimConfig builtInHand(const GripperSimConfig& scene) {
  const GripperOptions& g = scene.gripper;
  HandSimConfig config;
  config.hand = parseHandConfig(detail::kParallelGripperYaml, kBuiltInYaml, ".");
  config.hand.urdf_path = kBuiltInUrdf;  // given as a description: its name in messages
  // The yaml mounts each DIGIT square on its finger, a quarter turn about z, which double
  // precision rounds (cos(pi / 2) = 6e-17): the gels face exactly along the grip axis with the
  // exact rotation (GripperSim::gelInFinger). A gripper on the same trajectory as before it ran
  // on HandSim, bit for bit (as long as its drive stays below its force limit).
  for (const Finger finger : {Finger::kLeft, Finger::kRight}) {
    SensorMount& mount = config.hand.sensors.at(static_cast<int>(finger));
    const Eigen::Isometry3d square = GripperSim::gelInFinger(finger) * gelInDigit().inverse();
    if (!mount.digit_in_link.isApprox(square, 1e-12)) {
      throw Error(std::string(kBuiltInYaml) + ": sensor '" + mount.name +
                  "' is not mounted as the built-in gripper's gel (a bug: please report it)");
    }
    mount.digit_in_link = square;
  }
  config.hand.base_pose = Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, g.base_height_m));
  // One drive moves both fingers (a servo through a rack or linkage): the mimic finger's load
  // adds to its own, so the scene's force per gel is half its effort, and its stiffness per
  // finger (a finger sits back by its gel's force / k) is half the drive's (which sits back by
  // the sum of both / its stiffness).
  JointDriveOptions& drive = config.hand.drives[kFingerJoint];
  drive.effort = 2.0 * g.max_force_n;
  drive.velocity = g.max_speed_m_s;
  drive.stiffness = 2.0 * g.stiffness_n_per_m;
  config.hand.initial_positions = {{kFingerJoint, g.max_gap_m / 2.0}};
  config.hand.gripper_joints = {kFingerJoint};
  config.hand.gripper_closed = {g.min_gap_m / 2.0};
  config.hand.gripper_open = {g.max_gap_m / 2.0};
  HandSimConfig sim = makeHandSimConfig(std::move(config.hand), scene);
  // Where the constructor seats it once the mesh (loaded by HandSim) tells its centre.
  sim.object_pose = sim.hand.base_pose;
  return sim;
}

}  // namespace

GripperSim::GripperSim(const GripperSimConfig& config) : config_(config) {
  validate(config_);
  if (hasOwnHand()) {
    useOwnHand();
  } else {
    hand_ =
        std::make_unique<HandSim>(builtInHand(config_), builtInHandDescription(config_.gripper));
    finger_joint_ = hand_->description().jointIndex(kFingerJoint);
    gripper_joints_ = {kFingerJoint};
    gripper_joint_indices_ = {finger_joint_};
    grip_in_world_ = Eigen::Translation3d(0.0, 0.0, config_.gripper.base_height_m);
    pad_half_height_m_ = config_.gel_height_m / 2;
  }
  // What the stroke is called in messages: the scene's keys, or the hand's yaml.
  const std::string open_gap = hasOwnHand()
                                   ? "the hand's open gap (" + config_.gripper.hand_yaml + ")"
                                   : std::string("gripper.max_gap_mm");
  const std::string closed_gap = hasOwnHand()
                                     ? "the hand's closed gap (" + config_.gripper.hand_yaml + ")"
                                     : std::string("gripper.min_gap_mm");
  if (objectWidthM() + 2 * kSeatClearance > config_.gripper.max_gap_m) {
    std::ostringstream message;
    message << "object '" << config_.object.mesh << "' is " << objectWidthM() * 1e3
            << " mm wide along the grip axis: more than " << open_gap << " = "
            << config_.gripper.max_gap_m * 1e3 << " mm minus 2 mm of clearance";
    throw Error(message.str());
  }
  const EpisodeOptions& e = config_.episode;
  const double grip_depth =
      e.grasp_force_n > 0 ? config_.gel_law.indentation(e.grasp_force_n) : e.grasp_indentation_m;
  const double grip_reach = grip_depth + drivePreload(grip_depth);
  if (e.grasp_opening < 0 && objectWidthM() - 2 * grip_reach < config_.gripper.min_gap_m) {
    std::ostringstream message;
    message << "object '" << config_.object.mesh << "' is " << objectWidthM() * 1e3
            << " mm wide along the grip axis: the closed gripper (" << closed_gap << " = "
            << config_.gripper.min_gap_m * 1e3 << " mm) cannot indent both gels " << grip_depth * 1e3
            << " mm into it";
    if (grip_reach > grip_depth) {
      message << " (its drive would have to close " << (grip_reach - grip_depth) * 1e3
              << " mm further on each side: gripper.stiffness_n_per_mm)";
    }
    throw Error(message.str());
  }
  findHeightOffsetRange();
  // The object at the lowest offset, the fingers open.
  hand_->reset(seatedObjectPose(height_offset_range_.first), gripper_joints_,
               openJointPositions());
  command(1.0);
}

void GripperSim::useOwnHand() {
  const std::string& yaml = config_.gripper.hand_yaml;
  HandConfig hand = loadHandConfig(yaml);
  const auto refuse = [&](const std::string& why) {
    throw Error("hand '" + yaml + "' as a gripper: " + why);
  };
  if (hand.sensors.size() != 2) {
    refuse("a gripper's hand carries two DIGITs (sensors: the left finger's, then the right's); "
           "it has " + std::to_string(hand.sensors.size()));
  }
  if (hand.gripper_joints.empty()) {
    refuse("its yaml names no gripper.joints (the joints that open and close it, with their "
           "positions closed and open)");
  }
  gripper_joints_ = hand.gripper_joints;
  HandSimConfig sim = makeHandSimConfig(std::move(hand), config_);
  sim.object_pose = sim.hand.base_pose;  // seated below, once the hand is measured
  hand_ = std::make_unique<HandSim>(sim);
  const HandDescription& description = hand_->description();
  for (const std::string& name : gripper_joints_) {
    const int j = description.jointIndex(name);
    if (description.joints[j].type != HandJoint::Type::kPrismatic) {
      refuse("gripper joint '" + name + "' is not prismatic: GripperSim's episodes are a " +
             "parallel gripper's (HandEnv drives any hand)");
    }
    gripper_joint_indices_.push_back(j);
  }

  // The gels' centres and normals at a normalised opening, the object where it is.
  struct Gels {
    Eigen::Vector3d left, right, left_normal, right_normal;
  };
  const Eigen::Isometry3d object = hand_->objectInWorld();
  const auto gelsAt = [&](double opening) {
    hand_->reset(object, gripper_joints_, jointTargets(opening));
    const Eigen::Isometry3d l = hand_->gelInWorld(0), r = hand_->gelInWorld(1);
    return Gels{l.translation(), r.translation(), l.linear().col(2), r.linear().col(2)};
  };
  const Gels open = gelsAt(1.0), closed = gelsAt(0.0), half = gelsAt(0.5);
  const Eigen::Vector3d across = open.left - open.right;
  if (across.norm() < 1e-3) refuse("its open gels are less than 1 mm apart (gripper.open)");
  const Eigen::Vector3d y = across.normalized();
  const auto degrees = [](double cosine) {
    return std::acos(std::clamp(cosine, -1.0, 1.0)) * 180.0 / M_PI;
  };
  // Each gel's normal (its +z, out of the gel) must point at the other finger.
  constexpr double kMaxTiltDeg = 10.0;
  const double left_tilt = degrees(-open.left_normal.dot(y));
  const double right_tilt = degrees(open.right_normal.dot(y));
  if (left_tilt > kMaxTiltDeg || right_tilt > kMaxTiltDeg) {
    std::ostringstream message;
    message << "its gels do not face each other across the fingers: the left gel's normal is "
            << left_tilt << " degrees and the right's " << right_tilt
            << " degrees from the line to the other gel (at most " << kMaxTiltDeg
            << "; sensors: the left finger's first, and their gel: mounts)";
    refuse(message.str());
  }
  const auto gap = [&](const Gels& g) { return (g.left - g.right).dot(y); };
  const auto middle = [](const Gels& g) -> Eigen::Vector3d { return (g.left + g.right) / 2; };
  // Closing must move the gels towards each other along that line, both alike, in proportion.
  constexpr double kMaxDriftM = 0.5e-3;
  const Eigen::Vector3d closed_across = closed.left - closed.right;
  const double drift = std::max((middle(closed) - middle(open)).norm(),
                                (closed_across - closed_across.dot(y) * y).norm());
  const double bend = std::abs(gap(half) - (gap(closed) + gap(open)) / 2);
  if (drift > kMaxDriftM || bend > kMaxDriftM) {
    std::ostringstream message;
    message << "closing does not move its gels straight towards each other, centred (their "
            << "midpoint or their line moves " << drift * 1e3 << " mm, the gap at half opening "
            << "is " << bend * 1e3 << " mm off the mean of closed and open; at most "
            << kMaxDriftM * 1e3 << " mm): GripperSim's episodes are a parallel gripper's";
    refuse(message.str());
  }
  if (gap(closed) < 0.0) {
    std::ostringstream message;
    message << "at gripper.closed its gels overlap by " << -gap(closed) * 1e3
            << " mm (close less: the gel surfaces meet at gap 0)";
    refuse(message.str());
  }
  // z: the world's up made square to the grip axis.
  Eigen::Vector3d z = Eigen::Vector3d::UnitZ() - y.z() * y;
  if (z.norm() < 0.5) {
    std::ostringstream message;
    message << "its grip axis is " << degrees(std::abs(y.z()))
            << " degrees from vertical (at least 30 needed): the episodes hold the object "
            << "against gravity between the gels";
    refuse(message.str());
  }
  z.normalize();
  grip_in_world_.linear() << y.cross(z), y, z;
  grip_in_world_.translation() = middle(open);
  // How far each pad reaches up and down across the grip axis; the lower of the two.
  pad_half_height_m_ = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 2; ++i) {
    const Eigen::Matrix3d r = hand_->gelInWorld(i).linear();
    pad_half_height_m_ = std::min(pad_half_height_m_,
                                  (std::abs(r.col(0).dot(z)) * config_.gel_width_m +
                                   std::abs(r.col(1).dot(z)) * config_.gel_height_m) / 2);
  }

  // The gripper section: the hand's. Force, speed and stiffness per finger: a drive that moves
  // both fingers (one joint, the other mimicking it) counts half of its effort and stiffness.
  GripperOptions& g = config_.gripper;
  const double fingers_per_drive = gripper_joints_.size() == 1 ? 2.0 : 1.0;
  g.min_gap_m = gap(closed);
  g.max_gap_m = gap(open);
  g.base_height_m = grip_in_world_.translation().z();
  g.max_force_n = std::numeric_limits<double>::infinity();
  g.max_speed_m_s = std::numeric_limits<double>::infinity();
  g.stiffness_n_per_m = std::numeric_limits<double>::infinity();
  for (const int j : gripper_joint_indices_) {
    g.max_force_n = std::min(g.max_force_n, hand_->jointEffort(j) / fingers_per_drive);
    g.max_speed_m_s = std::min(g.max_speed_m_s, hand_->jointVelocity(j));
    g.stiffness_n_per_m = std::min(g.stiffness_n_per_m, hand_->jointStiffness(j) / fingers_per_drive);
  }
  // (validate()'s ranges for these are the built-in gripper's scene keys; a hand's come from its
  // URDF and yaml, which HandSim has checked. What the episode asks of the drive is checked.)
  if (config_.episode.grasp_force_n >= g.max_force_n) {
    std::ostringstream message;
    message << "episode.grasp_force_n = " << config_.episode.grasp_force_n
            << " N is not below its drives' force per finger, " << g.max_force_n << " N";
    refuse(message.str());
  }
}

std::vector<double> GripperSim::jointTargets(double opening) const {
  // The built-in gripper: the finger joint at half the gap (the scene's stroke).
  if (!hasOwnHand()) return {gapForOpening(opening) / 2.0};
  return hand_->gripperJointPositions(opening);
}

std::vector<double> GripperSim::openJointPositions() const {
  return hasOwnHand() ? hand_->gripperJointPositions(1.0)
                      : std::vector<double>{config_.gripper.max_gap_m / 2.0};
}

int GripperSim::ticksToArrive() const {
  const std::vector<double> targets = jointTargets(command_);
  int ticks = 0;
  for (size_t i = 0; i < targets.size(); ++i) {
    const int j = gripper_joint_indices_[i];
    const double travel = std::abs(hand_->driveJointPositions()[j] - targets[i]);
    ticks = std::max(ticks, static_cast<int>(std::ceil(travel / hand_->jointVelocity(j) /
                                                       tickSeconds())));
  }
  return ticks;
}

GripperSim::~GripperSim() = default;

void GripperSim::findHeightOffsetRange() {
  // The gels meet the object within their reach (the law's deepest point) of its extent along
  // the grip axis: both sides' bands must overlap the pads' height, or no grasp can be made.
  const EpisodeOptions& e = config_.episode;
  const double reach = config_.gel_law.points().back().first;
  const double pad = pad_half_height_m_;
  const ObjectMesh& object = hand_->object();
  const Eigen::AlignedBox3d bounds = object.mesh.bounds().cast<double>();
  const Eigen::Vector3d centre = object.mesh.bounds().center().cast<double>();
  double low = e.height_offset_low_m, high = e.height_offset_high_m;
  std::ostringstream sides;
  for (double side : {1.0, -1.0}) {
    const double extreme = side > 0 ? bounds.max().y() : bounds.min().y();
    double z_lo = std::numeric_limits<double>::infinity(), z_hi = -z_lo;
    for (const Eigen::Vector3f& v : object.mesh.vertices()) {
      if (side * (extreme - v.y()) <= reach) {
        z_lo = std::min(z_lo, v.z() - centre.z());
        z_hi = std::max(z_hi, v.z() - centre.z());
      }
    }
    // At offset o its side spans o + [z_lo, z_hi]; the pads [-pad, pad]; they must overlap by
    // kMinPadOverlap, or the gels would meet it only at their very rim.
    low = std::max(low, -pad - z_hi + kMinPadOverlap);
    high = std::min(high, pad - z_lo - kMinPadOverlap);
    sides << (side > 0 ? "" : ", ") << (side > 0 ? "+y" : "-y") << " side " << z_lo * 1e3 << " to "
          << z_hi * 1e3;
  }
  if (low > high) {
    std::ostringstream message;
    message << "object '" << config_.object.mesh
            << "' cannot be gripped at any height offset of episode.height_offset_mm ["
            << e.height_offset_low_m * 1e3 << ", " << e.height_offset_high_m * 1e3 << "]: within "
            << reach * 1e3 << " mm of its extent along the grip axis its sides span"
            << " z = " << sides.str() << " mm about its centre, the gel pads +-" << pad * 1e3
            << " mm (with " << kMinPadOverlap * 1e3 << " mm of overlap)";
    throw Error(message.str());
  }
  height_offset_range_ = {low, high};
}

double GripperSim::drivePreload(double depth) const {
  const double k = config_.gripper.stiffness_n_per_m;
  return k > 0.0 ? config_.gel_law.force(depth) / k : 0.0;
}

double GripperSim::gapForOpening(double opening) const {
  const GripperOptions& g = config_.gripper;
  return g.min_gap_m + opening * (g.max_gap_m - g.min_gap_m);
}

double GripperSim::opening() const {
  const GripperOptions& g = config_.gripper;
  return (2.0 * fingerPosition() - g.min_gap_m) / (g.max_gap_m - g.min_gap_m);
}

double GripperSim::fingerPosition() const {
  if (!hasOwnHand()) return hand_->jointPositions()[finger_joint_];
  return (hand_->gelInWorld(0).translation() - hand_->gelInWorld(1).translation())
             .dot(grip_in_world_.linear().col(1)) / 2.0;
}

void GripperSim::setOpening(double opening) {
  if (!(opening >= 0.0 && opening <= 1.0)) {
    std::ostringstream message;
    message << "gripper opening " << opening << " is out of range; valid: [0, 1] (0 = closed)";
    throw Error(message.str());
  }
  command(opening);
}

void GripperSim::addOpening(double delta) {
  if (!(std::abs(delta) <= 1.0)) {
    std::ostringstream message;
    message << "gripper opening delta " << delta << " is out of range; valid: [-1, 1]";
    throw Error(message.str());
  }
  command(std::clamp(command_ + delta, 0.0, 1.0));
}

void GripperSim::command(double opening) {
  command_ = opening;
  // Target positions outside the joint's limits are clamped: gapForOpening(1) / 2 may round a
  // hair above max_gap / 2.
  hand_->setJointTargets(gripper_joints_, jointTargets(opening));
}

Eigen::Isometry3d GripperSim::baseInWorld() const {
  if (hasOwnHand()) return hand_->basePose();
  return Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, config_.gripper.base_height_m));
}

Eigen::Isometry3d GripperSim::fingerInBase(Finger finger) const {
  if (hasOwnHand()) {
    const int sensor = static_cast<int>(finger);
    const int link = hand_->description().linkIndex(hand_->sensor(sensor).link);
    return hand_->basePose().inverse() * hand_->linkInWorld(link);
  }
  const double side = finger == Finger::kLeft ? 1.0 : -1.0;
  return Eigen::Isometry3d(Eigen::Translation3d(0.0, side * fingerPosition(), 0.0));
}

Eigen::Isometry3d GripperSim::gelInFinger(Finger finger) {
  // Columns: the gel's x (image right), y (image down = world -z), z (towards the other finger).
  Eigen::Matrix3d r;
  if (finger == Finger::kLeft) {
    r << -1, 0, 0,  //
        0, 0, -1,   //
        0, -1, 0;
  } else {
    r << 1, 0, 0,  //
        0, 0, 1,   //
        0, -1, 0;
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = r;
  return pose;
}

Eigen::Isometry3d GripperSim::gelInFingerFrame(Finger finger) const {
  return hasOwnHand() ? hand_->gelInLink(static_cast<int>(finger)) : gelInFinger(finger);
}

Eigen::Isometry3d GripperSim::gelInWorld(Finger finger) const {
  // The hand's: its link's pose, then the DIGIT's mount in parallel_gripper.yaml (its rotation
  // is gelInFinger's to within 1e-16, the sine of a right angle in double precision).
  return hand_->gelInWorld(static_cast<int>(finger));
}

Eigen::Isometry3d GripperSim::objectInWorld() const { return hand_->objectInWorld(); }

const GelContactState& GripperSim::contact(Finger finger) const {
  return hand_->contact(static_cast<int>(finger));
}

std::int64_t GripperSim::ticks() const { return hand_->ticks(); }

const ObjectMesh& GripperSim::object() const { return hand_->object(); }

const ObjectCollision& GripperSim::collision() const { return hand_->collision(); }

double GripperSim::objectWidthM() const {
  return static_cast<double>(hand_->object().mesh.bounds().sizes().y());
}

Eigen::Isometry3d GripperSim::seatedObjectPose(double offset_m) const {
  const Eigen::Vector3d centre = hand_->object().mesh.bounds().center().cast<double>();
  // The built-in gripper's grip frame is a translation: (0, 0, base_height + offset) exactly.
  const Eigen::Isometry3d body = grip_in_world_ * Eigen::Translation3d(0.0, 0.0, offset_m);
  return body * Eigen::Translation3d(-centre);
}

void GripperSim::step(int ticks) {
  // Dropped: free of both gels and below their lower edge (in the grip frame), at the end of a
  // tick.
  const Eigen::Isometry3d world_in_grip = grip_in_world_.inverse();
  for (int t = 0; t < ticks; ++t) {
    hand_->step(1);
    if (!contact(Finger::kLeft).in_contact && !contact(Finger::kRight).in_contact &&
        (world_in_grip * objectInWorld().translation()).z() < -pad_half_height_m_) {
      dropped_ = true;
    }
  }
}


double GripperSim::closeOnTheObject(double offset_m) {
  const EpisodeOptions& e = config_.episode;
  const GripperOptions& g = config_.gripper;
  const auto openingForGap = [&](double gap) {
    return std::clamp((gap - g.min_gap_m) / (g.max_gap_m - g.min_gap_m), 0.0, 1.0);
  };
  if (e.grasp_opening >= 0.0) {
    command(e.grasp_opening);
    step(ticksToArrive());
    return command_;
  }
  // Close until both gels touch. An object that has not touched both by the time the gap is
  // narrower than its width minus the gel law's deepest point on each side never will: its
  // sides miss the pads at this height.
  const double deepest_law_point = config_.gel_law.points().back().first;
  command(openingForGap(objectWidthM() - 2 * deepest_law_point));
  const int limit = ticksToArrive() + 1;
  const GelContactState& left = contact(Finger::kLeft);
  const GelContactState& right = contact(Finger::kRight);
  for (int t = 0; !(left.in_contact && right.in_contact); ++t) {
    if (t > limit) {
      std::ostringstream message;
      message << "the object does not reach both gel pads at height offset " << offset_m * 1e3
              << " mm: its sides miss the " << config_.gel_width_m * 1e3 << " x "
              << config_.gel_height_m * 1e3
              << " mm pads there (choose a smaller episode.height_offset_mm)";
      throw Error(message.str());
    }
    step(1);
  }
  // Then on to the grip, measured on the object's surface: its width between the gels is the gap
  // plus what each gel is already indented.
  const double depth =
      e.grasp_force_n > 0.0 ? config_.gel_law.indentation(e.grasp_force_n) : e.grasp_indentation_m;
  const double width = 2.0 * fingerPosition() + left.penetration_m + right.penetration_m;
  // A compliant drive must go further by the deflection the grip's force causes.
  command(openingForGap(width - 2.0 * (depth + drivePreload(depth))));
  step(ticksToArrive());
  return command_;
}

EpisodeStart GripperSim::reset(std::uint64_t seed, std::optional<double> height_offset_m) {
  const EpisodeOptions& e = config_.episode;
  std::mt19937_64 rng(seed);
  const auto [low, high] = height_offset_range_;
  const double offset = height_offset_m ? *height_offset_m : low + uniform01(rng) * (high - low);
  // Outside the scene's range the grasp is not the scene's (too high: the object barely touches
  // the gels; below: it tumbles), so a given offset is refused rather than clamped.
  if (!(offset >= e.height_offset_low_m && offset <= e.height_offset_high_m)) {
    std::ostringstream message;
    message << "height offset " << offset << " m is out of the scene's range; valid: ["
            << e.height_offset_low_m << ", " << e.height_offset_high_m
            << "] m (episode.height_offset_mm)";
    throw Error(message.str());
  }
  if (!(offset >= low && offset <= high)) {
    std::ostringstream message;
    message << "height offset " << offset << " m: the object's sides miss the gel pads there; "
            << "valid for this object: [" << low << ", " << high << "] m";
    throw Error(message.str());
  }
  EpisodeStart start;
  start.seed = seed;
  start.height_offset_m = offset;
  const GripperOptions& g = config_.gripper;

  // Seat the object, centred on its extent along the grip axis, between gels opened
  // kSeatClearance wider than it on each side, without gravity on it.
  dropped_ = false;
  const auto seat = [&] {
    const double opening = std::clamp(
        (objectWidthM() + 2 * kSeatClearance - g.min_gap_m) / (g.max_gap_m - g.min_gap_m), 0.0,
        1.0);
    hand_->reset(seatedObjectPose(offset), gripper_joints_, jointTargets(opening));
    command(opening);
  };
  seat();
  for (int i = 0; i < 2; ++i) {
    if (hand_->objectReachesIntoGel(i))
      throw Error("the seated object overlaps a gel (a bug: please report it)");
  }
  hand_->setObjectGravity(false);
  try {
    start.grasp_opening = closeOnTheObject(offset);
  } catch (const Error&) {
    seat();  // open again, the object at rest between the gels
    throw;
  }
  // Hold, still weightless, until the contacts settle; then gravity.
  step(static_cast<int>(std::ceil(kGraspHoldS / tickSeconds())));
  hand_->setObjectGravity(true);
  step(static_cast<int>(std::ceil(e.settle_s / tickSeconds())));
  start.episode = ++episode_;
  return start;
}

}  // namespace norm2tex
