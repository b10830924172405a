#include "norm2tex/render/sensor_model.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>
#include <opencv2/core.hpp>

#include "common/error_messages.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/render/digit_shader_response.hpp"
#include "norm2tex/render/synthetic_background.hpp"

namespace norm2tex {
namespace {

// Real DIGIT presses brighten blue below the contact, green on its left (slightly up) and red
// at its upper right, on every unit measured. The analytic model lights the side of a press
// facing an LED, so red sits at 30 degrees above the right, green at 30 degrees above the left
// and blue below (TACTO's 20 mm ring, with red and green swapped to match real units).
std::array<LedModel, 3> defaultLeds() {
  return {LedModel{"red", {17.32, -10.0, -3.0}, {0.0, 0.0, 1.0}, 1.0},
          LedModel{"green", {-17.32, -10.0, -3.0}, {0.0, 1.0, 0.0}, 1.0},
          LedModel{"blue", {0.0, 20.0, -3.0}, {1.0, 0.0, 0.0}, 1.0}};
}

const char* const kChannelNames[3] = {"blue", "green", "red"};

// Every key a sensor yaml may hold, by section ("" = top level): anything else is a typo.
const std::set<std::string>& allowedKeys(const std::string& section) {
  static const std::map<std::string, std::set<std::string>> keys = {
      {"",
       {"preset", "image", "gel", "camera", "leds", "shading", "noise", "background_image",
        "synthetic_background", "gel_model", "conformity", "markers", "shear"}},
      {"image", {"rows", "cols", "mm_per_pixel"}},
      {"gel", {"thickness_mm", "curvature_radius_mm", "pad_width_mm", "pad_height_mm"}},
      {"camera", {"fx", "fy", "cx", "cy"}},
      {"leds[]", {"name", "position_mm", "color_bgr", "intensity"}},
      {"shading", {"model", "gain", "shadow_sigma_mm", "slope_saturation", "response"}},
      {"shading.response", {"blue", "green", "red"}},
      {"noise",
       {"sigma_bgr", "neighbour_correlation", "correlation_bg", "correlation_gr", "correlation_br",
        "on_real_background"}},
      {"gel_model", {"pyramid_sigmas_mm", "core_fraction", "final_sigma_mm"}},
      {"conformity", {"enabled", "contact_modulus_mpa", "coating_length_mm"}},
      {"markers",
       {"enabled", "rows", "cols", "pitch_mm", "dot_diameter_mm", "darkness", "blur_mm",
        "jitter_mm", "seed", "offset_mm"}},
      {"shear", {"shear_modulus_mpa", "friction"}},
      {"synthetic_background", {"base_bgr", "vignette_strength", "vignette_power", "glows"}},
      {"synthetic_background.glows[]", {"centre_uv", "sigma_uv", "angle_rad", "color_bgr"}},
  };
  return keys.at(section);
}

std::string joined(const std::set<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

// Throws Error naming the first key of `node` (a map) not allowed in `section`.
void rejectUnknownKeys(const YAML::Node& node, const std::string& section) {
  if (!node) return;
  const std::string where = section.empty() ? "" : section + ".";
  if (!node.IsMap()) throw Error((section.empty() ? "the file" : section) + " must be a map");
  const std::set<std::string>& allowed = allowedKeys(section);
  for (const auto& entry : node) {
    const std::string key = entry.first.as<std::string>();
    if (allowed.count(key) == 0) {
      throw Error("unknown key '" + where + key + "'; valid keys" +
                  (section.empty() ? "" : " in " + section) + ": " + joined(allowed));
    }
  }
}

template <typename T>
void read(const YAML::Node& node, const char* key, T& value) {
  if (node && node[key]) value = node[key].as<T>();
}

cv::Vec3d readVec3(const YAML::Node& node, const std::string& key) {
  const std::vector<double> values = node.as<std::vector<double>>();
  if (values.size() != 3)
    throw Error(key + " needs 3 numbers, got " + std::to_string(values.size()));
  return {values[0], values[1], values[2]};
}

ShadingKind parseShadingKind(const std::string& name) {
  if (name == "calibrated") return ShadingKind::kCalibrated;
  if (name == "analytic_leds") return ShadingKind::kAnalyticLeds;
  throw Error("shading.model = '" + name + "' is not valid; valid: calibrated, analytic_leds");
}

void readShading(const YAML::Node& node, ShadingOptions& shading) {
  if (!node) return;
  rejectUnknownKeys(node, "shading");
  std::string kind = shadingKindName(shading.kind);
  read(node, "model", kind);
  shading.kind = parseShadingKind(kind);
  read(node, "gain", shading.gain);
  read(node, "shadow_sigma_mm", shading.shadow_sigma_mm);
  read(node, "slope_saturation", shading.slope_saturation);
  // A response belongs with the saturation it was fitted with: one given without it was fitted
  // on the slopes themselves (every calibrated yaml written before the option existed).
  if (node["response"] && !node["slope_saturation"]) shading.slope_saturation = 0.0;
  if (const YAML::Node response = node["response"]) {
    rejectUnknownKeys(response, "shading.response");
    for (int k = 0; k < 3; ++k) {
      if (!response[kChannelNames[k]]) continue;
      const std::vector<double> values = response[kChannelNames[k]].as<std::vector<double>>();
      if (values.size() != static_cast<size_t>(kShadingFeatureCount)) {
        throw Error(std::string("shading.response.") + kChannelNames[k] + " needs " +
                    std::to_string(kShadingFeatureCount) + " numbers (" + shadingFeatureNames() +
                    "), got " + std::to_string(values.size()));
      }
      std::copy(values.begin(), values.end(), shading.response_bgr[k].begin());
    }
  }
}

void readNoise(const YAML::Node& node, NoiseOptions& noise) {
  if (!node) return;
  rejectUnknownKeys(node, "noise");
  if (node["sigma_bgr"]) noise.sigma_bgr = readVec3(node["sigma_bgr"], "noise.sigma_bgr");
  read(node, "neighbour_correlation", noise.neighbour_correlation);
  read(node, "correlation_bg", noise.correlation_bg);
  read(node, "correlation_gr", noise.correlation_gr);
  read(node, "correlation_br", noise.correlation_br);
  read(node, "on_real_background", noise.on_real_background);
}

void readMarkers(const YAML::Node& node, MarkerOptions& markers) {
  if (!node) return;
  rejectUnknownKeys(node, "markers");
  read(node, "enabled", markers.enabled);
  read(node, "rows", markers.rows);
  read(node, "cols", markers.cols);
  read(node, "pitch_mm", markers.pitch_mm);
  read(node, "dot_diameter_mm", markers.dot_diameter_mm);
  read(node, "darkness", markers.darkness);
  read(node, "blur_mm", markers.blur_mm);
  read(node, "jitter_mm", markers.jitter_mm);
  read(node, "seed", markers.seed);
  if (node["offset_mm"]) {
    const std::vector<double> values = node["offset_mm"].as<std::vector<double>>();
    if (values.size() != 2)
      throw Error("markers.offset_mm needs 2 numbers, got " + std::to_string(values.size()));
    markers.offset_mm = {values[0], values[1]};
  }
}

std::array<double, 2> readPair(const YAML::Node& node, const std::string& key) {
  const std::vector<double> values = node.as<std::vector<double>>();
  if (values.size() != 2)
    throw Error(key + " needs 2 numbers, got " + std::to_string(values.size()));
  return {values[0], values[1]};
}

// A given glows list replaces the default one whole, and every glow gives all four keys: a glow
// half taken from the defaults would be a glow nobody measured.
void readSyntheticBackground(const YAML::Node& node, SyntheticBackgroundOptions& look) {
  if (!node) return;
  rejectUnknownKeys(node, "synthetic_background");
  if (node["base_bgr"]) look.base_bgr = readVec3(node["base_bgr"], "synthetic_background.base_bgr");
  read(node, "vignette_strength", look.vignette_strength);
  read(node, "vignette_power", look.vignette_power);
  const YAML::Node glows = node["glows"];
  if (!glows) return;
  if (!glows.IsSequence()) throw Error("synthetic_background.glows must be a list of glows");
  look.glows.clear();
  for (std::size_t j = 0; j < glows.size(); ++j) {
    const std::string name = "synthetic_background.glows[" + std::to_string(j) + "]";
    rejectUnknownKeys(glows[j], "synthetic_background.glows[]");
    for (const char* key : {"centre_uv", "sigma_uv", "angle_rad", "color_bgr"}) {
      if (!glows[j][key]) throw Error(name + " needs " + key);
    }
    BackgroundGlow glow;
    glow.centre_uv = readPair(glows[j]["centre_uv"], name + ".centre_uv");
    glow.sigma_uv = readPair(glows[j]["sigma_uv"], name + ".sigma_uv");
    glow.angle_rad = glows[j]["angle_rad"].as<double>();
    glow.color_bgr = readVec3(glows[j]["color_bgr"], name + ".color_bgr");
    look.glows.push_back(glow);
  }
}

void validateMarkers(const SensorModel& m) {
  using detail::requireParameter;
  const MarkerOptions& k = m.markers;
  requireParameter(k.rows >= 1 && k.rows <= 200, "markers.rows", k.rows, "[1, 200]");
  requireParameter(k.cols >= 1 && k.cols <= 200, "markers.cols", k.cols, "[1, 200]");
  requireParameter(k.pitch_mm > 0.0 && k.pitch_mm <= 20.0, "markers.pitch_mm", k.pitch_mm,
                   "(0, 20] mm");
  requireParameter(k.dot_diameter_mm > 0.0 && k.dot_diameter_mm < k.pitch_mm,
                   "markers.dot_diameter_mm", k.dot_diameter_mm,
                   "(0, pitch_mm) mm (dots that touch are no grid)");
  requireParameter(k.darkness >= 0.0 && k.darkness <= 1.0, "markers.darkness", k.darkness,
                   "[0, 1]");
  requireParameter(k.blur_mm >= 0.0 && k.blur_mm <= 1.0, "markers.blur_mm", k.blur_mm,
                   "[0, 1] mm");
  requireParameter(k.jitter_mm >= 0.0 && k.jitter_mm <= 0.5 * k.pitch_mm, "markers.jitter_mm",
                   k.jitter_mm, "[0, pitch_mm / 2] mm");
  requireParameter(std::isfinite(k.offset_mm[0]) && std::isfinite(k.offset_mm[1]) &&
                       std::abs(k.offset_mm[0]) <= 50.0 && std::abs(k.offset_mm[1]) <= 50.0,
                   "markers.offset_mm", k.offset_mm[0], "finite, within +-50 mm");
  requireParameter(m.shear.shear_modulus_mpa > 0.0 && m.shear.shear_modulus_mpa <= 100.0,
                   "shear.shear_modulus_mpa", m.shear.shear_modulus_mpa, "(0, 100] MPa");
  requireParameter(m.shear.friction > 0.0 && m.shear.friction <= 10.0, "shear.friction",
                   m.shear.friction, "(0, 10]");
}

}  // namespace

const char* shadingKindName(ShadingKind kind) {
  return kind == ShadingKind::kCalibrated ? "calibrated" : "analytic_leds";
}

cv::Point2d SensorModel::pixelToGelMm(double row, double col) const {
  return {(col + 0.5 - cols / 2.0) * mm_per_pixel, (row + 0.5 - rows / 2.0) * mm_per_pixel};
}

SensorModel makeDigitSensorModel(bool vga) {
  SensorModel model;
  model.leds = defaultLeds();
  model.shading.response_bgr = defaultShadingResponse();
  model.shading.slope_saturation = kDefaultSlopeSaturation;
  if (vga) {
    model.rows = 640;
    model.cols = 480;
    model.mm_per_pixel = 0.5 * model.mm_per_pixel;
    model.fx = model.fy = 554.3;
    model.cx = 239.5;
    model.cy = 319.5;
  }
  return model;
}

void validate(const SensorModel& m) {
  using detail::requireParameter;
  requireParameter(m.rows >= 8 && m.rows <= 4096, "image.rows", m.rows, "[8, 4096]");
  requireParameter(m.cols >= 8 && m.cols <= 4096, "image.cols", m.cols, "[8, 4096]");
  requireParameter(m.mm_per_pixel > 0.0 && m.mm_per_pixel <= 1.0, "image.mm_per_pixel",
                   m.mm_per_pixel, "(0, 1] mm");
  requireParameter(m.gel_thickness_mm > 0.0 && m.gel_thickness_mm <= 20.0, "gel.thickness_mm",
                   m.gel_thickness_mm, "(0, 20] mm");
  requireParameter(m.gel_curvature_radius_mm == 0.0 || m.gel_curvature_radius_mm > 5.0,
                   "gel.curvature_radius_mm", m.gel_curvature_radius_mm, "0 (flat) or > 5 mm");
  requireParameter(m.gel_pad_width_mm > 0.0 && m.gel_pad_width_mm <= 100.0, "gel.pad_width_mm",
                   m.gel_pad_width_mm, "(0, 100] mm");
  requireParameter(m.gel_pad_height_mm > 0.0 && m.gel_pad_height_mm <= 100.0,
                   "gel.pad_height_mm", m.gel_pad_height_mm, "(0, 100] mm");
  requireParameter(m.fx > 0.0 && m.fy > 0.0, "camera.fx/fy", m.fx, "> 0 pixels");
  requireParameter(std::isfinite(m.cx) && std::isfinite(m.cy), "camera.cx/cy", m.cx, "finite");
  for (const LedModel& led : m.leds) {
    requireParameter(led.intensity >= 0.0 && std::isfinite(led.intensity),
                     "leds." + led.name + ".intensity", led.intensity, ">= 0");
    requireParameter(std::isfinite(cv::norm(led.position_mm)), "leds." + led.name + ".position_mm",
                     "non-finite", "finite numbers");
    for (int i = 0; i < 3; ++i) {
      requireParameter(led.color_bgr[i] >= 0.0 && led.color_bgr[i] <= 1.0,
                       "leds." + led.name + ".color_bgr", led.color_bgr[i], "[0, 1] per channel");
    }
  }
  const ShadingOptions& s = m.shading;
  requireParameter(s.gain >= 0.0 && s.gain <= 100.0, "shading.gain", s.gain, "[0, 100]");
  requireParameter(s.shadow_sigma_mm >= 0.05 && s.shadow_sigma_mm <= 3.0, "shading.shadow_sigma_mm",
                   s.shadow_sigma_mm, "[0.05, 3] mm");
  requireParameter(s.slope_saturation == 0.0 ||
                       (s.slope_saturation >= 0.05 && s.slope_saturation <= 20.0),
                   "shading.slope_saturation", s.slope_saturation, "0 (none) or [0.05, 20]");
  for (int k = 0; k < 3; ++k) {
    for (const double value : s.response_bgr[k]) {
      requireParameter(std::isfinite(value) && std::abs(value) <= 1e5,
                       std::string("shading.response.") + kChannelNames[k], value,
                       "finite numbers within +-1e5 grey levels");
    }
  }
  const NoiseOptions& n = m.noise;
  for (int k = 0; k < 3; ++k) {
    requireParameter(n.sigma_bgr[k] >= 0.0 && n.sigma_bgr[k] <= 64.0, "noise.sigma_bgr",
                     n.sigma_bgr[k], "[0, 64] grey levels per channel");
  }
  requireParameter(n.neighbour_correlation >= 0.0 && n.neighbour_correlation <= 0.7,
                   "noise.neighbour_correlation", n.neighbour_correlation,
                   "[0, 0.7] (a 3 x 3 kernel reaches at most 0.707)");
  const double correlations[3] = {n.correlation_bg, n.correlation_gr, n.correlation_br};
  const char* const correlation_names[3] = {"noise.correlation_bg", "noise.correlation_gr",
                                            "noise.correlation_br"};
  for (int i = 0; i < 3; ++i) {
    requireParameter(std::abs(correlations[i]) < 1.0, correlation_names[i], correlations[i],
                     "(-1, 1)");
  }
  // The three correlations must form a valid (positive definite) correlation matrix.
  const double det = 1.0 + 2.0 * n.correlation_bg * n.correlation_gr * n.correlation_br -
                     n.correlation_bg * n.correlation_bg - n.correlation_gr * n.correlation_gr -
                     n.correlation_br * n.correlation_br;
  requireParameter(det > 1e-6, "noise.correlation_bg/gr/br", det,
                   "a positive definite correlation matrix (determinant > 0)");
  requireParameter(m.gel.core_fraction > 0.0 && m.gel.core_fraction <= 1.0,
                   "gel_model.core_fraction", m.gel.core_fraction, "(0, 1]");
  requireParameter(m.gel.final_sigma_mm >= 0.0 && m.gel.final_sigma_mm <= 5.0,
                   "gel_model.final_sigma_mm", m.gel.final_sigma_mm, "[0, 5] mm");
  for (double sigma : m.gel.pyramid_sigmas_mm) {
    requireParameter(sigma > 0.0 && sigma <= 20.0, "gel_model.pyramid_sigmas_mm", sigma,
                     "(0, 20] mm each");
  }
  requireParameter(m.conformity.contact_modulus_mpa > 0.0 && m.conformity.contact_modulus_mpa <= 100.0,
                   "conformity.contact_modulus_mpa", m.conformity.contact_modulus_mpa,
                   "(0, 100] MPa");
  requireParameter(m.conformity.coating_length_mm >= 0.0 && m.conformity.coating_length_mm <= 2.0,
                   "conformity.coating_length_mm", m.conformity.coating_length_mm, "[0, 2] mm");
  validateMarkers(m);
  validate(m.synthetic_background);
}

SensorModel loadSensorModel(const std::string& yaml_path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(yaml_path);
  } catch (const YAML::Exception& e) {
    throw Error("sensor config '" + yaml_path + "': " + e.what());
  }
  try {
    if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);  // an empty file: defaults
    rejectUnknownKeys(root, "");
    std::string preset = "qvga";
    read(root, "preset", preset);
    if (preset != "qvga" && preset != "vga") {
      throw Error("preset = '" + preset + "' is not valid; valid: qvga, vga");
    }
    SensorModel m = makeDigitSensorModel(preset == "vga");
    rejectUnknownKeys(root["image"], "image");
    read(root["image"], "rows", m.rows);
    read(root["image"], "cols", m.cols);
    read(root["image"], "mm_per_pixel", m.mm_per_pixel);
    rejectUnknownKeys(root["gel"], "gel");
    read(root["gel"], "thickness_mm", m.gel_thickness_mm);
    read(root["gel"], "curvature_radius_mm", m.gel_curvature_radius_mm);
    read(root["gel"], "pad_width_mm", m.gel_pad_width_mm);
    read(root["gel"], "pad_height_mm", m.gel_pad_height_mm);
    rejectUnknownKeys(root["camera"], "camera");
    read(root["camera"], "fx", m.fx);
    read(root["camera"], "fy", m.fy);
    read(root["camera"], "cx", m.cx);
    read(root["camera"], "cy", m.cy);
    if (const YAML::Node leds = root["leds"]) {
      if (!leds.IsSequence() || leds.size() != 3) throw Error("leds must list exactly 3 LEDs");
      for (size_t i = 0; i < 3; ++i) {
        rejectUnknownKeys(leds[i], "leds[]");
        LedModel& led = m.leds[i];
        read(leds[i], "name", led.name);
        if (leds[i]["position_mm"])
          led.position_mm = readVec3(leds[i]["position_mm"], "position_mm");
        if (leds[i]["color_bgr"]) led.color_bgr = readVec3(leds[i]["color_bgr"], "color_bgr");
        read(leds[i], "intensity", led.intensity);
      }
    }
    readShading(root["shading"], m.shading);
    readNoise(root["noise"], m.noise);
    read(root, "background_image", m.background_image);
    readSyntheticBackground(root["synthetic_background"], m.synthetic_background);
    if (const YAML::Node gel = root["gel_model"]) {
      rejectUnknownKeys(gel, "gel_model");
      read(gel, "pyramid_sigmas_mm", m.gel.pyramid_sigmas_mm);
      read(gel, "core_fraction", m.gel.core_fraction);
      read(gel, "final_sigma_mm", m.gel.final_sigma_mm);
    }
    if (const YAML::Node conformity = root["conformity"]) {
      rejectUnknownKeys(conformity, "conformity");
      read(conformity, "enabled", m.conformity.enabled);
      read(conformity, "contact_modulus_mpa", m.conformity.contact_modulus_mpa);
      read(conformity, "coating_length_mm", m.conformity.coating_length_mm);
    }
    readMarkers(root["markers"], m.markers);
    if (const YAML::Node shear = root["shear"]) {
      rejectUnknownKeys(shear, "shear");
      read(shear, "shear_modulus_mpa", m.shear.shear_modulus_mpa);
      read(shear, "friction", m.shear.friction);
    }
    if (!m.background_image.empty() && std::filesystem::path(m.background_image).is_relative()) {
      m.background_image =
          (std::filesystem::path(yaml_path).parent_path() / m.background_image).string();
    }
    validate(m);
    return m;
  } catch (const YAML::Exception& e) {
    throw Error("sensor config '" + yaml_path + "': " + e.what());
  } catch (const Error& e) {
    throw Error("sensor config '" + yaml_path + "': " + e.what());
  }
}

