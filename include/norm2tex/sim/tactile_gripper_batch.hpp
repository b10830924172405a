#pragma once

#include <memory>
#include <vector>

#include "norm2tex/common/parallel_for.hpp"
#include "norm2tex/sim/tactile_gripper.hpp"

namespace norm2tex {

/// What a batch step does to one gripper's command before it steps. kAbsolute and kDelta have
/// the values of the message norm2tex/GripperCommand's ABSOLUTE and DELTA (the ROS layer checks
/// it at compile time), kKeep comes after them: one set of values in C++, the message and Python
/// (norm2tex/envs/commands.py).
enum class OpeningCommand {
  kAbsolute = 0,  ///< GripperSim::setOpening(value)
  kDelta = 1,     ///< GripperSim::addOpening(value) (clamped to [0, 1])
  kKeep = 2,      ///< leave the command as it is
};

/// N TactileGrippers stepped together on a fixed set of threads: all physics first (one job
/// per gripper), then every sensor's render (two jobs per gripper), so that even one gripper
/// renders its two sensors in parallel. Each gripper gives exactly what it gives alone: the
/// threads only decide where a gripper's own work runs.
///
/// The grippers share one texture cache: a material variant is generated once for all. Each
/// gripper may have its own material (options); the cache keeps 32 variants per material.
class TactileGripperBatch {
 public:
  /// One gripper per entry of `options`. `threads` as ParallelFor (0: the machine's CPUs).
  /// Throws Error as TactileGripper does, or for no options.
  TactileGripperBatch(const GripperSimConfig& scene, const SensorModel& sensor,
                      const std::vector<TactileGripperOptions>& options, int threads = 0);

  int size() const { return static_cast<int>(grippers_.size()); }
  TactileGripper& gripper(int i);
  const TactileGripper& gripper(int i) const;
  int threads() const { return pool_.threads(); }

  /// Applies each gripper's command (`values[i]`, as `modes[i]` says; sizes must equal size()),
  /// then advances every gripper by `frames` and renders its sensors. Commands are checked
  /// before anything moves: an invalid one throws Error and changes nothing.
  void step(const std::vector<OpeningCommand>& modes, const std::vector<double>& values,
            int frames = 1);

  /// Resets gripper i (TactileGripper::reset) with the given variant first (< 0: keep).
  EpisodeStart reset(int i, std::uint64_t seed, std::optional<double> height_offset_m,
                     int variant = -1);

 private:
  std::shared_ptr<ObjectTextureCache> textures_;
  std::vector<std::unique_ptr<TactileGripper>> grippers_;
  ParallelFor pool_;
};

}  // namespace norm2tex
