#include "norm2tex/mesh/object_mesh.hpp"

#include <cmath>
#include <sstream>

#include "norm2tex/common/error.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"

namespace norm2tex {
namespace {

// A loaded box keeps its 8 corners (possibly duplicated per face for UVs).
bool allVerticesOnBoxCorners(const TexturedMesh& mesh) {
  const Eigen::AlignedBox3f& box = mesh.bounds();
  const float tolerance = 1e-4f * box.diagonal().norm();
  for (const Eigen::Vector3f& v : mesh.vertices()) {
    for (int axis = 0; axis < 3; ++axis) {
      if (std::abs(v[axis] - box.min()[axis]) > tolerance &&
          std::abs(v[axis] - box.max()[axis]) > tolerance) {
        return false;
      }
    }
  }
  return true;
}

// A tessellated sphere's vertices all sit on the sphere; returns its radius, or 0.
double sphereRadius(const TexturedMesh& mesh) {
  if (mesh.vertices().size() < 32) return 0.0;
  Eigen::Vector3d centre = mesh.bounds().center().cast<double>();
  double low = INFINITY, high = 0.0;
  for (const Eigen::Vector3f& v : mesh.vertices()) {
    const double r = (v.cast<double>() - centre).norm();
    low = std::min(low, r);
    high = std::max(high, r);
  }
  return (high > 0.0 && (high - low) <= 0.005 * high) ? high : 0.0;
}

}  // namespace

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
    out.sphere_radius_m = radius_mm * 1e-3;
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
    out.box_size_m = Eigen::Vector3d(x, y, z) * 1e-3;
    out.mesh = makeBox(out.box_size_m, 0.02);
    out.shape = ObjectMesh::Shape::kBox;
    return out;
  }
  MeshLoadOptions options;
  options.scale = scale;
  out.mesh = TexturedMesh::load(spec, options);
  const Eigen::Vector3f centre = out.mesh.bounds().center();
  if (allVerticesOnBoxCorners(out.mesh) &&
      centre.norm() <= 1e-4f * out.mesh.bounds().diagonal().norm()) {
    out.shape = ObjectMesh::Shape::kBox;
    out.box_size_m = out.mesh.bounds().sizes().cast<double>();
  } else if (const double r = sphereRadius(out.mesh); r > 0.0 && centre.norm() <= 1e-3f * r) {
    out.shape = ObjectMesh::Shape::kSphere;
    out.sphere_radius_m = r;
  }
  return out;
}

}  // namespace norm2tex