namespace {

std::string vec3(const cv::Vec3d& v) {
  std::ostringstream out;
  out << std::setprecision(9) << "[" << v[0] << ", " << v[1] << ", " << v[2] << "]";
  return out.str();
}

}  // namespace

void saveSensorModel(const SensorModel& m, const std::string& yaml_path) {
  validate(m);
  std::ostringstream out;
  out << std::setprecision(9);
  out << "# Sensor model for norm2tex (see config/digit.yaml for what each key means).\n"
      << "# Lengths in mm, images in pixels, grey levels of 255; colours in OpenCV BGR order.\n"
      << "image:\n  rows: " << m.rows << "\n  cols: " << m.cols
      << "\n  mm_per_pixel: " << m.mm_per_pixel << "\n"
      << "gel:\n  thickness_mm: " << m.gel_thickness_mm
      << "\n  curvature_radius_mm: " << m.gel_curvature_radius_mm
      << "\n  pad_width_mm: " << m.gel_pad_width_mm << "\n  pad_height_mm: " << m.gel_pad_height_mm
      << "\n"
      << "camera:\n  fx: " << m.fx << "\n  fy: " << m.fy << "\n  cx: " << m.cx << "\n  cy: " << m.cy
      << "\n"
      << "leds:\n";
  for (const LedModel& led : m.leds) {
    out << "  - name: " << led.name << "\n    position_mm: " << vec3(led.position_mm)
        << "\n    color_bgr: " << vec3(led.color_bgr) << "\n    intensity: " << led.intensity
        << "\n";
  }
  out << "shading:\n  model: " << shadingKindName(m.shading.kind) << "\n  gain: " << m.shading.gain
      << "\n  shadow_sigma_mm: " << m.shading.shadow_sigma_mm
      << "\n  slope_saturation: " << m.shading.slope_saturation
      << "\n  response:   # grey levels per unit of: " << shadingFeatureNames() << "\n";
  for (int k = 0; k < 3; ++k) {
    out << "    " << kChannelNames[k] << ": [";
    for (int j = 0; j < kShadingFeatureCount; ++j) {
      out << (j ? ", " : "") << m.shading.response_bgr[k][j];
    }
    out << "]\n";
  }
  out << "noise:\n  sigma_bgr: " << vec3(m.noise.sigma_bgr)
      << "\n  neighbour_correlation: " << m.noise.neighbour_correlation
      << "\n  correlation_bg: " << m.noise.correlation_bg
      << "\n  correlation_gr: " << m.noise.correlation_gr
      << "\n  correlation_br: " << m.noise.correlation_br
      << "\n  on_real_background: " << (m.noise.on_real_background ? "true" : "false") << "\n"
      << "background_image: \"" << m.background_image << "\"\n"
      << "synthetic_background:\n  base_bgr: " << vec3(m.synthetic_background.base_bgr)
      << "\n  vignette_strength: " << m.synthetic_background.vignette_strength
      << "\n  vignette_power: " << m.synthetic_background.vignette_power << "\n  glows:"
      << (m.synthetic_background.glows.empty() ? " []\n" : "\n");
  for (const BackgroundGlow& g : m.synthetic_background.glows) {
    out << "    - centre_uv: [" << g.centre_uv[0] << ", " << g.centre_uv[1] << "]\n"
        << "      sigma_uv: [" << g.sigma_uv[0] << ", " << g.sigma_uv[1] << "]\n"
        << "      angle_rad: " << g.angle_rad << "\n      color_bgr: " << vec3(g.color_bgr) << "\n";
  }
  out << "gel_model:\n  pyramid_sigmas_mm: [";
  for (size_t i = 0; i < m.gel.pyramid_sigmas_mm.size(); ++i) {
    out << (i ? ", " : "") << m.gel.pyramid_sigmas_mm[i];
  }
  out << "]\n  core_fraction: " << m.gel.core_fraction
      << "\n  final_sigma_mm: " << m.gel.final_sigma_mm << "\n"
      << "conformity:\n  enabled: " << (m.conformity.enabled ? "true" : "false")
      << "\n  contact_modulus_mpa: " << m.conformity.contact_modulus_mpa
      << "\n  coating_length_mm: " << m.conformity.coating_length_mm << "\n";
  const MarkerOptions& k = m.markers;
  out << "markers:\n  enabled: " << (k.enabled ? "true" : "false") << "\n  rows: " << k.rows
      << "\n  cols: " << k.cols << "\n  pitch_mm: " << k.pitch_mm
      << "\n  dot_diameter_mm: " << k.dot_diameter_mm << "\n  darkness: " << k.darkness
      << "\n  blur_mm: " << k.blur_mm << "\n  jitter_mm: " << k.jitter_mm << "\n  seed: " << k.seed
      << "\n  offset_mm: [" << k.offset_mm[0] << ", " << k.offset_mm[1] << "]\n"
      << "shear:\n  shear_modulus_mpa: " << m.shear.shear_modulus_mpa
      << "\n  friction: " << m.shear.friction << "\n";
  std::ofstream file(yaml_path);
  file << out.str();
  file.close();
  if (!file) throw Error("sensor config '" + yaml_path + "': cannot be written");
}

}  // namespace norm2tex
