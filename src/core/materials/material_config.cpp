#include "norm2tex/materials/material_config.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <type_traits>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/error_messages.hpp"
#include "materials/noise.hpp"
#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

const MaterialParameter& findParameter(const ProceduralMaterial& material,
                                       const std::string& name) {
  for (const MaterialParameter& p : material.parameters()) {
    if (p.name == name) return p;
  }
  material.parameter(name);  // throws the Error listing the valid names
  throw Error("unreachable");
}

std::string rangeText(const MaterialParameter& p) {
  std::ostringstream text;
  text << "[" << p.min << ", " << p.max << "]" << (p.unit.empty() ? "" : " " + p.unit);
  return text.str();
}

/// Integers inside [low, high] for integer parameters.
std::pair<double, double> integerSpan(const std::pair<double, double>& range) {
  return {std::ceil(range.first), std::floor(range.second)};
}

/// Seed of variant k's noise; distinct from the stream used for parameter draws.
std::uint64_t variantSeed(std::uint64_t seed, int variant) {
  return noise::mix64(seed ^ noise::mix64(0xA5A5A5A5ull + static_cast<std::uint64_t>(variant)));
}

}  // namespace

void validate(const MaterialConfig& config) {
  using detail::requireParameter;
  const std::unique_ptr<ProceduralMaterial> material = makeMaterial(config.name);
  requireParameter(config.beta_mm > 0.0 && config.beta_mm <= 2.0, "beta_mm", config.beta_mm,
                   "(0, 2] mm");
  requireParameter(config.friction >= 0.0 && config.friction <= 2.0, "friction", config.friction,
                   "[0, 2]");
  requireParameter(config.mm_per_texel > 0.0 && config.mm_per_texel <= 1.0, "mm_per_texel",
                   config.mm_per_texel, "(0, 1] mm");
  requireParameter(config.size >= 16 && config.size <= 16384, "size", config.size,
                   "[16, 16384] texels");
  requireParameter(config.variant_count >= 1 && config.variant_count <= 10000, "variant_count",
                   config.variant_count, "[1, 10000]");
  for (const auto& [name, value] : config.parameters) {
    try {
      material->setParameter(name, value);
    } catch (const Error& e) {
      throw Error("parameters." + name + ": " + e.what());
    }
  }
  for (const auto& [name, range] : config.variant_ranges) {
    const auto [low, high] = range;
    std::string where = "variant_ranges." + name;
    try {
      const MaterialParameter& p = findParameter(*material, name);
      std::ostringstream text;
      text << "[" << low << ", " << high << "]";
      if (!(low >= p.min && high <= p.max)) {
        throw Error(text.str() + " is outside " + config.name + "." + name + "'s valid range " +
                    rangeText(p));
      }
      if (!(low <= high)) throw Error(text.str() + " has low > high");
      if (p.integer && integerSpan(range).first > integerSpan(range).second) {
        throw Error(text.str() + " holds no integer; " + name + " takes integers in " +
                    rangeText(p));
      }
    } catch (const Error& e) {
      throw Error(where + ": " + e.what());
    }
  }
}

MaterialConfig loadMaterialConfig(const std::string& yaml_path) {
  static const char* const kKeys[] = {"material",      "beta_mm",      "range",
                                      "friction",      "mm_per_texel", "size",
                                      "variant_count", "parameters",   "variant_ranges"};
  const std::string where = "material config '" + yaml_path + "': ";
  YAML::Node root;
  try {
    root = YAML::LoadFile(yaml_path);
  } catch (const YAML::Exception& e) {
    throw Error(where + e.what());
  }
  if (!root.IsMap()) throw Error(where + "expected a map of keys at the top level");
  std::string key;  // the key being read, for error messages
  try {
    for (const auto& entry : root) {
      key = entry.first.as<std::string>();
      bool known = false;
      std::string valid;
      for (const char* k : kKeys) {
        known = known || key == k;
        valid += (valid.empty() ? "" : ", ") + std::string(k);
      }
      if (!known) throw Error("unknown key; valid: " + valid);
    }
    MaterialConfig config;
    key = "material";
    if (!root["material"]) {
      std::string names;
      for (const std::string& n : materialNames()) names += (names.empty() ? "" : ", ") + n;
      throw Error("missing; valid: " + names);
    }
    config.name = root["material"].as<std::string>();
    const auto read = [&](const char* k, auto& value) {
      key = k;
      if (root[k]) value = root[k].as<std::remove_reference_t<decltype(value)>>();
    };
    read("beta_mm", config.beta_mm);
    read("friction", config.friction);
    read("mm_per_texel", config.mm_per_texel);
    read("size", config.size);
    read("variant_count", config.variant_count);
    key = "range";
    if (root["range"]) config.range = parseHeightRange(root["range"].as<std::string>());
    key = "parameters";
    if (const YAML::Node parameters = root["parameters"]; parameters && !parameters.IsNull()) {
      if (!parameters.IsMap()) throw Error("expected a map of parameter: value");
      for (const auto& entry : parameters) {
        key = "parameters." + entry.first.as<std::string>();
        config.parameters[entry.first.as<std::string>()] = entry.second.as<double>();
      }
    }
    key = "variant_ranges";
    if (const YAML::Node ranges = root["variant_ranges"]; ranges && !ranges.IsNull()) {
      if (!ranges.IsMap()) throw Error("expected a map of parameter: [low, high]");
      for (const auto& entry : ranges) {
        key = "variant_ranges." + entry.first.as<std::string>();
        const std::vector<double> bounds = entry.second.as<std::vector<double>>();
        if (bounds.size() != 2) throw Error("expected [low, high]");
        config.variant_ranges[entry.first.as<std::string>()] = {bounds[0], bounds[1]};
      }
    }
    key.clear();  // validate() names the field itself
    validate(config);
    return config;
  } catch (const YAML::Exception& e) {
    throw Error(where + key + ": " + e.what());
  } catch (const Error& e) {
    throw Error(where + (key.empty() ? "" : key + ": ") + e.what());
  }
}

std::unique_ptr<ProceduralMaterial> makeMaterialVariant(const MaterialConfig& config, int variant,
                                                        std::uint64_t seed) {
  detail::requireParameter(variant >= 0, "variant", variant, ">= 0");
  validate(config);
  std::unique_ptr<ProceduralMaterial> material = makeMaterial(config.name);
  for (const auto& [name, value] : config.parameters) material->setParameter(name, value);
  if (variant == 0) {
    material->setSeed(seed);
    return material;
  }
  for (const auto& [name, range] : config.variant_ranges) {
    // One uniform per (seed, variant, parameter name): adding a range to the config does not
    // change the draws of the others.
    const double u = noise::unit(
        noise::hash2(noise::derive(seed, noise::hashString(name)), variant, 0x7661726961ll));
    if (findParameter(*material, name).integer) {
      const auto [low, high] = integerSpan(range);
      material->setParameter(name, std::min(high, low + std::floor(u * (high - low + 1.0))));
    } else {
      material->setParameter(
          name, std::min(range.second, range.first + u * (range.second - range.first)));
    }
  }
  material->setSeed(variantSeed(seed, variant));
  return material;
}

}  // namespace norm2tex
