#pragma once
// Private to norm2tex_sim: the options TactileGripper and TactileHand share (rates, material,
// variant, beta, friction), checked and resolved the same way.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "norm2tex/common/error.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/render/object_texture.hpp"
#include "norm2tex/render/object_texture_cache.hpp"

namespace norm2tex {
namespace detail {

/// Throws Error("<what> <name> = <value> is out of range; valid: <range>") for the first of
/// `o`'s shared options out of range.
template <typename Options>
void validateTactileOptions(const Options& o, const std::string& what) {
  const auto text = [](double value) {
    std::ostringstream out;
    out << value;
    return out.str();
  };
  const auto bad = [&](const std::string& name, const std::string& value,
                       const std::string& valid) {
    throw Error(what + " " + name + " = " + value + " is out of range; valid: " + valid);
  };
  if (!(o.physics_rate_hz >= 100.0 && o.physics_rate_hz <= 100000.0)) {
    bad("physics_rate_hz", text(o.physics_rate_hz), "[100, 100000] Hz");
  }
  if (!(o.frame_rate_hz >= 1.0 && o.frame_rate_hz <= 1000.0 &&
        o.frame_rate_hz <= o.physics_rate_hz)) {
    bad("frame_rate_hz", text(o.frame_rate_hz), "[1, 1000] Hz and <= physics_rate_hz");
  }
  if (o.variant < 0) bad("variant", text(o.variant), ">= 0");
  if (!(o.beta_mm < 0.0 || o.beta_mm <= 2.0)) {
    bad("beta_mm", text(o.beta_mm), "[0, 2] mm, or < 0 for the material's");
  }
  if (!(o.friction < 0.0 || o.friction <= 5.0) || std::isnan(o.friction)) {
    bad("friction", text(o.friction), "[0, 5], or < 0 for the material's");
  }
  if (o.material_config.empty() && o.beta_mm > 0.0) {
    bad("beta_mm", text(o.beta_mm), "0 or < 0 without a material (nothing to texture)");
  }
}

/// Texture variants a simulation keeps generated when it has a cache of its own (the paper
/// rotates 24).
constexpr std::size_t kKeptVariants = 32;

/// The shared options resolved as the ROS system resolves them (contact_sim, tactile_renderer).
struct TactileSetup {
  std::optional<MaterialConfig> material;
  /// The given friction, else the material's, else `default_friction`.
  double friction = 0.0;
  /// Whole physics ticks per sensor frame, so that every frame is a physics state, and the
  /// physics rate that makes them whole.
  int ticks_per_frame = 1;
  double physics_rate_hz = 0.0;
  /// The given beta, else the material's; 0 without a material (textureless).
  double beta_mm = 0.0;
};

template <typename Options>
TactileSetup resolveTactileOptions(const Options& o, double default_friction) {
  TactileSetup setup;
  if (!o.material_config.empty()) setup.material = loadMaterialConfig(o.material_config);
  setup.friction = o.friction >= 0.0 ? o.friction
                   : setup.material  ? setup.material->friction
                                     : default_friction;
  setup.ticks_per_frame =
      std::max(1, static_cast<int>(std::lround(o.physics_rate_hz / o.frame_rate_hz)));
  setup.physics_rate_hz = setup.ticks_per_frame * o.frame_rate_hz;
  setup.beta_mm = setup.material ? (o.beta_mm >= 0.0 ? o.beta_mm : setup.material->beta_mm) : 0.0;
  return setup;
}

/// Texture variant `variant` of `material_config` (seeded `seed`) on `mesh`, from `cache` (made
/// once for every simulation sharing it). A mesh without UVs is unwrapped for its texture
/// first, in place: every renderer of the simulation then draws the unwrapped mesh.
std::shared_ptr<const ObjectTexture> objectTextureVariant(ObjectTextureCache& cache,
                                                          const std::string& material_config,
                                                          std::uint64_t seed, int variant,
                                                          std::shared_ptr<TexturedMesh>& mesh);

/// Starts generating a variant in the background (see objectTextureVariant); `mesh` has UVs.
void prefetchObjectTextureVariant(ObjectTextureCache& cache, const std::string& material_config,
                                  std::uint64_t seed, int variant,
                                  const std::shared_ptr<const TexturedMesh>& mesh);

}  // namespace detail
}  // namespace norm2tex
