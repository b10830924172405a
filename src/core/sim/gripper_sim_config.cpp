#include "norm2tex/sim/gripper_sim_config.hpp"

#include <cmath>
#include <filesystem>
#include <set>

#include <yaml-cpp/yaml.h>

#include "common/error_messages.hpp"
#include "norm2tex/common/error.hpp"
#include "sim/yaml_keys.hpp"

namespace norm2tex {
namespace {

using detail::requireKnownKeys;

template <typename T>
void read(const YAML::Node& section, const char* key, T& value) {
  if (section && section[key]) value = section[key].as<T>();
}

// Millimetres in the file, metres in the struct.
void readMm(const YAML::Node& section, const char* key, double& value_m) {
  if (section && section[key]) value_m = section[key].as<double>() * 1e-3;
}

bool isPrimitive(const std::string& mesh) {
  return mesh.rfind("box:", 0) == 0 || mesh.rfind("sphere:", 0) == 0;
}

}  // namespace

void setGelFromSensor(const SensorModel& sensor, GripperSimConfig& config) {
  config.gel_width_m = sensor.gel_pad_width_mm * 1e-3;
  config.gel_height_m = sensor.gel_pad_height_mm * 1e-3;
  config.gel_thickness_m = sensor.gel_thickness_mm * 1e-3;
}

void validate(const GripperSimConfig& c) {
  using detail::requireParameter;
  const GripperOptions& g = c.gripper;
  requireParameter(
      std::isfinite(g.base_height_m) && g.base_height_m > 0.05 && g.base_height_m <= 10.0,
      "gripper.base_height_mm", g.base_height_m * 1e3, "(50, 10000] mm");
  requireParameter(g.min_gap_m >= 0.0 && g.min_gap_m < g.max_gap_m, "gripper.min_gap_mm",
                   g.min_gap_m * 1e3, "[0, max_gap_mm)");
  requireParameter(g.max_gap_m <= 0.5, "gripper.max_gap_mm", g.max_gap_m * 1e3,
                   "(min_gap, 500] mm");
  requireParameter(g.max_force_n > 0.0 && g.max_force_n <= 500.0, "gripper.max_force_n",
                   g.max_force_n, "(0, 500] N");
  requireParameter(g.max_speed_m_s > 0.0 && g.max_speed_m_s <= 1.0, "gripper.max_speed_mm_s",
                   g.max_speed_m_s * 1e3, "(0, 1000] mm/s");
  // Stiffer than 1 MN/m the fingers' deflection is below a nanometre at the force limit: rigid
  // control (0) says that exactly.
  requireParameter(std::isfinite(g.stiffness_n_per_m) && g.stiffness_n_per_m >= 0.0 &&
                       g.stiffness_n_per_m <= 1e6,
                   "gripper.stiffness_n_per_mm", g.stiffness_n_per_m * 1e-3,
                   "0 (rigid) or (0, 1000] N/mm");
  const ObjectOptions& o = c.object;
  requireParameter(!o.mesh.empty(), "object.mesh", "''", "a mesh file or box:XxYxZ / sphere:R");
  requireParameter(o.scale > 0.0 && o.scale <= 1000.0, "object.scale", o.scale, "(0, 1000]");
  requireParameter(o.mass_kg > 0.0 && o.mass_kg <= 100.0, "object.mass_kg", o.mass_kg,
                   "(0, 100] kg");
  requireParameter(o.collision == "auto" || o.collision == "box" || o.collision == "hull" ||
                       o.collision == "decomposition",
                   "object.collision", o.collision, "auto, box, hull, decomposition");
  requireParameter(o.friction >= 0.0 && o.friction <= 2.0, "object.friction", o.friction, "[0, 2]");
  const PhysicsOptions& p = c.physics;
  requireParameter(p.rate_hz >= 100.0 && p.rate_hz <= 100000.0, "physics.rate_hz", p.rate_hz,
                   "[100, 100000] Hz");
  requireParameter(p.substeps >= 1 && p.substeps <= 100, "physics.substeps", p.substeps,
                   "[1, 100]");
  requireParameter(p.solver_iterations >= 1 && p.solver_iterations <= 10000,
                   "physics.solver_iterations", p.solver_iterations, "[1, 10000]");
  requireParameter(p.solver_tolerance_m_s >= 0.0 && p.solver_tolerance_m_s <= 1e-2,
                   "physics.solver_tolerance_m_s", p.solver_tolerance_m_s, "[0, 0.01] m/s");
  requireParameter(p.gravity_m_s2 >= 0.0 && p.gravity_m_s2 <= 100.0, "physics.gravity_m_s2",
                   p.gravity_m_s2, "[0, 100] m/s^2");
  requireParameter(p.gel_damping >= 0.0 && p.gel_damping <= 1e4, "physics.gel_damping",
                   p.gel_damping, "[0, 10000] N s/m");
  requireParameter(p.friction_erp >= 0.0 && p.friction_erp <= 1.0, "physics.friction_erp",
                   p.friction_erp, "[0, 1]");
  const EpisodeOptions& e = c.episode;
  requireParameter(std::isfinite(e.height_offset_low_m) && std::isfinite(e.height_offset_high_m) &&
                       e.height_offset_low_m <= e.height_offset_high_m &&
                       std::abs(e.height_offset_low_m) <= 0.5 &&
                       std::abs(e.height_offset_high_m) <= 0.5,
                   "episode.height_offset_mm", e.height_offset_low_m * 1e3,
                   "[low, high] with low <= high, each within +-500 mm");
  requireParameter(e.grasp_opening < 0.0 || e.grasp_opening <= 1.0, "episode.grasp_opening",
                   e.grasp_opening, "[0, 1], or < 0 to derive it from grasp_indentation_mm");
  requireParameter(e.grasp_indentation_m > 0.0 && e.grasp_indentation_m < c.gel_thickness_m,
                   "episode.grasp_indentation_mm", e.grasp_indentation_m * 1e3,
                   "(0, gel thickness)");
  requireParameter(e.grasp_force_n >= 0.0 && e.grasp_force_n < g.max_force_n,
                   "episode.grasp_force_n", e.grasp_force_n,
                   "[0, gripper.max_force_n) N (0: grasp_indentation_mm decides)");
  requireParameter(e.settle_s >= 0.0 && e.settle_s <= 60.0, "episode.settle_s", e.settle_s,
                   "[0, 60] s");
  requireParameter(c.gel_width_m > 0.001 && c.gel_width_m <= 0.2, "gel_width_m", c.gel_width_m,
                   "(0.001, 0.2] m (from the sensor model)");
  requireParameter(c.gel_height_m > 0.001 && c.gel_height_m <= 0.2, "gel_height_m", c.gel_height_m,
                   "(0.001, 0.2] m (from the sensor model)");
  requireParameter(c.gel_thickness_m > 0.0001 && c.gel_thickness_m <= 0.02, "gel_thickness_m",
                   c.gel_thickness_m, "(0.0001, 0.02] m (from the sensor model)");
}

GripperSimConfig loadGripperSimConfig(const std::string& yaml_path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(yaml_path);
  } catch (const YAML::Exception& e) {
    throw Error("scene config '" + yaml_path + "': " + e.what());
  }
  try {
    GripperSimConfig c;
    if (!root.IsNull()) {
      requireKnownKeys(root, "", {"gripper", "object", "physics", "episode", "gel"});
    }
    const YAML::Node g = root["gripper"];
    requireKnownKeys(g, "gripper",
                     {"hand", "base_height_mm", "min_gap_mm", "max_gap_mm", "max_force_n",
                      "max_speed_mm_s", "stiffness_n_per_mm"});
    if (g && g["hand"]) {
      // The stroke, drive and height are the hand's own (its URDF and yaml): giving them here
      // too would leave two answers to one question.
      for (const char* key : {"base_height_mm", "min_gap_mm", "max_gap_mm", "max_force_n",
                              "max_speed_mm_s", "stiffness_n_per_mm"}) {
        if (g[key]) {
          throw Error(std::string("gripper.") + key + " is given with gripper.hand: a hand's " +
                      "stroke, drives and pose are its own (its URDF, its hand yaml's gripper, " +
                      "joints and hand.base_pose); remove gripper." + key);
        }
      }
      const std::string hand = g["hand"].as<std::string>();
      if (hand.empty()) throw Error("gripper.hand is empty; valid: a hand yaml (docs/hands.md)");
      c.gripper.hand_yaml = std::filesystem::path(hand).is_relative()
                                ? (std::filesystem::path(yaml_path).parent_path() / hand).string()
                                : hand;
    }
    readMm(g, "base_height_mm", c.gripper.base_height_m);
    readMm(g, "min_gap_mm", c.gripper.min_gap_m);
    readMm(g, "max_gap_mm", c.gripper.max_gap_m);
    read(g, "max_force_n", c.gripper.max_force_n);
    readMm(g, "max_speed_mm_s", c.gripper.max_speed_m_s);
    // N/mm in the file, N/m in the struct.
    if (g && g["stiffness_n_per_mm"]) {
      c.gripper.stiffness_n_per_m = g["stiffness_n_per_mm"].as<double>() * 1e3;
    }

    const YAML::Node o = root["object"];
    requireKnownKeys(o, "object", {"name", "mesh", "scale", "mass_kg", "collision", "friction"});
    read(o, "name", c.object.name);
    read(o, "mesh", c.object.mesh);
    read(o, "scale", c.object.scale);
    read(o, "mass_kg", c.object.mass_kg);
    read(o, "collision", c.object.collision);
    read(o, "friction", c.object.friction);
    if (!isPrimitive(c.object.mesh) && std::filesystem::path(c.object.mesh).is_relative()) {
      c.object.mesh = (std::filesystem::path(yaml_path).parent_path() / c.object.mesh).string();
    }

    const YAML::Node p = root["physics"];
    requireKnownKeys(p, "physics",
                     {"rate_hz", "substeps", "solver_iterations", "solver_tolerance_m_s",
                      "gravity_m_s2", "gel_damping", "friction_erp"});
    read(p, "rate_hz", c.physics.rate_hz);
    read(p, "substeps", c.physics.substeps);
    read(p, "solver_iterations", c.physics.solver_iterations);
    read(p, "solver_tolerance_m_s", c.physics.solver_tolerance_m_s);
    read(p, "gravity_m_s2", c.physics.gravity_m_s2);
    read(p, "gel_damping", c.physics.gel_damping);
    read(p, "friction_erp", c.physics.friction_erp);

    const YAML::Node e = root["episode"];
    requireKnownKeys(e, "episode",
                     {"height_offset_mm", "grasp_opening", "grasp_indentation_mm", "grasp_force_n",
                      "settle_s"});
    if (e && e["height_offset_mm"]) {
      const auto range = e["height_offset_mm"].as<std::vector<double>>();
      if (range.size() != 2) throw Error("episode.height_offset_mm needs [low, high]");
      c.episode.height_offset_low_m = range[0] * 1e-3;
      c.episode.height_offset_high_m = range[1] * 1e-3;
    }
    read(e, "grasp_opening", c.episode.grasp_opening);
    readMm(e, "grasp_indentation_mm", c.episode.grasp_indentation_m);
    read(e, "grasp_force_n", c.episode.grasp_force_n);
    read(e, "settle_s", c.episode.settle_s);

    const YAML::Node gel = root["gel"];
    requireKnownKeys(gel, "gel", {"law"});
    if (gel && gel["law"]) {
      // [[indentation_mm, force_n], ...]
      std::vector<std::pair<double, double>> points;
      for (const auto& point : gel["law"]) {
        const auto pair = point.as<std::vector<double>>();
        if (pair.size() != 2) throw Error("gel.law: each point is [indentation_mm, force_n]");
        points.emplace_back(pair[0] * 1e-3, pair[1]);
      }
      c.gel_law = GelLaw(std::move(points));
    }
    validate(c);
    return c;
  } catch (const YAML::Exception& e) {
    throw Error("scene config '" + yaml_path + "': " + e.what());
  } catch (const Error& e) {
    throw Error("scene config '" + yaml_path + "': " + e.what());
  }
}

}  // namespace norm2tex
