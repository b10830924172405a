#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "norm2tex/mesh/textured_mesh.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/contact_patch.hpp"

namespace norm2tex {

/// How a free DIGIT probes an object, the paper's data collection: press onto a random surface
/// point with the gel aligned to the local normal, then slide a little, one frame per step.
struct ProbeConfig {
  double press_depth_min_m = 0.0003;  ///< press depth drawn uniformly in [min, max], metres
  double press_depth_max_m = 0.0012;
  int slides_per_press = 4;         ///< frames after the press, each one small slide further
  double slide_step_max_m = 0.0004;  ///< each slide moves the object up to this far along the gel
};

/// Throws Error naming the first field out of range and its valid range.
void validate(const ProbeConfig& config);

/// One frame of a probe: where the object is, seen from the gel.
struct ProbeFrame {
  std::uint64_t press = 0;  ///< press index in the scenario (the seed stream it was drawn from)
  int slide = 0;            ///< 0 = the press itself, 1..slides_per_press = slides after it
  /// Pressed surface point and its outward unit normal, object frame, metres.
  Eigen::Vector3d surface_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d surface_normal = Eigen::Vector3d::UnitZ();
  double press_depth_m = 0.0;  ///< how deep the surface point sits below the undeformed gel
  double roll_rad = 0.0;       ///< rotation of the gel about the normal
  /// Slide so far: the object's displacement along the gel surface (gel x, y), metres.
  Eigen::Vector2d slide_m = Eigen::Vector2d::Zero();
  /// Object frame in the gel frame (+x image right, +y image down, +z out of the gel).
  Eigen::Isometry3d object_in_gel = Eigen::Isometry3d::Identity();
};

/// Seeded, reproducible probe poses on a mesh. Press `p` of seed `s` is a pure function of
/// (s, p, mesh, config): any subset of presses (a shard) can be generated alone and gives the
/// same frames as in the full sequence.
///
/// A press: a surface point drawn uniformly by area over the triangles, the triangle's outward
/// normal (the mesh's winding; meshes from loadObjectMesh are wound outwards), the gel turned so
/// its +z points against that normal, a roll about it uniform in [0, 2 pi), and the object
/// moved so the point sits press_depth below the gel surface at the gel's centre. A point whose
/// press would push another part of the object deeper into the sensor's imaged area than the
/// point itself (a hollow, an inner wall: the rasterized H_sensor is deeper than the press) is
/// not a contact a real gel could make there: it is drawn again (up to 64 times).
/// Slides: each moves the object along the gel surface by a uniform random step of up to
/// slide_step_max in a direction that turns by at most 45 degrees between steps (a stroke, not a
/// jitter), keeping the press depth.
class ProbeScenario {
 public:
  /// Throws Error for an invalid config or a mesh with no triangle of positive area. `mesh` must
  /// outlive the scenario.
  ProbeScenario(const TexturedMesh& mesh, const ProbeConfig& config, const SensorModel& sensor,
                std::uint64_t seed);

  int framesPerPress() const { return 1 + config_.slides_per_press; }
  /// Every frame of press `press`, the press first. Throws Error when no admissible point was
  /// found (an object that is all hollows).
  /// Not thread-safe (one scenario per thread): it reuses its raster buffers.
  std::vector<ProbeFrame> press(std::uint64_t press);
  const ProbeConfig& config() const { return config_; }
  std::uint64_t seed() const { return seed_; }

 private:
  /// Does the image at `object_in_gel` show nothing deeper than `depth`?
  bool reachable(const Eigen::Isometry3d& object_in_gel, double depth);

  const TexturedMesh& mesh_;
  ProbeConfig config_;
  std::uint64_t seed_;
  std::vector<double> cumulative_area_;  ///< running sum of triangle areas, for area sampling
  ContactPatchMeter meter_;
};

}  // namespace norm2tex
