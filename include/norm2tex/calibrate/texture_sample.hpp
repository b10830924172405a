#pragma once

#include <cstdint>
#include <string>

#include "norm2tex/calibrate/texture_match.hpp"
#include "norm2tex/materials/material_config.hpp"

namespace norm2tex {

/// A flat sample of a procedural material: its plain square texture (config.size texels at
/// config.mm_per_texel, variant 0 with `seed`) encoded as a 16-bit normal map and baked with
/// config.range, as bakeMaterialAtlas bakes it for a mesh; beta starts at config.beta_mm.
TextureSample makeMaterialSample(const MaterialConfig& config, std::uint64_t seed = 0);

/// A flat sample of a normal map file whose texels are `mm_per_texel` mm on the surface: its
/// largest centred square (the face repeats one period in u and v alike), baked as norm2tex_bake
/// bakes a normal map (symmetric range, relief longer than 2 mm removed). Throws Error naming the
/// file when it cannot be read, or for mm_per_texel outside (0, 1] or beta_mm outside (0, 2].
TextureSample makeNormalMapSample(const std::string& path, double mm_per_texel, double beta_mm);

}  // namespace norm2tex
