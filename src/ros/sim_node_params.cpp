#include "sim_node_params.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>

#include "lock_step.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/render/object_texture.hpp"
#include "params.hpp"

namespace norm2tex {

using ros_params::badParameter;
using ros_params::packageFile;
using ros_params::readParam;
using ros_params::text;

void readSimNodeParams(const ros::NodeHandle& pnh, SimNodeParams& p) {
  std::string mode = "real_time";
  readParam<std::string>(pnh, "mode", mode, mode);
  if (mode != "real_time" && mode != "synchronous") {
    badParameter("mode", "'" + mode + "'", "real_time, synchronous");
  }
  p.synchronous = mode == "synchronous";
  readParam<std::string>(pnh, "scene", p.scene, packageFile("config/scenes/cube.yaml"));
  readParam<std::string>(pnh, "mesh", p.mesh, "");
  readParam(pnh, "scale", p.scale, p.scale);
  if (!(p.scale > 0.0 && p.scale <= 1000.0)) badParameter("scale", text(p.scale), "(0, 1000]");
  readParam<std::string>(pnh, "sensor", p.sensor, packageFile("config/digit.yaml"));
  readParam<std::string>(pnh, "material", p.material, "wood");
  if (p.material.empty()) p.material = ros_params::kNoMaterial;
  if (p.material != ros_params::kNoMaterial) {
    p.material_config = ros_params::materialConfigPath(p.material, ", or none (then ~friction)");
  }
  readParam(pnh, "friction", p.friction, p.friction);
  if (!(p.friction < 0.0 || p.friction <= 5.0) || std::isnan(p.friction)) {
    badParameter("friction", text(p.friction), "[0, 5], or < 0 for the material's");
  }
  readParam(pnh, "beta", p.beta, p.beta);
  readParam(pnh, "physics_rate", p.physics_rate, p.physics_rate);
  if (!(p.physics_rate >= 100.0 && p.physics_rate <= 100000.0)) {
    badParameter("physics_rate", text(p.physics_rate), "[100, 100000] Hz");
  }
  readParam(pnh, "frame_rate", p.frame_rate, p.frame_rate);
  if (!(p.frame_rate >= 1.0 && p.frame_rate <= 1000.0 && p.frame_rate <= p.physics_rate)) {
    badParameter("frame_rate", text(p.frame_rate), "[1, 1000] Hz and <= ~physics_rate");
  }
  readLockStepParams(pnh, p.renderers, p.render_timeout, p.ready_timeout);
}

SimNodeScene makeSimNodeScene(const SimNodeParams& p) {
  SimNodeScene out;
  std::optional<MaterialConfig> material;
  if (!p.material_config.empty()) material = loadMaterialConfig(p.material_config);
  out.beta_mm = p.beta >= 0.0 ? p.beta : material ? material->beta_mm : kFileTextureBetaMm;
  out.friction = p.friction >= 0.0 ? p.friction : material ? material->friction : kDefaultFriction;
  out.sensor = loadSensorModel(p.sensor);
  out.config = loadGripperSimConfig(p.scene);
  if (!p.mesh.empty()) {
    out.config.object.mesh = p.mesh;
    out.config.object.scale = p.scale;
    out.config.object.name = std::filesystem::path(p.mesh).stem().string();
  }
  out.config.object.friction = out.friction;
  out.config.object.material = p.material;
  setGelFromSensor(out.sensor, out.config);
  out.ticks_per_frame = std::max(1, static_cast<int>(std::lround(p.physics_rate / p.frame_rate)));
  out.config.physics.rate_hz = out.ticks_per_frame * p.frame_rate;
  out.frame_period_ns = std::llround(1e9 / p.frame_rate);
  return out;
}

}  // namespace norm2tex
