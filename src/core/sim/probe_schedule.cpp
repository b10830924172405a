#include "norm2tex/sim/probe_schedule.hpp"

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

/// FNV-1a of the block's name mixed with the dataset seed: every block draws its own presses,
/// fixed across platforms.
std::uint64_t blockSeed(std::uint64_t seed, const std::string& material, int variant) {
  std::uint64_t h = 1469598103934665603ull ^ seed;
  const std::string key = material + "/" + std::to_string(variant);
  for (unsigned char c : key) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace

ProbeSchedule::ProbeSchedule(const std::vector<std::pair<std::string, int>>& materials,
                             std::uint64_t samples_per_material, int frames_per_press,
                             std::uint64_t seed, int shard, int num_shards)
    : shard_(shard), num_shards_(num_shards) {
  if (materials.empty()) throw Error("probe schedule: no material given");
  if (samples_per_material < 1) {
    throw Error("probe schedule: samples per material = 0 is not valid; valid: >= 1");
  }
  if (frames_per_press < 1) {
    throw Error("probe schedule: frames per press = " + std::to_string(frames_per_press) +
                " is not valid; valid: >= 1");
  }
  if (num_shards < 1 || shard < 0 || shard >= num_shards) {
    throw Error("probe schedule: shard " + std::to_string(shard) + " of " +
                std::to_string(num_shards) + " is not valid; valid: 0 <= shard < num_shards");
  }
  std::uint64_t number = 0;  // press number across all blocks, for the round-robin
  for (const auto& [material, variants] : materials) {
    if (variants < 1) {
      throw Error("probe schedule: material '" + material + "' has " + std::to_string(variants) +
                  " variants; valid: >= 1");
    }
    for (int v = 0; v < variants; ++v) {
      ProbeBlock block;
      block.material = material;
      block.variant = v;
      block.frames = samples_per_material / variants +
                     (static_cast<std::uint64_t>(v) < samples_per_material % variants ? 1 : 0);
      block.scenario_seed = blockSeed(seed, material, v);
      const std::uint64_t presses = (block.frames + frames_per_press - 1) / frames_per_press;
      for (std::uint64_t p = 0; p < presses; ++p, ++number) {
        if (number % num_shards != static_cast<std::uint64_t>(shard)) continue;
        ProbePress press;
        press.block = static_cast<int>(blocks_.size());
        press.press = p;
        press.frames = static_cast<int>(
            std::min<std::uint64_t>(frames_per_press, block.frames - p * frames_per_press));
        frames_ += press.frames;
        presses_.push_back(press);
      }
      blocks_.push_back(block);
    }
  }
}

}  // namespace norm2tex
