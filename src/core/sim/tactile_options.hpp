#pragma once
// Private to norm2tex_sim: the options TactileGripper and TactileHand share (rates, material,
// variant, beta, friction), checked the same way.

#include <cmath>
#include <sstream>
#include <string>

#include "norm2tex/common/error.hpp"

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

}  // namespace detail
}  // namespace norm2tex
