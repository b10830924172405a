#include "norm2tex/sim/probe_scenario.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// splitmix64: a fixed, portable generator (std distributions differ between standard
/// libraries, and a dataset must not change with the compiler).
class Random {
 public:
  Random(std::uint64_t seed, std::uint64_t stream) : state_(seed * 0x9E3779B97F4A7C15ull ^ stream) {
    next();
    state_ ^= stream * 0xD1B54A32D192ED03ull;
  }
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, 1).
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double low, double high) { return low + (high - low) * uniform(); }

 private:
  std::uint64_t state_;
};

void require(bool ok, const char* field, double value, const char* valid) {
  if (ok) return;
  std::ostringstream message;
  message << "probe config: " << field << " = " << value << " is not valid; valid: " << valid;
  throw Error(message.str());
}

/// Gel orientation whose +z points against `normal`, turned by `roll` about it.
Eigen::Matrix3d gelInObjectRotation(const Eigen::Vector3d& normal, double roll) {
  const Eigen::Vector3d z = -normal;
  // Any unit vector orthogonal to z, then the roll turns it.
  const Eigen::Vector3d helper =
      std::abs(z.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d x0 = (helper - helper.dot(z) * z).normalized();
  const Eigen::Vector3d x = Eigen::AngleAxisd(roll, z) * x0;
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = z.cross(x);
  r.col(2) = z;
  return r;
}

}  // namespace

void validate(const ProbeConfig& c) {
  require(c.press_depth_min_m > 0.0 && c.press_depth_min_m <= 0.004, "press_depth_min_m",
          c.press_depth_min_m, "(0, 0.004] m");
  require(c.press_depth_max_m >= c.press_depth_min_m && c.press_depth_max_m <= 0.004,
          "press_depth_max_m", c.press_depth_max_m, "[press_depth_min_m, 0.004] m");
  require(c.slides_per_press >= 0 && c.slides_per_press <= 1000, "slides_per_press",
          c.slides_per_press, "[0, 1000]");
  require(c.slide_step_max_m >= 0.0 && c.slide_step_max_m <= 0.005, "slide_step_max_m",
          c.slide_step_max_m, "[0, 0.005] m");
}

ProbeScenario::ProbeScenario(const TexturedMesh& mesh, const ProbeConfig& config,
                             const SensorModel& sensor, std::uint64_t seed)
    : mesh_(mesh), config_(config), seed_(seed), meter_(sensor) {
  validate(config_);
  cumulative_area_.reserve(mesh.triangles().size());
  double total = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles()) {
    const Eigen::Vector3d a = mesh.vertices()[t[0]].cast<double>();
    const Eigen::Vector3d b = mesh.vertices()[t[1]].cast<double>();
    const Eigen::Vector3d c = mesh.vertices()[t[2]].cast<double>();
    total += 0.5 * (b - a).cross(c - a).norm();
    cumulative_area_.push_back(total);
  }
  if (!(total > 0.0)) throw Error("probe scenario: the mesh has no triangle of positive area");
}

bool ProbeScenario::reachable(const Eigen::Isometry3d& object_in_gel, double depth) {
  // The pressed face itself rasterizes at -depth up to float rounding of millimetres.
  const double tolerance = 1e-6 + 1e-4 * depth;
  return meter_.measure(mesh_, object_in_gel).max_indentation_m <= depth + tolerance;
}

std::vector<ProbeFrame> ProbeScenario::press(std::uint64_t press) {
  Random random(seed_, press);
  constexpr int kAttempts = 64;
  const auto& triangles = mesh_.triangles();
  const auto& vertices = mesh_.vertices();
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    // Area-weighted triangle, then a uniform point in it.
    const double pick = random.uniform() * cumulative_area_.back();
    const std::size_t index = std::min<std::size_t>(
        std::upper_bound(cumulative_area_.begin(), cumulative_area_.end(), pick) -
            cumulative_area_.begin(),
        triangles.size() - 1);
    const Eigen::Vector3i& t = triangles[index];
    const Eigen::Vector3d a = vertices[t[0]].cast<double>();
    const Eigen::Vector3d b = vertices[t[1]].cast<double>();
    const Eigen::Vector3d c = vertices[t[2]].cast<double>();
    double u = random.uniform(), v = random.uniform();
    if (u + v > 1.0) {
      u = 1.0 - u;
      v = 1.0 - v;
    }
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    const double roll = random.uniform(0.0, 2.0 * kPi);
    const double depth = random.uniform(config_.press_depth_min_m, config_.press_depth_max_m);
    const double heading = random.uniform(0.0, 2.0 * kPi);
    if (cross.norm() <= 0.0) continue;  // a degenerate triangle: draw again

    ProbeFrame frame;
    frame.press = press;
    frame.surface_point = a + u * (b - a) + v * (c - a);
    frame.surface_normal = cross.normalized();
    frame.press_depth_m = depth;
    frame.roll_rad = roll;
    const Eigen::Matrix3d gel_in_object = gelInObjectRotation(frame.surface_normal, roll);
    // object_in_gel maps the surface point to (0, 0, -depth).
    frame.object_in_gel.linear() = gel_in_object.transpose();
    frame.object_in_gel.translation() =
        Eigen::Vector3d(0.0, 0.0, -depth) - gel_in_object.transpose() * frame.surface_point;
    if (!reachable(frame.object_in_gel, depth)) continue;

    std::vector<ProbeFrame> frames{frame};
    double direction = heading;
    for (int s = 1; s <= config_.slides_per_press; ++s) {
      direction += random.uniform(-0.25 * kPi, 0.25 * kPi);
      const double step = random.uniform(0.0, config_.slide_step_max_m);
      ProbeFrame slid = frames.back();
      slid.slide = s;
      slid.slide_m += step * Eigen::Vector2d(std::cos(direction), std::sin(direction));
      slid.object_in_gel = frame.object_in_gel;
      slid.object_in_gel.pretranslate(Eigen::Vector3d(slid.slide_m.x(), slid.slide_m.y(), 0.0));
      frames.push_back(slid);
    }
    return frames;
  }
  std::ostringstream message;
  message << "probe scenario: no reachable surface point in " << kAttempts
          << " draws for press " << press << " (seed " << seed_
          << "); is the mesh wound inwards or all hollows?";
  throw Error(message.str());
}

}  // namespace norm2tex
