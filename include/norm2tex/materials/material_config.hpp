#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "norm2tex/materials/procedural_material.hpp"
#include "norm2tex/texture/height_range.hpp"

namespace norm2tex {

/// One material of the texture library: which procedural material, how its texture enters the
/// simulation, and how its variants are drawn (config/materials/<name>.yaml).
struct MaterialConfig {
  std::string name;      ///< material class, one of materialNames()
  double beta_mm = 0.1;  ///< texture depth: H_final = H_sensor + beta H_local
  HeightRange range = HeightRange::kSymmetric;  ///< normalisation range of H_global
  double friction = 0.5;                        ///< Coulomb friction coefficient for the physics
  double mm_per_texel = 0.05;  ///< texture resolution: the largest texel, mm on the surface
  /// Texture size, texels (square): a flat texture's, and the largest atlas on a mesh (see
  /// materialAtlasSize).
  int size = 1024;
  std::map<std::string, double> parameters;  ///< overrides of the material's defaults
  /// Per parameter: [low, high] from which variants draw it uniformly (integers for integer
  /// parameters). Must lie inside the parameter's valid range.
  std::map<std::string, std::pair<double, double>> variant_ranges;
  int variant_count = 24;  ///< the paper used 24 variants per material
};

/// Throws Error naming the field (and for parameters the valid names or range) when the config
/// is not usable: unknown material, beta_mm outside (0, 2] mm, friction outside [0, 2],
/// mm_per_texel outside (0, 1] mm, size outside [16, 16384], variant_count outside
/// [1, 10000], unknown parameter names, values or variant ranges outside the parameter ranges,
/// low > high, or an integer parameter's range holding no integer.
void validate(const MaterialConfig& config);

/// Reads a material yaml (keys: material, beta_mm, range, friction, mm_per_texel, size,
/// variant_count, parameters, variant_ranges; all but material optional) and validates it.
/// Throws Error naming the file and the key at fault; unknown keys are errors (typos would
/// otherwise be silently ignored).
MaterialConfig loadMaterialConfig(const std::string& yaml_path);

/// The material with the config's parameters applied and its seed set. Variant 0 is the
/// config's own values with seed `seed`. Variant k >= 1 draws every parameter of
/// variant_ranges uniformly within its range, reproducibly from (seed, k, parameter name), and
/// gets its own noise seed derived from (seed, k), so variants differ even without ranges.
/// Any k >= 0 is allowed (variant_count is what a generator is meant to produce). Throws Error
/// for k < 0 or an invalid config.
std::unique_ptr<ProceduralMaterial> makeMaterialVariant(const MaterialConfig& config, int variant,
                                                        std::uint64_t seed);

}  // namespace norm2tex
