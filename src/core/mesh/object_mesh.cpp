#include "norm2tex/mesh/object_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "norm2tex/common/error.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"

namespace norm2tex {
namespace {

// A loaded box has every vertex on a corner of its bounds (duplicated per face for UVs) and
// uses all 8 corners (4 corners alone can make a tetrahedron).
bool isBoundingBox(const TexturedMesh& mesh) {
  const Eigen::AlignedBox3f& box = mesh.bounds();
  const float tolerance = 1e-4f * box.diagonal().norm();
  unsigned corners_used = 0;  // bit k: corner k (x, y, z at max = bits 0, 1, 2)
  for (const Eigen::Vector3f& v : mesh.vertices()) {
    int corner = 0;
    for (int axis = 0; axis < 3; ++axis) {
      if (std::abs(v[axis] - box.max()[axis]) <= tolerance) {
        corner |= 1 << axis;
      } else if (std::abs(v[axis] - box.min()[axis]) > tolerance) {
        return false;
      }
    }
    corners_used |= 1u << corner;
  }
  return corners_used == 0xFFu;
}

// Rim vertices a tessellated cylinder needs before it counts as one (a 12-sided prism is a
// prism: its flats touch a gel unlike a round side).
constexpr int kMinRimVertices = 16;

// Fits a sphere, an axis-aligned cylinder or capsule centred in the bounds; true when every
// vertex lies on it within `tolerance`.
bool fitRoundPrimitive(ObjectMesh& out) {
  const TexturedMesh& mesh = out.mesh;
  const Eigen::AlignedBox3d box = mesh.bounds().cast<double>();
  const Eigen::Vector3d centre = box.center(), size = box.sizes();
  const double tolerance = 1e-4 * size.norm();
  if (mesh.vertices().size() < static_cast<size_t>(kMinRimVertices)) return false;
  // Sphere: every vertex at one distance from the centre, the bounds a cube.
  double radius = 0;
  for (const Eigen::Vector3f& v : mesh.vertices()) {
    radius = std::max(radius, (v.cast<double>() - centre).norm());
  }
  const bool on_sphere =
      std::all_of(mesh.vertices().begin(), mesh.vertices().end(), [&](const Eigen::Vector3f& v) {
        return std::abs((v.cast<double>() - centre).norm() - radius) <= tolerance;
      });
  if (on_sphere && size.maxCoeff() - size.minCoeff() <= 0.02 * size.maxCoeff()) {
    out.shape = ObjectMesh::Shape::kSphere;
    out.radius_m = radius;
    return true;
  }
  for (int axis = 0; axis < 3; ++axis) {
    const int i = (axis + 1) % 3, j = (axis + 2) % 3;
    if (std::abs(size[i] - size[j]) > 0.02 * size[i]) continue;  // not round about this axis
    const auto radial = [&](const Eigen::Vector3f& v) {
      return std::hypot(v[i] - centre[i], v[j] - centre[j]);
    };
    double r = 0;
    for (const Eigen::Vector3f& v : mesh.vertices()) r = std::max(r, radial(v));
    const double half_height = size[axis] / 2;
    // Cylinder: each vertex on the side (at the rim's radius) or on a cap plane.
    std::set<long> rim_angles;  // distinct rim directions, in 0.1 degree steps
    bool cylinder = true, capsule = half_height - r > tolerance;
    const double spine = half_height - r;
    for (const Eigen::Vector3f& v : mesh.vertices()) {
      const double rho = radial(v), h = v[axis] - centre[axis];
      const bool on_side = std::abs(rho - r) <= tolerance;
      if (!on_side && std::abs(std::abs(h) - half_height) > tolerance) cylinder = false;
      if (on_side) {
        rim_angles.insert(
            std::lround(std::atan2(v[j] - centre[j], v[i] - centre[i]) * 1800 / M_PI));
      }
      // Capsule: each vertex at the radius from its spine, the segment along the axis.
      const double along = std::clamp(h, -spine, spine);
      if (capsule && std::abs(std::hypot(rho, h - along) - r) > tolerance) capsule = false;
      if (!cylinder && !capsule) break;
    }
    if (static_cast<int>(rim_angles.size()) < kMinRimVertices) continue;
    if (capsule || cylinder) {
      out.shape = capsule ? ObjectMesh::Shape::kCapsule : ObjectMesh::Shape::kCylinder;
      out.axis = axis;
      out.radius_m = r;
      out.half_length_m = capsule ? spine : half_height;
      return true;
    }
  }
  return false;
}

}  // namespace

bool isPrimitiveMeshSpec(const std::string& spec) {
  return spec.rfind("sphere:", 0) == 0 || spec.rfind("box:", 0) == 0;
}

ObjectMesh loadObjectMesh(const std::string& spec, double scale) {
  ObjectMesh out;
  if (spec.rfind("sphere:", 0) == 0) {
    std::istringstream text(spec.substr(7));
    double radius_mm = 0;
    if (!(text >> radius_mm) || !(radius_mm > 0) || !text.eof()) {
      throw Error("object mesh '" + spec + "': a sphere is sphere:<radius_mm> with radius > 0");
    }
    out.mesh = makeUvSphere(radius_mm * 1e-3, 96, 192);
    out.shape = ObjectMesh::Shape::kSphere;
    out.radius_m = radius_mm * 1e-3;
    return out;
  }
  if (spec.rfind("box:", 0) == 0) {
    double x = 0, y = 0, z = 0;
    char sep1 = 0, sep2 = 0;
    std::istringstream sizes(spec.substr(4));
    if (!(sizes >> x >> sep1 >> y >> sep2 >> z) || sep1 != 'x' || sep2 != 'x' || !(x > 0) ||
        !(y > 0) || !(z > 0) || !sizes.eof()) {
      throw Error("object mesh '" + spec + "': a box is box:<x_mm>x<y_mm>x<z_mm>, sizes > 0");
    }
    out.mesh = makeBox(Eigen::Vector3d(x, y, z) * 1e-3, 0.02);
    out.shape = ObjectMesh::Shape::kBox;
    return out;
  }
  MeshLoadOptions options;
  options.scale = scale;
  out.mesh = TexturedMesh::load(spec, options);
  if (isBoundingBox(out.mesh)) {
    out.shape = ObjectMesh::Shape::kBox;
  } else {
    fitRoundPrimitive(out);
  }
  return out;
}

const char* shapeName(ObjectMesh::Shape shape) {
  switch (shape) {
    case ObjectMesh::Shape::kBox:
      return "box";
    case ObjectMesh::Shape::kSphere:
      return "sphere";
    case ObjectMesh::Shape::kCylinder:
      return "cylinder";
    case ObjectMesh::Shape::kCapsule:
      return "capsule";
    case ObjectMesh::Shape::kMesh:
      break;
  }
  return "mesh";
}

}  // namespace norm2tex
