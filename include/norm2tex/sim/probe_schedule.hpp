#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace norm2tex {

/// One texture of a probe dataset: a material variant and how many frames it gets.
struct ProbeBlock {
  std::string material;
  int variant = 0;
  std::uint64_t frames = 0;      ///< frames of this block in the whole (unsharded) dataset
  std::uint64_t scenario_seed = 0;  ///< ProbeScenario seed of this block (from the dataset seed)
};

/// One press of this shard: which block, which press of the block, how many frames of it.
struct ProbePress {
  int block = 0;
  std::uint64_t press = 0;  ///< press index within the block (ProbeScenario::press)
  int frames = 0;           ///< frames recorded of it: frames_per_press, fewer for a block's last
};

/// The paper's collection plan: `samples_per_material` frames per material, spread evenly over
/// its variants (the first samples % variants variants get one more), in presses of
/// `frames_per_press` frames (a press and its slides; a block's last press may be cut short).
/// Sharding: the presses, numbered across all blocks in order, go round-robin to `num_shards`
/// shards; shard k holds those with number % num_shards == k. So shards are disjoint, their
/// union is the unsharded dataset press for press, and their sizes differ by at most one press
/// per block.
class ProbeSchedule {
 public:
  /// `materials`: (name, variant count) in order. Throws Error for an empty list, a variant
  /// count < 1, samples < 1, frames_per_press < 1, num_shards < 1 or shard outside
  /// [0, num_shards).
  ProbeSchedule(const std::vector<std::pair<std::string, int>>& materials,
                std::uint64_t samples_per_material, int frames_per_press, std::uint64_t seed,
                int shard = 0, int num_shards = 1);

  const std::vector<ProbeBlock>& blocks() const { return blocks_; }
  /// This shard's presses, in order.
  const std::vector<ProbePress>& presses() const { return presses_; }
  /// Frames this shard records (sum of its presses' frames).
  std::uint64_t frames() const { return frames_; }
  int shard() const { return shard_; }
  int numShards() const { return num_shards_; }

 private:
  std::vector<ProbeBlock> blocks_;
  std::vector<ProbePress> presses_;
  std::uint64_t frames_ = 0;
  int shard_ = 0, num_shards_ = 1;
};

}  // namespace norm2tex
