#include "norm2tex/render/sensor_model.hpp"

#include <cmath>
#include <filesystem>

#include <yaml-cpp/yaml.h>

#include "common/error_messages.hpp"
#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

// TACTO's DIGIT lights sit 20 mm off the axis at 30, 150 and 270 degrees; seen through the
// portrait image, red lights the top-left, green the top-right, blue the bottom. They sit
// behind the gel surface (z < 0), on the camera's side of the membrane.
std::array<LedModel, 3> defaultLeds() {
  return {LedModel{"red", {-17.32, -10.0, -3.0}, {0.0, 0.0, 1.0}, 1.0},
          LedModel{"green", {17.32, -10.0, -3.0}, {0.0, 1.0, 0.0}, 1.0},
          LedModel{"blue", {0.0, 20.0, -3.0}, {1.0, 0.0, 0.0}, 1.0}};
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

}  // namespace

cv::Point2d SensorModel::pixelToGelMm(double row, double col) const {
  return {(col + 0.5 - cols / 2.0) * mm_per_pixel, (row + 0.5 - rows / 2.0) * mm_per_pixel};
}

SensorModel makeDigitSensorModel(bool vga) {
  SensorModel model;
  model.leds = defaultLeds();
  if (vga) {
    model.rows = 640;
    model.cols = 480;
    model.mm_per_pixel = 0.04;
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
  requireParameter(m.shading_gain >= 0.0 && m.shading_gain <= 100.0, "shading_gain", m.shading_gain,
                   "[0, 100]");
  requireParameter(m.noise_sigma >= 0.0 && m.noise_sigma <= 64.0, "noise_sigma", m.noise_sigma,
                   "[0, 64] grey levels");
  requireParameter(m.gel.core_fraction > 0.0 && m.gel.core_fraction <= 1.0,
                   "gel_model.core_fraction", m.gel.core_fraction, "(0, 1]");
  requireParameter(m.gel.final_sigma_mm >= 0.0 && m.gel.final_sigma_mm <= 5.0,
                   "gel_model.final_sigma_mm", m.gel.final_sigma_mm, "[0, 5] mm");
  for (double sigma : m.gel.pyramid_sigmas_mm) {
    requireParameter(sigma > 0.0 && sigma <= 20.0, "gel_model.pyramid_sigmas_mm", sigma,
                     "(0, 20] mm each");
  }
}

SensorModel loadSensorModel(const std::string& yaml_path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(yaml_path);
  } catch (const YAML::Exception& e) {
    throw Error("sensor config '" + yaml_path + "': " + e.what());
  }
  try {
    std::string preset = "qvga";
    read(root, "preset", preset);
    if (preset != "qvga" && preset != "vga") {
      throw Error("preset = '" + preset + "' is not valid; valid: qvga, vga");
    }
    SensorModel m = makeDigitSensorModel(preset == "vga");
    read(root["image"], "rows", m.rows);
    read(root["image"], "cols", m.cols);
    read(root["image"], "mm_per_pixel", m.mm_per_pixel);
    read(root["gel"], "thickness_mm", m.gel_thickness_mm);
    read(root["gel"], "curvature_radius_mm", m.gel_curvature_radius_mm);
    read(root["camera"], "fx", m.fx);
    read(root["camera"], "fy", m.fy);
    read(root["camera"], "cx", m.cx);
    read(root["camera"], "cy", m.cy);
    if (const YAML::Node leds = root["leds"]) {
      if (!leds.IsSequence() || leds.size() != 3) throw Error("leds must list exactly 3 LEDs");
      for (size_t i = 0; i < 3; ++i) {
        LedModel& led = m.leds[i];
        read(leds[i], "name", led.name);
        if (leds[i]["position_mm"])
          led.position_mm = readVec3(leds[i]["position_mm"], "position_mm");
        if (leds[i]["color_bgr"]) led.color_bgr = readVec3(leds[i]["color_bgr"], "color_bgr");
        read(leds[i], "intensity", led.intensity);
      }
    }
    read(root, "shading_gain", m.shading_gain);
    read(root, "noise_sigma", m.noise_sigma);
    read(root, "background_image", m.background_image);
    if (const YAML::Node gel = root["gel_model"]) {
      read(gel, "pyramid_sigmas_mm", m.gel.pyramid_sigmas_mm);
      read(gel, "core_fraction", m.gel.core_fraction);
      read(gel, "final_sigma_mm", m.gel.final_sigma_mm);
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

}  // namespace norm2tex
